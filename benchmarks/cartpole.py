#!/usr/bin/env python3
"""CartPole speed, one JSON line per measurement.

  python benchmarks/cartpole.py              # env floor + pool scaling (no TensorFlow needed)
  python benchmarks/cartpole.py --train a2c  # also: train the default preset, wall time and steps/s

Measurements:
  env_random   one in-process CartPole-v1 env, random actions: the floor
  pool         agent steps/s of the env pool, inline vs processes, with 1, 2, 4, 8 envs
  train        env steps/s and wall seconds of a training run (default preset), and its best evaluation
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from common import emit, pool_rate, random_env_rate  # noqa: E402

from cartpole.experiment import make_env  # noqa: E402


def bench_env():
    emit(bench="env_random", env="CartPole-v1", steps_per_s=random_env_rate(make_env))


def bench_pool(seconds=3.0):
    for mode in ("inline", "processes"):
        for n in (1, 2, 4, 8):
            startup, rate = pool_rate(make_env, n, mode, n_actions=2, seconds=seconds)
            emit(bench="pool", env="CartPole-v1", mode=mode, num_envs=n, startup_s=round(startup, 2),
                 agent_steps_per_s=round(rate))


def bench_train(algo: str, experiment: str, no_eval: bool = False):
    import tempfile

    from rlcore.algorithms.registry import family
    from rlcore.environments.registry import get_experiment
    from rlcore.training.spec import RunSpec

    exp = get_experiment(experiment)
    cfg = exp.preset(algo, "default")
    if no_eval:  # the training loop alone: article 002 tests 10 episodes every 800 env steps
        cfg = dataclasses.replace(cfg, eval_every_steps=0, keep_best=False)
    spec = RunSpec(exp, algo, "default", cfg, 0, "off", Path(tempfile.mkdtemp(prefix="bench_")),
                   command="benchmark", progress=False)
    with contextlib.redirect_stdout(sys.stderr):  # stdout carries only the JSON lines
        model_dir = family(exp.algo(algo).kind).train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    emit(bench="train", experiment=experiment, algo=algo, preset="default", seed=0, periodic_eval=not no_eval,
         env_steps=meta["env_steps"], wall_seconds=meta["wall_seconds"],
         env_steps_per_s=round(meta["env_steps"] / meta["wall_seconds"]), best_eval=meta["best_eval"])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--train", choices=["dqn", "a2c"], default=None)
    parser.add_argument("--experiment", default="cartpole", choices=["cartpole", "cartpole_v0"])
    parser.add_argument("--no-eval", action="store_true", help="train without the periodic evaluations")
    parser.add_argument("--skip-pool", action="store_true", help="skip the env and pool measurements")
    args = parser.parse_args()
    if not args.skip_pool:
        bench_env()
        bench_pool()
    if args.train:
        bench_train(args.train, args.experiment, args.no_eval)


if __name__ == "__main__":
    main()
