"""What the benchmark scripts share: one JSON line per measurement, the raw env step rate and a pool's."""
from __future__ import annotations

import json
import time

import numpy as np


def emit(**row) -> None:
    """Print one measurement as a JSON line (stdout carries nothing else)."""
    print(json.dumps(row), flush=True)


def random_env_rate(make_env, seconds: float = 3.0) -> int:
    """Env steps per second of one in-process env under uniformly random actions: the floor."""
    env = make_env()
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    n_actions = int(env.action_space.n)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = env.step(int(rng.integers(n_actions)))
        steps += 1
        if terminated or truncated:
            env.reset()
    env.close()
    return round(steps / (time.perf_counter() - start))


def pool_rate(make_env, num_envs: int, mode: str, n_actions: int, seconds: float) -> tuple[float, float]:
    """(startup seconds, agent steps per second) of an EnvPool of `num_envs` copies under random actions."""
    from rlcore.environments.vector import EnvPool

    rng = np.random.default_rng(0)
    started = time.perf_counter()
    with EnvPool([make_env] * num_envs, mode=mode) as pool:
        pool.reset(seed=0)
        startup = time.perf_counter() - started
        vector_steps, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            pool.step(rng.integers(0, n_actions, num_envs))
            vector_steps += 1
        elapsed = time.perf_counter() - start
    return startup, vector_steps * num_envs / elapsed
