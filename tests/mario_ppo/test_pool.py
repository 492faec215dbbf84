"""The Mario env pool: emulator workers over Pipes match in-process envs; a dead one is a clear error."""
import os
import signal
import time

import numpy as np
import pytest

from mario_ppo.experiment import EXPERIMENT
from rlcore.environments.vector import EnvPool, EnvWorkerDied

N = 2


def _run(pool, steps=30):
    obs, _ = pool.reset(seed=list(range(N)))
    trace = [obs]
    for t in range(steps):
        obs, rewards, terminated, truncated, infos = pool.step(np.array([1, 4])[:N])
        trace += [obs, rewards, infos["x_pos"]]
    return trace


def test_process_pool_matches_inline_and_sends_frames_as_bytes():
    make = EXPERIMENT.env_factory(EXPERIMENT.preset("ppo", None))
    with EnvPool([make] * N, mode="processes") as pool:
        got = _run(pool)
        assert pool.single_observation_space.dtype == np.uint8
    with EnvPool([make] * N, mode="inline") as pool:
        want = _run(pool)
    assert got[-3].dtype == np.uint8 and got[-3].shape == (N, 84, 84, 4)
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)
    assert got[-1][0] != got[-1][1], "different actions should move Mario differently"


def test_a_killed_emulator_worker_is_named_and_nothing_is_left():
    make = EXPERIMENT.env_factory(EXPERIMENT.preset("ppo", None))
    pool = EnvPool([make] * N, mode="processes", step_timeout=10)
    pool.reset(seed=0)
    pids = pool.worker_pids()
    os.kill(pids[0], signal.SIGKILL)
    with pytest.raises(EnvWorkerDied, match=rf"env worker 0 \(pid {pids[0]}\) killed by signal 9"):
        for _ in range(5):
            pool.step(np.zeros(N, np.int64))
    time.sleep(0.3)
    for pid in pids:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
