#!/usr/bin/env python3
"""Super Mario Bros PPO speed, one JSON line per measurement.

  python benchmarks/mario.py                 # emulator floor, pool scaling, PPO update, act
  python benchmarks/mario.py --train-rollouts 3   # also: end-to-end training frames per second

Measurements:
  emulator      NES frames/s of one raw SuperMarioBros-1-1-v0 env (no wrappers), random buttons
  env_wrapped   agent steps/s (and frames/s) of one env with the article's wrappers (skip 4), for
                each frame stack (--frames skipped | history)
  pool          agent steps/s of the env pool, processes over Pipes vs inline, with 1, 2, 4, 8 envs
  act           one batched action for 8 envs (compiled CNN forward + numpy sampling)
  update        one PPO update (10 epochs x 16 minibatches of 256 over 512 x 8), seconds
                (act, update and train run once per --precision: float32 and bfloat16 by default)
  train         end-to-end env steps/s and emulator frames/s of the default preset over N rollouts
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
from common import emit, pool_rate, random_env_rate  # noqa: E402

from mario_ppo.experiment import EXPERIMENT  # noqa: E402

CFG = EXPERIMENT.preset("ppo", "default")


def bench_emulator(seconds: float):
    import gym_super_mario_bros  # noqa: F401
    import gymnasium as gym

    rate = random_env_rate(lambda: gym.make("SuperMarioBros-1-1-v0").unwrapped, seconds)
    emit(bench="emulator", env="SuperMarioBros-1-1-v0", frames_per_s=rate)
    for frames in ("skipped", "history"):  # history grays 2 of a step's 4 frames, skipped all 4
        wrapped = random_env_rate(EXPERIMENT.env_factory(dataclasses.replace(CFG, frames=frames)), seconds)
        emit(bench="env_wrapped", frames=frames, agent_steps_per_s=wrapped, frames_per_s=wrapped * 4)


def bench_pool(seconds: float):
    make = EXPERIMENT.env_factory(CFG)
    for mode in ("processes", "inline"):
        for n in (1, 2, 4, 8):
            if mode == "inline" and n > 2:
                continue  # one process: no faster than the single env; shown for 1 and 2
            startup, rate = pool_rate(make, n, mode, n_actions=7, seconds=seconds)
            emit(bench="pool", mode=mode, num_envs=n, startup_s=round(startup, 2),
                 agent_steps_per_s=round(rate, 1))


def bench_agent(precision: str):
    from rlcore.algorithms.ppo.agent import PPOAgent

    cfg = dataclasses.replace(CFG, precision=precision)
    agent = PPOAgent((84, 84, 4), 7, cfg)
    rng = np.random.default_rng(0)
    obs = rng.integers(0, 256, (8, 84, 84, 4), dtype=np.uint8)
    for _ in range(5):
        agent.act(obs, rng)
    start, n = time.perf_counter(), 100
    for _ in range(n):
        agent.act(obs, rng)
    emit(bench="act", precision=precision, num_envs=8, ms=round((time.perf_counter() - start) / n * 1e3, 2))
    t, m = cfg.n_steps, cfg.num_envs
    rollout = (rng.integers(0, 256, (t, m, 84, 84, 4), dtype=np.uint8), rng.integers(0, 7, (t, m)).astype(np.int32),
               *(rng.normal(size=(t, m)).astype(np.float32) for _ in range(4)),
               np.zeros((t, m), np.float32), np.zeros((t, m), np.float32))
    start = time.perf_counter()
    agent.update(*rollout, rng)
    first = time.perf_counter() - start
    start = time.perf_counter()
    agent.update(*rollout, rng)
    emit(bench="update", precision=precision, transitions=t * m, epochs=cfg.epochs, minibatch=cfg.minibatch,
         first_call_s=round(first, 1), seconds=round(time.perf_counter() - start, 1))


def bench_train(rollouts: int, precision: str):
    from rlcore.algorithms.ppo import train as ppo
    from rlcore.training.spec import RunSpec

    steps = rollouts * CFG.n_steps * CFG.num_envs
    cfg = dataclasses.replace(CFG, max_env_steps=steps, precision=precision)
    spec = RunSpec(EXPERIMENT, "ppo", "default", cfg, 0, "off", Path(tempfile.mkdtemp(prefix="bench_")),
                   command="benchmark", progress=False)
    with contextlib.redirect_stdout(sys.stderr):
        model_dir = ppo.train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    emit(bench="train", precision=precision, rollouts=rollouts, env_steps=meta["env_steps"],
         wall_seconds=meta["wall_seconds"],
         env_steps_per_s=round(meta["env_steps"] / meta["wall_seconds"], 1),
         frames_per_s=round(4 * meta["env_steps"] / meta["wall_seconds"], 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=5.0, help="per env/pool measurement")
    parser.add_argument("--train-rollouts", type=int, default=0, help="also time N rollouts of training")
    parser.add_argument("--skip-pool", action="store_true")
    parser.add_argument("--skip-env", action="store_true", help="no emulator or wrapped-env rates")
    parser.add_argument("--precision", nargs="+", default=["float32", "bfloat16"], choices=["float32", "bfloat16"],
                        help="the CNN's compute precision(s) for act, update and train, side by side")
    args = parser.parse_args()
    if not args.skip_env:
        bench_emulator(args.seconds)
    if not args.skip_pool:
        bench_pool(args.seconds)
    for precision in args.precision:
        bench_agent(precision)
    if args.train_rollouts:
        for precision in args.precision:
            bench_train(args.train_rollouts, precision)


if __name__ == "__main__":
    main()
