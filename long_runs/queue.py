#!/usr/bin/env python3
"""Issue 49's trainings, one at a time and in order, each resumed where it stopped:

1. the Minitaur SAC sweep over seeds 0-4 (``long_runs/sweeps/minitaur__sac``, started by hand: the README
   beside this file), until every trial has finished;
2. Mario 1-1 over seeds 0-2 with the recipe fixed before the first run (the same README), each run then
   evaluated on 30 further unseen seeds; nothing once ``results/sweeps/mario_ppo__1-1`` is kept.

    .venv/bin/python long_runs/queue.py --dry-run     # the next command, from the folders' state
    setsid nohup .venv/bin/python long_runs/queue.py > /tmp/queue.log 2>&1 &

Each step is read from the folders when the step before it ends, so the queue can be stopped and started
again at any time. Stop it with SIGTERM or Ctrl-C to its process group (``kill -TERM -- -PGID``; the
queue prints its PGID): the running training writes its checkpoint and exits, and the queue starts
nothing more. A step that fails stops the queue with that step's exit status, and so does a step that
ends well but leaves the folders as they were (it would run again forever). Keeping a finished sweep
(``main.py report ... --keep``) and committing it are left to a person, who reads the result first.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # rlcore, from this checkout
MINITAUR = "long_runs/sweeps/minitaur__sac"
MARIO_KEPT = "results/sweeps/mario_ppo__1-1"
MARIO_SEEDS = (0, 1, 2)
# the recipe, fixed before the first run (issue 49): the default preset, a 0.9 flag share stops it
MARIO_RECIPE = ["--world", "1", "--stage", "1", "--stop-success-share", "0.9", "--precision", "bfloat16"]
QUIET = ["--wandb", "offline", "--no-progress"]


def mario_dir(seed: int) -> str:
    return f"long_runs/mario_ppo/1-1-seed-{seed}"


def next_command(repo: Path = REPO) -> list[str] | None:
    """The next step's ``main.py`` arguments, from the state of the folders under ``repo``; None when the
    queue has nothing left to run."""
    from rlcore.sweep import Sweep, trial_name

    minitaur = repo / MINITAUR
    if (minitaur / "sweep.json").is_file():
        sweep = Sweep.load(minitaur)
        done = _evaluated if sweep.final_eval_episodes != 0 else (lambda run: (run / "model" / "meta.json").is_file())
        if not all(done(minitaur / trial_name(trial)) for trial in sweep.trials()):  # its resume evaluates a trained one
            return ["sweep", "minitaur", "sac", "--dir", "long_runs/sweeps", "--name", "minitaur__sac", "--resume",
                    "--num-cpus", "1"]
    if (repo / MARIO_KEPT).exists():
        return None
    for seed in MARIO_SEEDS:
        run = repo / mario_dir(seed)
        meta = run / "model" / "meta.json"
        if meta.is_file():
            if not _evaluated(run):  # trained, but the process ended before its 10-episode evaluation
                return ["evaluate", "mario_ppo", "ppo", "--model", mario_dir(seed), "--record"]
            if not json.loads(meta.read_text()).get("further_evaluations"):
                return ["evaluate", "mario_ppo", "ppo", "--model", mario_dir(seed), "--episodes", "30",
                        "--record-further"]
            continue
        if (run / "checkpoint.npz").is_file():
            return ["train", "mario_ppo", "ppo", "--resume", mario_dir(seed), *QUIET]
        return ["train", "mario_ppo", "ppo", *MARIO_RECIPE, "--seed", str(seed), "--run-dir", mario_dir(seed), *QUIET]
    return None


def _evaluated(run: Path) -> bool:
    """The run has trained and its evaluation on unseen seeds is in its model's meta.json."""
    meta = run / "model" / "meta.json"
    return meta.is_file() and bool(json.loads(meta.read_text()).get("evaluation"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dry-run", action="store_true", help="print the next command and exit")
    args = parser.parse_args(argv)
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
            if command == done:  # it ended well and changed nothing: a trial that keeps failing, say
                print("queue: stopped: python main.py " + " ".join(command) + " ended with status 0 and left "
                      "the folders as they were; see its output above", flush=True)
                return 1
            print("queue: python main.py " + " ".join(command), flush=True)
            code = subprocess.call([sys.executable, "main.py", *command], cwd=REPO)
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
