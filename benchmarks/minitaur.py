#!/usr/bin/env python3
"""Minitaur SAC speed, one JSON line per measurement.

  python benchmarks/minitaur.py                  # env alone, act, train step
  python benchmarks/minitaur.py --train-steps 20000   # also: end-to-end training env steps/s

Measurements:
  env_random   env steps/s of our pybullet Minitaur (5 physics substeps each), random actions
  render       seconds per rgb_array frame (CPU TinyRenderer)
  act          one sampled action: numpy actor forward
  train_step   one SAC gradient step (critics, actor, temperature, targets), alone and K per call
  train        end-to-end env steps/s of the default preset for N steps (incl. 10k random ones)
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
from common import emit  # noqa: E402

from minitaur.experiment import EXPERIMENT  # noqa: E402

CFG = EXPERIMENT.preset("sac", "default")


def bench_env(seconds: float):
    env = EXPERIMENT.make_env()
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    steps, resets, start = 0, 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 8))
        steps += 1
        if terminated or truncated:
            env.reset()
            resets += 1
    emit(bench="env_random", steps_per_s=round(steps / (time.perf_counter() - start)), resets=resets)
    env.close()
    env = EXPERIMENT.make_env(render_mode="rgb_array")
    env.reset(seed=0)
    start = time.perf_counter()
    for _ in range(10):
        env.step(np.zeros(8))
        frame = env.render()
    emit(bench="render", size=list(frame.shape), seconds_per_frame=round((time.perf_counter() - start) / 10, 3))
    env.close()


def _time(fn, n):
    for _ in range(3):
        fn()
    start = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - start) / n * 1e3


def bench_agent():
    from rlcore.algorithms.sac.agent import SACAgent

    rng = np.random.default_rng(0)
    obs = rng.normal(size=(1, 28)).astype(np.float32)
    agent = SACAgent(28, 8, dataclasses.replace(CFG, updates_per_call=1))
    emit(bench="act", ms=round(_time(lambda: agent.act(obs, rng), 2000), 4))
    for k in (1, 4, 8):  # 4 is the default: 8 and 16 cost more per update on 2 cores
        agent = SACAgent(28, 8, dataclasses.replace(CFG, updates_per_call=k))
        b = CFG.batch_size
        batch = (rng.normal(size=(k, b, 28)).astype(np.float32), rng.uniform(-1, 1, (k, b, 8)).astype(np.float32),
                 rng.normal(size=(k, b)).astype(np.float32), rng.normal(size=(k, b, 28)).astype(np.float32),
                 np.zeros((k, b), np.float32))
        ms = _time(lambda: agent.train_steps(*batch, rng), 200)
        emit(bench="train_step", updates_per_call=k, ms_per_call=round(ms, 2), ms_per_update=round(ms / k, 2))


def bench_train(steps: int):
    from rlcore.algorithms.sac import train as sac
    from rlcore.training.spec import RunSpec

    cfg = dataclasses.replace(CFG, max_env_steps=steps, eval_every_steps=0, keep_best=False)
    spec = RunSpec(EXPERIMENT, "sac", "default", cfg, 0, "off", Path(tempfile.mkdtemp(prefix="bench_")),
                   command="benchmark", progress=False)
    with contextlib.redirect_stdout(sys.stderr):
        model_dir = sac.train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    emit(bench="train", env_steps=meta["env_steps"], random_steps=cfg.learning_starts,
         wall_seconds=meta["wall_seconds"], env_steps_per_s=round(meta["env_steps"] / meta["wall_seconds"], 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--train-steps", type=int, default=0, help="also time N steps of training")
    args = parser.parse_args()
    bench_env(args.seconds)
    bench_agent()
    if args.train_steps:
        bench_train(args.train_steps)


if __name__ == "__main__":
    main()
