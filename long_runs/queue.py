#!/usr/bin/env python3
"""Issue 63's trainings, one at a time and in order, each resumed where it stopped: every Mario level
from 1-1 to 2-4 from one command (the ``flag`` preset, fixed on 2026-12-03 before the first of these
runs), plus two lever runs that measure a cheaper recipe (``--epochs 4``) on 1-1 and on 2-1 against it, each
stopped at the flag share 0.9 or at 1.5x the env steps its baseline took to reach it (:func:`lever_limits`),
and trained as soon as that stop is known (:func:`training_order`). Where 4 epochs prove cheaper on both,
the levels not yet started add ``--epochs 4`` (:func:`adopted`).
Each level's run is then evaluated on 30 further unseen seeds.

    .venv/bin/python long_runs/queue.py --dry-run     # the next command, from the folders' state
    .venv/bin/python long_runs/queue.py --status      # where each run stands, a line each
    .venv/bin/python long_runs/queue.py --plot long_runs/mario_ppo/flag_share.png   # the runs' flag share
    setsid nohup .venv/bin/python long_runs/queue.py > /tmp/queue.log 2>&1 &

Each step is read from the folders when the step before it ends, so the queue can be stopped and started
again at any time. Stop it with SIGTERM or Ctrl-C to its process group (``kill -TERM -- -PGID``; the
queue prints its PGID): the running training writes its checkpoint and exits, and the queue starts
nothing more. A step that fails stops the queue with that step's exit status, and so does a step that
ends well but leaves the folders as they were (it would run again forever). Shipping a finished level
(its model, card and GIF) is left to a person, who reads the result first (``long_runs/README.md`` says how);
the queue then reads that level's run from its ``saved_networks/`` folder.

A training run from a worktree at a fixed commit (``git worktree add --detach ../runner``, its
``long_runs/mario_ppo`` a symlink to this one's) cannot be reached by code changed here meanwhile; its
run folders are this checkout's, committed by ``make save-long-runs``.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
# the recipe, fixed before the first run (issue 63): the flag preset; bfloat16 where the CPU has it
PRESET = "flag"
RECIPE = ["--preset", PRESET, "--seed", "0", "--precision", "bfloat16", "--final-eval-episodes", "30"]
QUIET = ["--wandb", "offline", "--no-progress"]
LEVELS = ("1-1", "1-2", "1-3", "1-4", "2-1", "2-2", "2-3", "2-4")
# (folder name, level, what the run adds to the recipe), in the order they train
RUNS = (("1-1", "1-1", []), ("1-1-epochs-4", "1-1", ["--epochs", "4"]),
        ("2-1", "2-1", []), ("2-1-epochs-4", "2-1", ["--epochs", "4"]),
        *((level, level, []) for level in LEVELS if level not in ("1-1", "2-1")))


LEVER_SHARE, LEVER_MARGIN = 0.9, 1.5  # where a lever run stops (lever_limits)
# how much faster 4 epochs are per env step than 10 (benchmarks/mario_recipe.py, 2026-12-07; docs/notes/speed.md)
LEVER_SPEEDUP = {"1-1": 1.23, "2-1": 1.30}


def run_dir(name: str) -> str:
    return f"long_runs/mario_ppo/{name}"


def shipped(name: str, folders: Path = HERE) -> Path | None:
    """Where a level's run lives once it is published (``--publish`` copies its model, CSV tables and meta.json
    into saved_networks/, and its long_runs folder is then deleted): that folder; None while it is not."""
    level, extra = next((level, extra) for run, level, extra in RUNS if run == name)
    target = folders / "saved_networks" / "mario_ppo" / level
    if extra or (folders / run_dir(name)).exists() or not (target / "meta.json").is_file():
        return None
    return target if json.loads((target / "meta.json").read_text()).get("preset") == PRESET else None


def home(name: str, folders: Path = HERE) -> Path:
    """Where a run's files are: its model folder in saved_networks/ once published, else its long_runs folder."""
    return shipped(name, folders) or folders / run_dir(name)


def train_command(name: str, level: str, extra: list[str]) -> list[str]:
    world, stage = level.split("-")
    return ["train", "mario_ppo", "ppo", *RECIPE, "--world", world, "--stage", stage, *extra,
            "--run-dir", run_dir(name), *QUIET]


def next_command(folders: Path = HERE) -> list[str] | None:
    """The next step's ``main.py`` arguments, from the state of the run folders under ``folders``; None
    when the queue has nothing left to run."""
    for name, level, extra in training_order(folders):
        run = folders / run_dir(name)
        if shipped(name, folders):
            continue
        meta = run / "model" / "meta.json"
        if meta.is_file():
            if not _evaluated(meta):  # trained, but the process ended before its final evaluation
                return ["evaluate", "mario_ppo", "ppo", "--model", run_dir(name), "--episodes", "30", "--record"]
            if not json.loads(meta.read_text()).get("further_evaluations"):
                return ["evaluate", "mario_ppo", "ppo", "--model", run_dir(name), "--episodes", "30",
                        "--record-further"]
            continue
        if (run / "checkpoint.npz").is_file():
            return ["train", "mario_ppo", "ppo", "--resume", run_dir(name), *QUIET]
        added = lever_limits(level, folders) if extra else adopted(level, folders)
        return train_command(name, level, extra + added)
    return None


def adopted(level: str, folders: Path = HERE) -> list[str]:
    """What a level's run adds to the recipe when it starts: ``--epochs 4`` once both lever runs have
    finished and on both levels 4 epochs reached the flag share 0.9 for fewer CPU-seconds than the recipe's 10
    (:func:`levers_cheaper`); nothing for 1-1 and 2-1, whose runs of the recipe are the baselines. Set
    2026-12-07, before either lever run had an episode."""
    has_lever = any(extra and lever_level == level for _, lever_level, extra in RUNS)
    return ["--epochs", "4"] if not has_lever and levers_cheaper(folders) else []


def levers_cheaper(folders: Path = HERE) -> bool:
    """Both lever runs have trained, and each reached the flag share 0.9 in fewer env steps than its baseline
    took times :data:`LEVER_SPEEDUP` (a baseline that never reached 0.9 spent its whole budget without it, so a
    lever that reached it within that budget, its limit, was cheaper)."""
    for name, level, extra in RUNS:
        if not extra:
            continue
        lever = folders / run_dir(name)
        if not (lever / "model" / "meta.json").is_file() or (reached := _reached(lever)) is None:
            return False
        if (before := _reached(home(level, folders))) is not None and reached >= LEVER_SPEEDUP[level] * before:
            return False
    return True


def training_order(folders: Path = HERE) -> list[tuple[str, str, list[str]]]:
    """RUNS in the order they train now: a lever run moves ahead of its baseline once the baseline, still
    training, has reached the flag share 0.9, since the lever's stop is fixed from then on (:func:`lever_limits`)
    and its answer (is the cheaper recipe as good?) is wanted before the later levels start; the baseline then
    resumes, unchanged. Set 2026-12-07, when 1-1 had reached 0.9 and stayed below its stop share for 1.6M env
    steps."""
    order = list(RUNS)
    for lever in [run for run in RUNS if run[2]]:
        baseline = folders / run_dir(lever[1])
        if not (baseline / "model").exists() and not shipped(lever[1], folders) and _reached(baseline):
            order.remove(lever)
            order.insert(order.index(next(run for run in order if run[0] == lever[1])), lever)
    return order


def _reached(run: Path) -> int | None:
    """The env steps at which the run's flag share from the start first reached the lever share, or None."""
    steps, shares = flag_curve(run / "metrics.csv")
    return next((step for step, share in zip(steps, shares) if share >= LEVER_SHARE), None)


def lever_limits(level: str, folders: Path = HERE) -> list[str]:
    """A lever run's stop, fixed when it starts from its baseline (the level's run of the recipe, which trains
    before it, to its end or to the share 0.9: :func:`training_order`): the flag share 0.9, or 1.5x the env steps
    the baseline took to first reach that share (where it never did, the baseline's env steps), within the
    recipe's budget. 4 epochs cost 1/1.23 of 10 per env step
    (benchmarks/mario_recipe.py), so a lever run that needs over 1.23x its baseline's env steps to the same share
    is not cheaper; the margin leaves room for a seed's luck. Set 2026-12-07, before either lever run started."""
    from mario_ppo.experiment import FLAG

    baseline = home(level, folders)
    reached = _reached(baseline)
    rows = _rows(baseline / "metrics.csv") or []
    budget = round(LEVER_MARGIN * reached) if reached else int(float(rows[-1]["env_steps"])) if rows else None
    return ["--stop-success-share", str(LEVER_SHARE)] + (
        ["--steps", str(min(budget, FLAG.max_env_steps))] if budget else [])


def _evaluated(meta: Path) -> bool:
    """The run has trained and its evaluation on unseen seeds is in its model's meta.json."""
    return bool(json.loads(meta.read_text()).get("evaluation"))


def run_status(name: str, folders: Path = HERE) -> str:
    """One line: queued, at a checkpoint (env steps, episodes, the flag share of the last 100 episodes from
    the level's start), or finished (what ended it, and the flag on unseen seeds)."""
    run, home = folders / run_dir(name), shipped(name, folders)
    meta = home / "meta.json" if home else run / "model" / "meta.json"
    if meta.is_file():
        record = json.loads(meta.read_text())
        scores = [record.get("evaluation") or {}] + list(record.get("further_evaluations") or [])
        flags = ", ".join(f"{round(e['success_share'] * e['episodes'])} of {e['episodes']}" for e in scores
                          if "success_share" in e and "episodes" in e)
        return (f"{name}: {f'shipped to {home.relative_to(folders)}, ' if home else ''}finished at "
                f"{record.get('env_steps', 0):,} env steps ({record.get('stopped_by', '?')}); "
                f"flag on unseen seeds: {flags or 'not evaluated yet'}")
    if (run / "checkpoint.npz").is_file():
        return f"{name}: in progress (a checkpoint kept); " + _progress(run / "metrics.csv")
    return f"{name}: queued"


def _rows(metrics: Path) -> list[dict] | None:
    """The episode rows of a run's metrics.csv (damaged rows left out, as a resume reads them); None
    when there is no readable table."""
    from rlcore.errors import UserError
    from rlcore.files.csv_tables import read_table

    try:
        table, _ = read_table(metrics)
    except (OSError, UserError):
        return None
    return [dict(zip(table[0], row)) for row in table[1:]]


def _from_start(row: dict) -> bool:
    return row.get("restarted") in (None, "", "0", "0.0")  # a restarted episode began mid-level


def _flag(row: dict) -> bool:
    return row.get("success") in ("1", "1.0", "True")


def _progress(metrics: Path) -> str:
    """Env steps and episodes so far, and the flag in the last 100 episodes from the level's start."""
    rows = _rows(metrics)
    if rows is None:
        return "no readable metrics.csv"
    if not rows:
        return "no episode yet"
    counted = [r for r in rows if _from_start(r)][-100:]
    return (f"{int(float(rows[-1]['env_steps'])):,} env steps, {len(rows):,} episodes, "
            f"flag in {sum(map(_flag, counted))} of the last {len(counted)} from the start")


def flag_curve(metrics: Path) -> tuple[list[int], list[float]]:
    """(env steps, flag share of the last 100 episodes from the level's start), one point per such episode
    from the 100th on."""
    steps, shares, window = [], [], []
    for row in _rows(metrics) or []:
        if _from_start(row):
            window = [*window[-99:], _flag(row)]
            if len(window) == 100:
                steps.append(int(float(row["env_steps"])))
                shares.append(sum(window) / 100)
    return steps, shares


DEFAULT_1_1 = "results/sweeps/mario_ppo__1-1"  # 1-1's recipe before this queue, 3 seeds: what the flag preset is measured against


def plot(path: Path, folders: Path = HERE) -> None:
    """The flag share against env steps of every run that has one, beside 1-1's default preset (3 seeds), with
    the bar (27 of 30) and the stop share of the recipe (0.95)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, metrics in enumerate(sorted(folders.glob(f"{DEFAULT_1_1}/seed=*/metrics.csv"))):
        steps, shares = flag_curve(metrics)
        ax.plot([s / 1e6 for s in steps], shares, color="silver", linewidth=0.8,
                label="1-1, default preset (3 seeds)" if i == 0 else None)
    for name, _, extra in RUNS:
        steps, shares = flag_curve(home(name, folders) / "metrics.csv")
        if steps:
            ax.plot([s / 1e6 for s in steps], shares, label=name, linestyle="--" if extra else "-", linewidth=1.2)
    ax.axhline(0.9, color="gray", linewidth=0.8, linestyle=":", label="bar: 27 of 30")
    ax.axhline(0.95, color="black", linewidth=0.8, linestyle=":", label="stop share 0.95")
    ax.set(xlabel="env steps (millions)", ylabel="flag share, last 100 episodes from the start", ylim=(0, 1),
           title="Mario, one command per level (flag preset): training")
    ax.legend(loc="lower right", fontsize=8, ncol=2)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dry-run", action="store_true", help="print the next command and exit")
    parser.add_argument("--status", action="store_true", help="print where each run stands and exit")
    parser.add_argument("--plot", metavar="PNG", help="write the flag share against env steps of every run and exit")
    args = parser.parse_args(argv)
    if args.plot:
        plot(Path(args.plot))
        print(f"plot: {args.plot}")
        return 0
    if args.status:
        print("\n".join(run_status(name) for name, _, _ in RUNS))
        return 0
    if args.dry_run:
        command = next_command()
        print("nothing left to run" if command is None else " ".join(["python", "main.py", *command]))
        return 0
    stopping: list[bool] = []
    # the training in the same process group gets the signal too, and checkpoints; the queue only stops
    previous = {number: signal.signal(number, lambda *_: stopping.append(True))
                for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        print(f"queue: pid {os.getpid()}, process group {os.getpgrp()}", flush=True)
        done = None
        while not stopping and (command := next_command()) is not None:
            if command == done:  # it ended well and changed nothing: a run that keeps failing, say
                print("queue: stopped: python main.py " + " ".join(command) + " ended with status 0 and left "
                      "the folders as they were; see its output above", flush=True)
                return 1
            print("queue: python main.py " + " ".join(command), flush=True)
            code = subprocess.call([sys.executable, "main.py", *command], cwd=HERE)
            if code != 0:
                print(f"queue: stopped, exit status {code}", flush=True)
                return code
            done = command
        print("queue: " + ("stopped" if stopping else "nothing left to run"), flush=True)
        return 130 if stopping else 0
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


if __name__ == "__main__":
    sys.exit(main())
