#!/usr/bin/env python3
"""LunarLander speed, one JSON line per measurement.

  python benchmarks/lunar_lander.py dqn            # env floor, act/update costs, train to solved
  python benchmarks/lunar_lander.py a2c --skip-train

Measurements:
  env_random      raw env steps/s with random actions (render_mode=None): the floor
  act             one action: numpy forward (what training uses) vs a compiled Keras call
  update          one gradient step, alone and batched K per compiled call
  train_to_solved wall seconds and env steps until the 100-episode average reaches 200, default preset
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
from common import emit, random_env_rate  # noqa: E402

from lunar_lander.experiment import EXPERIMENT  # noqa: E402


def bench_env():
    emit(bench="env_random", env="LunarLander-v3", steps_per_s=random_env_rate(EXPERIMENT.make_env))


def _time(fn, n):
    for _ in range(5):
        fn()
    start = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - start) / n * 1e3


def bench_dqn_costs():
    import tensorflow as tf

    from rlcore.algorithms.dqn.agent import DQNAgent
    cfg = EXPERIMENT.preset("dqn", "default")
    agent = DQNAgent(8, 4, cfg)
    rng = np.random.default_rng(0)
    obs = rng.normal(size=(1, 8)).astype(np.float32)
    compiled = tf.function(lambda x: tf.argmax(agent.q_network(x), axis=1),
                           input_signature=[tf.TensorSpec([None, 8], tf.float32)])
    emit(bench="act", algo="dqn", numpy_ms=round(_time(lambda: agent.greedy_actions(obs), 2000), 4),
         tf_function_ms=round(_time(lambda: compiled(obs).numpy(), 2000), 4))

    def batch(k):
        b = cfg.batch_size
        return (rng.normal(size=(k, b, 8)).astype(np.float32), rng.integers(0, 4, (k, b)).astype(np.int32),
                rng.normal(size=(k, b)).astype(np.float32), rng.normal(size=(k, b, 8)).astype(np.float32),
                np.zeros((k, b), np.float32))
    for k in (1, 4):
        data = batch(k)
        ms = _time(lambda: agent.train_steps(*data), 300)
        emit(bench="update", algo="dqn", updates_per_call=k, ms_per_call=round(ms, 3),
             ms_per_update=round(ms / k, 3), tracing_count=agent._compiled(k).experimental_get_tracing_count())


def bench_train_to_solved(algo: str, seed: int, max_seconds: float):
    from rlcore.algorithms.registry import family
    from rlcore.training.session import TrainingSession
    from rlcore.training.spec import RunSpec
    from rlcore.training.stopping import Interrupted

    cfg = dataclasses.replace(EXPERIMENT.preset(algo, "default"), stop_score=EXPERIMENT.solved_score)
    run_dir = Path(tempfile.mkdtemp(prefix=f"bench_{algo}_"))
    spec = RunSpec(EXPERIMENT, algo, "default", cfg, seed, "off", run_dir, command="benchmark", progress=False)
    kind = EXPERIMENT.algo(algo).kind
    # stop (through the Ctrl-C path) once the time budget is spent
    original = TrainingSession.should_stop
    TrainingSession.should_stop = lambda self: original(self) or self.elapsed() > max_seconds
    start = time.perf_counter()
    try:
        with contextlib.redirect_stdout(sys.stderr):  # stdout carries only the JSON lines
            model_dir = family(kind).train(spec)
        meta = json.loads((model_dir / "meta.json").read_text())
    except Interrupted:
        meta = None
    wall = time.perf_counter() - start
    if meta is None:
        emit(bench="train_to_solved", algo=algo, seed=seed, solved=False, wall_seconds=round(wall, 1))
        return
    emit(bench="train_to_solved", algo=algo, preset="default", seed=seed,
         solved=meta["final_average"] >= EXPERIMENT.solved_score and meta["episodes"] < cfg.max_episodes,
         episodes=meta["episodes"], env_steps=meta["env_steps"], wall_seconds=meta["wall_seconds"],
         env_steps_per_s=round(meta["env_steps"] / meta["wall_seconds"]),
         final_average=meta["final_average"])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("algo", choices=list(EXPERIMENT.algos))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-seconds", type=float, default=1800, help="give up training after this long")
    parser.add_argument("--skip-train", action="store_true", help="only the quick measurements")
    args = parser.parse_args()
    bench_env()
    if EXPERIMENT.algo(args.algo).kind == "dqn":
        bench_dqn_costs()
    if not args.skip_train:
        bench_train_to_solved(args.algo, args.seed, args.max_seconds)


if __name__ == "__main__":
    main()
