"""FrameStackReplay (issue 65): each frame kept once, and every transition it hands back equal to the one
given, checked against the plain ReplayMemory's full copies; the ring, a checkpoint's round trip, and the
size of 100,000 Atari transitions, measured."""
import numpy as np
import psutil
import pytest

from rlcore.algorithms.replay import FrameStackReplay, ReplayMemory

K, SIDE = 4, 6


def episodes(rng, lengths, terminal=True):
    """Stacked observations as Gymnasium's FrameStackObservation gives them (newest frame last; the
    first observation repeats its frame), with an id per transition in ``action``."""
    transition = 0
    for length in lengths:
        frame = rng.integers(0, 256, (SIDE, SIDE), dtype=np.uint8)
        obs = np.stack([frame] * K, axis=-1)
        for step in range(length):
            frame = rng.integers(0, 256, (SIDE, SIDE), dtype=np.uint8)
            next_obs = np.concatenate([obs[..., 1:], frame[..., None]], axis=-1)
            yield obs, transition, float(rng.normal()), next_obs, float(terminal and step == length - 1)
            obs, transition = next_obs, transition + 1


def fill(capacity, lengths, seed=0):
    frames, full = FrameStackReplay(capacity, (SIDE, SIDE, K)), ReplayMemory(10_000, (SIDE, SIDE, K), np.uint8)
    for transition in episodes(np.random.default_rng(seed), lengths):
        frames.add(*transition)
        full.add(*transition)
    return frames, full


def assert_same_as_given(frames: FrameStackReplay, full: ReplayMemory, draws=500):
    obs, action, reward, next_obs, terminated = frames.sample(draws, np.random.default_rng(1))
    for i, t in enumerate(action):
        np.testing.assert_array_equal(obs[i], full.obs[t])
        np.testing.assert_array_equal(next_obs[i], full.next_obs[t])
        assert reward[i] == full.reward[t] and terminated[i] == full.terminated[t]
    return set(action.tolist())


def test_every_drawn_transition_is_the_one_given():
    frames, full = fill(1_000, [5, 1, 30, 12])
    assert len(frames) == len(full) == 48
    assert assert_same_as_given(frames, full) == set(range(48))  # all drawn, all exact
    assert frames.written == 48 + 4 * K  # a frame per step, plus each episode's K starting frames


def test_once_the_ring_wraps_only_whole_transitions_are_drawn():
    frames, full = fill(40, [25, 17, 30])  # 72 steps + 12 starting frames through 40 slots
    drawn = assert_same_as_given(frames, full)
    oldest = 72 - len(frames)
    assert drawn == set(range(oldest, 72)) and len(frames) <= 40 - K


def test_a_checkpoint_round_trip_gives_back_the_same_transitions():
    frames, full = fill(40, [25, 17, 30])
    again = FrameStackReplay(40, (SIDE, SIDE, K))
    again.load_state_dict(frames.state_dict())
    assert len(again) == len(frames)
    assert assert_same_as_given(again, full) == assert_same_as_given(frames, full)
    with pytest.raises(ValueError, match="full observations"):
        again.load_state_dict(full.state_dict())
    with pytest.raises(ValueError, match="ring of 40 frames, memory capacity is 60"):  # a wrapped ring: its own size
        FrameStackReplay(60, (SIDE, SIDE, K)).load_state_dict(frames.state_dict())


def test_an_unwrapped_memory_loads_into_a_larger_one_whole():
    frames, full = fill(40, [10, 12])
    larger = FrameStackReplay(100, (SIDE, SIDE, K))
    larger.load_state_dict(frames.state_dict())
    assert len(larger) == len(frames) == 22 and assert_same_as_given(larger, full) == set(range(22))


def test_a_full_memory_says_so_though_it_holds_fewer_transitions_than_slots():
    """Each episode's k starting frames take slots, so a frame memory never holds as many transitions as
    slots: the off-policy loop learns once it is full, whatever learning_starts asked (up to buffer_size)."""
    frames, _ = fill(20, [5] * 6)
    assert frames.full and len(frames) < 20
    assert not fill(20, [5])[0].full
def test_stacked_minibatches_keep_their_shapes():
    frames, _ = fill(200, [50, 50])
    obs, action, reward, next_obs, terminated = frames.sample_stacked(3, 8, np.random.default_rng(0))
    assert obs.shape == next_obs.shape == (3, 8, SIDE, SIDE, K) and obs.dtype == np.uint8
    assert action.shape == reward.shape == terminated.shape == (3, 8)


def test_100000_atari_transitions_stay_within_the_stated_size():
    """The docstring states ~0.7 GB for 100,000 transitions of 84 x 84 x 4 frames (two full stacks per
    transition would take 5.6 GB); the memory is filled, and the process's growth measured."""
    process = psutil.Process()
    before = process.memory_info().rss
    memory = FrameStackReplay(100_000, (84, 84, K))
    assert memory.nbytes < 0.72e9
    obs = np.zeros((84, 84, K), np.uint8)
    for step in range(100_000):
        next_obs = np.roll(obs, -1, axis=-1)
        next_obs[..., -1] = step % 251
        memory.add(obs, step % 6, 0.0, next_obs, 0.0)
        obs = next_obs
    grown = process.memory_info().rss - before
    assert len(memory) == 100_000 - K and grown < memory.nbytes + 50e6, (grown, memory.nbytes)


class _Env:
    """What replay_memory reads of an env: its observation space and the frame-stack marker."""

    def __init__(self, shape, dtype, stacked=None):
        import gymnasium as gym

        self.observation_space = gym.spaces.Box(0, 255, shape, dtype)
        self.stacked = stacked

    def get_wrapper_attr(self, name):
        if self.stacked is None:
            raise AttributeError(name)
        return self.stacked


@pytest.mark.parametrize("env, kind", [(_Env((84, 84, 4), np.uint8, stacked=4), FrameStackReplay),
                                       (_Env((96, 96, 3), np.uint8), ReplayMemory),
                                       (_Env((8,), np.float32), ReplayMemory)])
def test_a_memory_is_checked_against_free_memory_by_its_true_size(env, kind, monkeypatch):
    from rlcore.algorithms import replay
    from rlcore.errors import UserError

    memory = replay.replay_memory(1_000, env)
    assert type(memory) is kind
    monkeypatch.setattr(replay, "available_memory", lambda: memory.nbytes)
    replay.replay_memory(1_000, env)  # exactly what it takes fits
    monkeypatch.setattr(replay, "available_memory", lambda: memory.nbytes - 1)
    with pytest.raises(UserError, match=r"^--buffer-size 1,000: a replay memory of .* GB free; give a smaller"):
        replay.replay_memory(1_000, env)
