"""What the benchmark scripts share: one JSON line per measurement, and the raw env step rate."""
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
