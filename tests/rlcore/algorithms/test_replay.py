import numpy as np

from rlcore.algorithms.replay import ReplayMemory


def test_ring_buffer_overwrites_oldest_and_round_trips():
    memory = ReplayMemory(3, (2,))
    for i in range(5):
        memory.add(np.full(2, i), i, float(i), np.full(2, i + 1), i == 4)
    assert len(memory) == 3
    assert sorted(memory.action.tolist()) == [2, 3, 4]
    copy = ReplayMemory(3, (2,))
    copy.load_state_dict(memory.state_dict())
    rng_a, rng_b = np.random.default_rng(0), np.random.default_rng(0)
    for a, b in zip(memory.sample(8, rng_a), copy.sample(8, rng_b)):
        np.testing.assert_array_equal(a, b)
    copy.add(np.zeros(2), 9, 0.0, np.zeros(2), False)  # position restored: overwrites the oldest (2)
    assert sorted(copy.action.tolist()) == [3, 4, 9]


def test_sample_returns_consistent_transitions():
    memory = ReplayMemory(100, (1,))
    for i in range(50):
        memory.add([i], i % 4, float(i), [i + 1], i % 3 == 0)
    obs, action, reward, next_obs, terminated = memory.sample(32, np.random.default_rng(1))
    np.testing.assert_array_equal(next_obs[:, 0], obs[:, 0] + 1)
    np.testing.assert_array_equal(reward, obs[:, 0])
    np.testing.assert_array_equal(action, obs[:, 0] % 4)  # every field from the same row
    np.testing.assert_array_equal(terminated, obs[:, 0] % 3 == 0)
    assert 0 < terminated.sum() < 32
    assert obs.dtype == np.float32 and action.dtype == np.int32
