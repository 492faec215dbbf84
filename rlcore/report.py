"""``main.py report``: per-run results of one or more sweeps, aggregated with confidence intervals.

Statistics follow rliable (Agarwal et al. 2021): mean, median and interquartile mean (IQM) of the
runs' final scores, each with a 95 % stratified percentile bootstrap interval, and the probability
that one sweep's runs beat another's. The aggregates and the probability of improvement are
rliable's own (``rliable.metrics``); the bootstrap is written here because ``rliable.library``
calls ``arch``, and neither arch 7 (it fails to import with pandas 3) nor arch 8 (it no longer
takes rliable's ``random_state`` argument) works with it on Python 3.13 today.

A run's final score is the evaluation on unseen seeds in its ``model/meta.json``: the greedy mean
return, or for Mario the share of episodes that reached the flag. TensorFlow-free.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.eval_history import stability_summary, story, story_text
from rlcore.extras import require

AGGREGATES = ("mean", "median", "iqm")


def aggregates(scores: np.ndarray) -> np.ndarray:
    """[mean, median, IQM] of a (runs, tasks) score matrix.

    The mean and IQM are rliable's. The median is the median over runs of each run's mean over
    tasks: rliable's ``aggregate_median`` is the median over *tasks* of the per-task means, which
    for the single task of a sweep group is just the mean again.
    """
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return np.array([metrics.aggregate_mean(scores), float(np.median(scores.mean(axis=1))),
                     metrics.aggregate_iqm(scores)])


def stratified_bootstrap_ci(statistic, *matrices: np.ndarray, reps: int = 5000, level: float = 0.95,
                            seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval of ``statistic(*matrices)`` under rliable's stratified bootstrap.

    Each matrix is (runs, tasks); a resample draws, for every task separately, as many runs with
    replacement as there are (the strata are the tasks). Returns ``(point, [low, high])``.
    """
    rng = np.random.default_rng(seed)
    point = np.asarray(statistic(*matrices))
    draws = []
    for _ in range(reps):
        resampled = []
        for m in matrices:
            runs, tasks = m.shape
            rows = rng.integers(0, runs, (runs, tasks))
            resampled.append(np.take_along_axis(m, rows, axis=0))
        draws.append(statistic(*resampled))
    tail = (1 - level) / 2 * 100
    return point, np.percentile(np.asarray(draws), [tail, 100 - tail], axis=0)


def probability_of_improvement(x: np.ndarray, y: np.ndarray) -> float:
    """P(a run of X scores above a run of Y), ties counting half (rliable's definition)."""
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return float(metrics.probability_of_improvement(x, y))


# --------------------------------------------------------------------------------- run folders
def load_runs(sweep_dir: Path) -> list[dict]:
    """One row per run folder of a sweep: trial, final score, env steps, wall time and the CPU it ran
    on (finished runs only)."""
    sweep_dir = Path(sweep_dir)
    if not sweep_dir.is_dir():
        raise UserError(f"no sweep folder {sweep_dir}")
    rows, unevaluated = [], []
    for meta_path in sorted(sweep_dir.glob("*/model/meta.json")):
        meta = json.loads(meta_path.read_text())
        ev = meta.get("evaluation") or {}
        score = ev.get("success_share", ev.get("mean"))
        if score is None:
            unevaluated.append(meta_path.parent.parent.name)  # trained but not evaluated: no score
            continue
        rows.append({"trial": meta_path.parent.parent.name, "seed": meta["seed"], "score": float(score),
                     "eval_episodes": ev.get("episodes"), "env_steps": meta["env_steps"],
                     "wall_seconds": meta["wall_seconds"], "run_dir": meta_path.parent.parent,
                     "cpu": cpus_text(meta), "time_limit_share": ev.get("time_limit_share"),
                     "further": [(f["episodes"], f.get("success_share", f.get("mean")))
                                 for f in meta.get("further_evaluations", [])],
                     "story": story(meta_path.parent.parent, meta, _solved_score(meta)),
                     "what": f"{meta.get('experiment')} {meta.get('algo')}"})
    if not rows:
        raise UserError(f"{sweep_dir} holds no finished, evaluated run (model/meta.json with an evaluation)")
    if unevaluated:  # leaving a trained seed out would report the others as if they were all
        raise UserError(f"{sweep_dir}: {', '.join(unevaluated)} trained but has no evaluation on unseen seeds; "
                        f"evaluate it first (a sweep's --resume does, or `python main.py evaluate ... --model "
                        f"RUN_DIR --record`)")
    kinds = sorted({row["what"] for row in rows})
    if len(kinds) > 1:  # one aggregate over unlike scores would mean nothing
        raise UserError(f"{sweep_dir} holds runs of {' and '.join(kinds)}: a report aggregates one experiment "
                        f"and algorithm per folder; give each its own SWEEP_DIR")
    return rows


def _solved_score(meta: dict) -> float | None:
    """The solved score of the task a run's meta.json names: a Gymnasium id's recorded
    ``reward_threshold``, else the registry's. None where it has none or it cannot be known here (then
    nothing is claimed, :func:`rlcore.eval_history.far_from_solved`): a report never needs the env itself."""
    from rlcore.experiment import EXPERIMENT_MODULES, get_experiment

    env = meta.get("env")
    if isinstance(env, dict) and "reward_threshold" in env:
        threshold = env["reward_threshold"]
        return None if threshold is None else float(threshold)
    if meta.get("experiment") not in EXPERIMENT_MODULES:
        return None  # a Gymnasium id without its record: building its env only to learn this is not worth it
    try:
        return get_experiment(meta["experiment"]).solved_score
    except Exception:  # the experiment's extra is missing, or its module fails to import: no claim
        return None


#: what ``keep`` copies of a run folder: what the report reads (meta.json, metrics.csv), the periodic
#: evaluations (evals.csv), PPO's rollout table (rollouts.csv) and the model's weights (model/*.h5), so
#: that a kept run's model can be evaluated again (``main.py evaluate ... --model KEPT/seed=S``);
#: checkpoints, replay memories and plots stay behind
KEPT_FILES = ("model/meta.json", "model/*.h5", "metrics.csv", "evals.csv", "rollouts.csv")


def kept_files(run_dir: Path) -> list[str]:
    """The :data:`KEPT_FILES` a run folder holds, as paths relative to it."""
    run_dir = Path(run_dir)
    return [p.relative_to(run_dir).as_posix() for pattern in KEPT_FILES for p in sorted(run_dir.glob(pattern))
            if p.is_file()]


def is_run_folder(folder: Path) -> bool:
    """A finished run's folder (``model/meta.json``), as opposed to a sweep's folder of such runs."""
    return (Path(folder) / "model" / "meta.json").is_file()


def _keep_into(dest: Path, pairs: list[tuple[Path, str]], sweep: dict | None = None) -> Path:
    """Make ``dest`` hold exactly the ``pairs`` (source file, path in ``dest``) and, given, ``sweep`` as
    its sweep.json; an earlier kept sweep there is replaced whole (a seed it held and this keep lacks
    does not survive), in one swap (:func:`rlcore.atomic.replace_folder`), so a kept folder is never a
    mix of two keeps or a keep cut short."""
    from rlcore.atomic import replace_folder

    if dest.exists() and not dest.is_dir():
        raise UserError(f"--keep {dest}: a file is there; give a folder")
    earlier_keep = (dest / "sweep.json").is_file() or any(dest.glob("*/model/meta.json"))
    if dest.is_dir() and any(dest.iterdir()) and not earlier_keep:
        raise UserError(f"--keep {dest}: that folder holds other files and no kept sweep (sweep.json); give a new "
                        f"folder, or one an earlier keep wrote, which is replaced whole")

    def fill(fresh: Path) -> None:
        for source, name in pairs:
            (fresh / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, fresh / name)
        if sweep is not None:
            (fresh / "sweep.json").write_text(json.dumps(sweep, indent=2) + "\n")

    return replace_folder(dest, fill)


#: config fields kept runs may differ in: budgets, which a resume may give again (the stop rule ends a run)
BUDGETS = ("max_env_steps", "max_episodes")


def cpus_text(meta: dict) -> str | None:
    """The CPUs a run trained on: meta.json's ``cpu`` (the last command's machine), or where its commands
    recorded theirs (from 2026-11-29 on) and a resume moved the run to another CPU, each with where it
    took over: ``AMD EPYC (...); Intel Xeon (...) from 614,400 env steps``."""
    changes: list[tuple[int, str]] = []
    for start in command_starts(meta):
        cpu = (start or {}).get("cpu")
        if cpu and (not changes or changes[-1][1] != cpu):
            changes.append((int(start.get("env_steps", 0)), cpu))
    if len(changes) < 2:
        return meta.get("cpu") or (changes[0][1] if changes else None)
    return "; ".join(cpu if i == 0 and steps == 0 else f"{cpu} from {steps:,} env steps"
                     for i, (steps, cpu) in enumerate(changes))


def command_starts(record: dict) -> list:
    """A run's ``command_starts`` (meta.json's or a checkpoint's), one per command it records: None for
    the commands of records from before 2026-11-27, which did not keep it."""
    starts = list(record.get("command_starts") or [])
    commands = record.get("commands") or []
    return [None] * (len(commands) - len(starts)) + starts


def check_one_recipe_throughout(run_dir: Path, meta: dict) -> None:
    """Refuse a run that did not follow one recipe from random weights to its end: one started from a
    model's weights (``--init-from``), or resumed with a hyperparameter other than a :data:`BUDGETS` changed
    (read from meta.json's ``command_starts``, where each resume records what it changed), or a resume
    whose record predates that."""
    if meta.get("init_from"):
        source = meta["init_from"].get("path", "a model") if isinstance(meta["init_from"], dict) else meta["init_from"]
        raise UserError(f"{run_dir} started from the weights of {source} (--init-from): kept runs train from "
                        f"random weights")
    for number, start in enumerate(command_starts(meta)[1:], 2):
        if not isinstance(start, dict) or "changed" not in start:
            raise UserError(f"{run_dir}: its meta.json does not say what its command {number} (a resume) changed "
                            f"(a record from before 2026-11-27): kept runs must show that a resume gave budgets only")
        changed = {name: values for name, values in start["changed"].items() if name not in BUDGETS}
        if changed:
            what = ", ".join(f"{name} {before} -> {after}" for name, (before, after) in sorted(changed.items()))
            raise UserError(f"{run_dir} was resumed at env step {start['env_steps']:,} with {what}: kept runs follow "
                            f"one recipe from start to end (a resume may give budgets again, nothing else)")


def keep_runs(run_dirs: list[Path], dest: Path) -> Path:
    """Keep single runs of one recipe over seeds (``main.py train ... --seed S``, one run folder each) as
    a sweep would be kept: per run :data:`KEPT_FILES` into ``dest/seed=S/``, and a ``sweep.json`` naming
    the experiment, algorithm, preset, seeds and (for Mario) the level, so that ``report`` and the docs
    generator read ``dest`` like any kept sweep. The runs must differ in their seed (and :data:`BUDGETS`) only,
    and each must have kept its recipe throughout (:func:`check_one_recipe_throughout`)."""
    from rlcore.experiment import get_experiment
    from rlcore.hparams import to_dict

    run_dirs, dest = [Path(d) for d in run_dirs], Path(dest)
    metas = [json.loads((d / "model" / "meta.json").read_text()) for d in run_dirs]
    first = metas[0]
    for d, meta in zip(run_dirs, metas):
        check_one_recipe_throughout(d, meta)
        what = (meta.get("experiment"), meta.get("algo"), meta.get("preset"))
        if what != (first.get("experiment"), first.get("algo"), first.get("preset")):
            raise UserError(f"{d} is a run of {' '.join(map(str, what))}, {run_dirs[0]} of {first.get('experiment')} "
                            f"{first.get('algo')} {first.get('preset')}: kept runs are one recipe over seeds")
        differ = sorted(k for k in set(meta.get("config", {})) | set(first.get("config", {}))
                        if k not in BUDGETS and meta.get("config", {}).get(k) != first.get("config", {}).get(k))
        if differ:
            raise UserError(f"{d} and {run_dirs[0]} differ in {', '.join(differ)}: kept runs are one recipe over seeds")
    seeds = [meta["seed"] for meta in metas]
    if len(set(seeds)) != len(seeds):
        raise UserError(f"two of the runs have the same seed ({', '.join(map(str, seeds))}): keep one run per seed")
    if not all(meta.get("evaluation") for meta in metas):
        raise UserError("a run has no evaluation on unseen seeds in its model/meta.json: evaluate it first "
                        "(main.py evaluate ... --model RUN_DIR --record)")
    exp = get_experiment(first["experiment"])
    fields = exp.shipped_by.fields if exp.shipped_by else ()
    preset = json.loads(json.dumps(to_dict(exp.preset(first["algo"], first.get("preset")))))  # as meta.json has it
    sweep = {"experiment": first["experiment"], "algo": first["algo"], "name": dest.name,
             "seeds": sorted(seeds), "grid": {}, "preset": first.get("preset"),
             # what the recipe set beside its preset (Mario: the level, the stop share, the precision)
             "overrides": {k: v for k, v in first["config"].items()
                           if k in fields or (k not in BUDGETS and preset.get(k) != v)}}
    pairs = [(d / name, f"seed={meta['seed']}/{name}") for d, meta in zip(run_dirs, metas) for name in kept_files(d)]
    return _keep_into(dest, pairs, sweep)


def keep(sweep_dir: Path, dest: Path) -> Path:
    """Copy ``sweep.json`` and, per run, :data:`KEPT_FILES` of ``sweep_dir``
    into ``dest``, a folder git keeps (``results/sweeps/NAME``); a report of ``dest`` then gives the
    same numbers. Returns ``dest``."""
    sweep_dir, dest = Path(sweep_dir), Path(dest)
    runs = load_runs(sweep_dir)  # refuses a folder with no finished run before anything is copied
    copies = [(sweep_dir / "sweep.json", "sweep.json")] if (sweep_dir / "sweep.json").is_file() else []
    for run in runs:
        copies += [(run["run_dir"] / name, f"{run['trial']}/{name}") for name in kept_files(run["run_dir"])]
    return _keep_into(dest, copies)


# --------------------------------------------------------------------------------------- report
def setting_of(trial: str) -> str:
    """``lr=0.0001__seed=3`` -> ``lr=0.0001``: the grid values, which group runs across seeds."""
    return "__".join(part for part in trial.split("__") if not part.startswith("seed="))


def summarize(sweep_dirs: list[Path], reps: int = 5000) -> dict:
    """Everything ``main.py report`` prints, as numbers: one group per sweep and grid setting."""
    groups = []
    for folder in sweep_dirs:
        runs = load_runs(folder)
        settings = sorted({setting_of(r["trial"]) for r in runs})
        for setting in settings:
            members = [r for r in runs if setting_of(r["trial"]) == setting]
            scores = np.array([[r["score"]] for r in members])
            point, ci = stratified_bootstrap_ci(aggregates, scores, reps=reps)
            label = Path(folder).name + (f" [{setting}]" if setting else "")
            groups.append({"folder": Path(folder), "label": label, "runs": members,
                           "aggregates": {name: (float(point[i]), float(ci[0][i]), float(ci[1][i]))
                                          for i, name in enumerate(AGGREGATES)}})
    result = {"sweeps": groups}
    if len(groups) == 2:
        x, y = (np.array([[r["score"]] for r in g["runs"]]) for g in groups)
        point, ci = stratified_bootstrap_ci(lambda a, b: probability_of_improvement(a, b), x, y, reps=reps)
        result["probability_of_improvement"] = (float(point), float(ci[0]), float(ci[1]))
    return result


def share_text(share: float | None) -> str:
    return "–" if share is None else f"{share:.0%}"


def markdown(result: dict) -> str:
    lines = []
    for s in result["sweeps"]:
        lines += [f"## {s['label']} ({s['folder']})", "",
                  "| run | seed | final score (unseen seeds) | to time limit | env steps | wall | env steps/s | CPU |",
                  "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
        lines += [f"| {r['trial']} | {r['seed']} | {r['score']:.3f} | {share_text(r.get('time_limit_share'))} "
                  f"| {r['env_steps']:,} | {r['wall_seconds']:.0f} s | {r['env_steps'] / max(r['wall_seconds'], 1e-9):,.0f} "
                  f"| {r.get('cpu') or 'not recorded'} |" for r in s["runs"]]
        lines += ["", f"| over {len(s['runs'])} runs | point | 95% CI (stratified bootstrap) |",
                  "| --- | ---: | --- |"]
        lines += [f"| {name} | {p:.3f} | [{lo:.3f}, {hi:.3f}] |" for name, (p, lo, hi) in s["aggregates"].items()]
        if any(r.get("further") for r in s["runs"]):
            lines += ["", "Further evaluations on other unseen seeds (`evaluate --record-further`), each run's in order:",
                      ""] + [f"- {r['trial']}: " + ("; ".join(f"{score:.3f} over {episodes} episodes"
                                                             for episodes, score in r["further"]) or "none")
                             for r in s["runs"]]
        lines += ["", *stability_lines(s["runs"]), ""]
        if critic := critic_lines(s["runs"]):
            lines += [*critic, ""]
    if "probability_of_improvement" in result:
        p, lo, hi = result["probability_of_improvement"]
        first, second = (s["label"] for s in result["sweeps"])
        lines += [f"P({first} > {second}) = {p:.3f} [{lo:.3f}, {hi:.3f}]", ""]
    return "\n".join(lines)


def stability_lines(runs: list[dict]) -> list[str]:
    """What the runs' periodic evaluations (on selection seeds) say: collapses and the weights kept
    (:mod:`rlcore.eval_history` defines a collapse)."""
    stories = [r["story"] for r in runs]
    if not any(st.evaluations for st in stories):
        return ["No periodic evaluations: each model holds its run's last weights."]
    lines = [f"Periodic evaluations (selection seeds): {stability_summary(stories)}", ""]
    lines += [f"- {r['trial']}: {story_text(r['story'])}" for r in runs]
    return lines


def critic_lines(runs: list[dict]) -> list[str]:
    """Each run's critic at its end beside the largest return it was paid (:mod:`rlcore.critic_trace`);
    nothing for runs that log no Q."""
    from rlcore.critic_trace import WINDOW, critic_cell, critic_trace

    traces = [critic_trace(r["run_dir"]) for r in runs]
    if all(t is None for t in traces):
        return []
    return [f"Critic: the mean Q of its training batches at the end of each run (median of its last {WINDOW} "
            f"episodes), beside the largest return of any of its training episodes (– where a run logs no Q); "
            f"report_critic.png draws that running median over training.", ""] + [
        f"- {r['trial']}: {critic_cell(t)}" for r, t in zip(runs, traces)]
