"""The env pool: same results in every mode, a dead worker is a clear error, close leaves nothing."""
import os
import signal
import time
from functools import partial

import gymnasium as gym
import numpy as np
import pytest

from rlcore.environments.vector import EnvPool, EnvWorkerDied, bootstrap_observations

N = 3
make_cartpole = partial(gym.make, "CartPole-v1")


def rollout(pool, steps=60):
    """Fixed action sequence; returns everything the pool gave back."""
    obs, _ = pool.reset(seed=[10 + i for i in range(N)])
    trace = [obs]
    for t in range(steps):
        actions = np.array([(t + i) % 2 for i in range(N)])
        obs, rewards, terminated, truncated, infos = pool.step(actions)
        trace += [obs, rewards, terminated, truncated, bootstrap_observations(obs, infos)]
    return trace


def sequential(steps=60):
    """The same by hand: one env at a time, reset on episode end."""
    envs = [make_cartpole() for _ in range(N)]
    obs = [env.reset(seed=10 + i)[0] for i, env in enumerate(envs)]
    trace = [np.stack(obs)]
    for t in range(steps):
        step = [env.step((t + i) % 2) for i, env in enumerate(envs)]
        final = np.stack([s[0] for s in step])
        for i, (o, r, term, trunc, _) in enumerate(step):
            if term or trunc:
                obs[i] = envs[i].reset()[0]
            else:
                obs[i] = o
        trace += [np.stack(obs), np.array([s[1] for s in step]), np.array([s[2] for s in step]),
                  np.array([s[3] for s in step]), final]
    return trace


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.parametrize("mode", ["inline", "processes"])
def test_pool_matches_a_sequential_loop(mode):
    with EnvPool([make_cartpole] * N, mode=mode) as pool:
        got = rollout(pool)
    want = sequential()
    assert any(t.any() for t in want[3::5]), "the rollout should cross an episode end"
    for a, b in zip(got, want):
        np.testing.assert_allclose(a, b, rtol=1e-6)


def test_killed_worker_is_a_clear_error_and_nothing_is_left():
    pool = EnvPool([make_cartpole] * N, mode="processes", step_timeout=10)
    pool.reset(seed=0)
    pids = pool.worker_pids()
    assert len(pids) == N and all(alive(p) for p in pids)
    os.kill(pids[1], signal.SIGKILL)
    start = time.perf_counter()
    with pytest.raises(EnvWorkerDied, match=rf"env worker 1 \(pid {pids[1]}\) killed by signal 9"):
        for _ in range(5):
            pool.step(np.zeros(N, np.int64))
    assert time.perf_counter() - start < 5
    time.sleep(0.2)
    assert not any(alive(p) for p in pids)


def test_close_joins_every_worker():
    pool = EnvPool([make_cartpole] * N, mode="processes")
    pool.reset(seed=0)
    pids = pool.worker_pids()
    pool.close()
    assert not any(alive(p) for p in pids)
    pool.close()  # twice is fine


def test_bootstrap_observations_use_the_final_observation():
    next_obs = np.zeros((3, 2))
    final = np.empty(3, dtype=object)  # how Gymnasium batches final_obs: objects, None where not done
    final[1] = np.ones(2)
    infos = {"_final_obs": np.array([False, True, False]), "final_obs": final}
    boot = bootstrap_observations(next_obs, infos)
    np.testing.assert_array_equal(boot, [[0, 0], [1, 1], [0, 0]])
    assert next_obs.sum() == 0  # not modified in place
