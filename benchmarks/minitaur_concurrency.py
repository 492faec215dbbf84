#!/usr/bin/env python3
"""Minitaur SAC on this machine's cores: one run at a time, or two at once (issue 49's question).

  python benchmarks/minitaur_concurrency.py [--steps 9000] [--learning-starts 2000]

Starts `main.py train minitaur sac` (default preset, a short step budget, no periodic evaluation) as
separate processes, as a sweep's trials are, in three layouts, one after another:
  alone_1_thread    one run, TensorFlow on 1 thread (a sweep with --num-cpus 1, as the seeds run)
  alone_2_threads   one run, TensorFlow on 2 threads
  pair_1_thread     two runs at once, 1 thread each (a sweep with --num-cpus 2)
Each run's rate is read from its own metrics.csv: env steps per wall second between the first episode
that ends after learning starts (gradient steps from then on) and its last episode. One JSON line per
layout, then one comparing them: the hours five seeds of 1M steps would take each way.
Stop any training first: a run beside these would slow both and make the figures meaningless.
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from common import emit  # noqa: E402

from rlcore.host.cpu import cpu_description  # noqa: E402


def start(run_dir: Path, steps: int, learning_starts: int, threads: int, seed: int) -> subprocess.Popen:
    env = {**os.environ, "TF_NUM_INTRAOP_THREADS": str(threads), "TF_NUM_INTEROP_THREADS": "1",
           "TF_CPP_MIN_LOG_LEVEL": "3"}
    command = [sys.executable, str(ROOT / "main.py"), "train", "minitaur", "sac", "--steps", str(steps),
               "--learning-starts", str(learning_starts), "--eval-every-steps", "0", "--seed", str(seed),
               "--final-eval-episodes", "1", "--wandb", "off", "--no-progress", "--run-dir", str(run_dir)]
    return subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)


def learning_rate_of(run_dir: Path, learning_starts: int) -> float:
    """Env steps per wall second over the episodes that end after the first gradient step."""
    with open(run_dir / "metrics.csv", newline="") as f:
        rows = [(int(r["env_steps"]), float(r["wall_seconds"])) for r in csv.DictReader(f)]
    learning = [r for r in rows if r[0] > learning_starts]
    if len(learning) < 3:
        raise SystemExit(f"error: {run_dir} ended {len(learning)} episodes after learning began; "
                         "give more --steps")
    (s0, w0), (s1, w1) = learning[0], learning[-1]
    return (s1 - s0) / (w1 - w0)


def layout(name: str, root: Path, runs: int, threads: int, args) -> list[float]:
    procs = [(root / f"{name}_{i}", start(root / f"{name}_{i}", args.steps, args.learning_starts, threads, i))
             for i in range(runs)]
    for run_dir, proc in procs:
        _, err = proc.communicate()
        if proc.returncode != 0:
            raise SystemExit(f"error: {name} run {run_dir.name} exited {proc.returncode}: {err.strip()[-300:]}")
    rates = [learning_rate_of(run_dir, args.learning_starts) for run_dir, _ in procs]
    emit(bench="minitaur_concurrency", layout=name, runs=runs, tf_threads=threads,
         env_steps_per_s_each=[round(r, 1) for r in rates], env_steps_per_s_total=round(sum(rates), 1))
    return rates


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=9000, help="env steps of each run (default 9000)")
    parser.add_argument("--learning-starts", type=int, default=2000,
                        help="random steps before the first update (default 2000)")
    args = parser.parse_args()
    root = Path(tempfile.mkdtemp(prefix="bench_minitaur_concurrency_"))
    one = layout("alone_1_thread", root, 1, 1, args)[0]
    two_threads = layout("alone_2_threads", root, 1, 2, args)[0]
    pair = layout("pair_1_thread", root, 2, 1, args)
    seeds, steps = 5, 1_000_000
    # five trials on two slots: two pairs, then the fifth alone
    pair_hours = (2 * steps / min(pair) + steps / one) / 3600
    emit(bench="minitaur_concurrency_5_seeds_1M", one_at_a_time_1_thread_h=round(seeds * steps / one / 3600, 1),
         one_at_a_time_2_threads_h=round(seeds * steps / two_threads / 3600, 1),
         two_at_a_time_1_thread_each_h=round(pair_hours, 1), cpu=cpu_description())


if __name__ == "__main__":
    main()
