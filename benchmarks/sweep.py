#!/usr/bin/env python3
"""Ray's overhead per trial: a sweep of N short runs against the same runs one after another.

  python benchmarks/sweep.py [--runs 4] [--episodes 60]

Both sides train the toy DQN task of the tests (seeds 0..N-1, the same budget) through the same
run_training function; the sweep runs them as Ray Tune trials on a local Ray with 2 CPUs, 1 per
trial. One JSON line: wall seconds of each side (the sweep's includes starting and stopping Ray)
and the overhead per trial. On 2 cores two trials run at once, so the sweep can also be faster.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from common import emit  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=4)
    parser.add_argument("--episodes", type=int, default=60)
    args = parser.parse_args()
    from rlcore.environments import registry
    from rlcore.sweeps.on_ray import run_sweep
    from rlcore.sweeps.sweep import Sweep
    from rlcore.training.run import build_spec, run_training

    registry.EXPERIMENT_MODULES["toy"] = "tests.toy"
    budget = {"max_episodes": args.episodes, "stop_score": 99.0}
    root = Path(tempfile.mkdtemp(prefix="bench_sweep_"))
    start = time.perf_counter()
    with contextlib.redirect_stdout(sys.stderr):
        for seed in range(args.runs):
            spec = build_spec("toy", "dqn", seed=seed, overrides=budget, run_dir=root / f"serial_{seed}",
                              wandb_mode="off", progress=False, command="benchmark")
            run_training(spec)
    serial = time.perf_counter() - start
    start = time.perf_counter()
    sweep = Sweep("toy", "dqn", "bench", str(root / "sweep"), list(range(args.runs)), {}, None, budget,
                  1.0, 0, 0)
    with contextlib.redirect_stdout(sys.stderr):
        rows = run_sweep(sweep, num_cpus=2)
    swept = time.perf_counter() - start
    assert all(r["error"] is None for r in rows), rows
    emit(bench="sweep_overhead", runs=args.runs, episodes=args.episodes, serial_s=round(serial, 1),
         sweep_s=round(swept, 1), overhead_per_trial_s=round((swept - serial) / args.runs, 2))


if __name__ == "__main__":
    main()
