"""Replay memories as preallocated numpy ring buffers: full transitions, or frames kept once."""
from __future__ import annotations

import numpy as np

from rlcore.errors import UserError
from rlcore.host.machine import available_memory


class ReplayMemory:
    """Fixed-capacity FIFO of transitions (obs, action, reward, next_obs, terminated).

    ``terminated`` is stored rather than ``done``: a time-limit truncation must still bootstrap.
    """

    FIELDS = ("obs", "action", "reward", "next_obs", "terminated")

    def __init__(self, capacity: int, obs_shape: tuple[int, ...], obs_dtype=np.float32,
                 action_shape: tuple[int, ...] = (), action_dtype=np.int32):
        self.capacity = int(capacity)
        self.obs = np.zeros((capacity, *obs_shape), dtype=obs_dtype)
        self.next_obs = np.zeros((capacity, *obs_shape), dtype=obs_dtype)
        self.action = np.zeros((capacity, *action_shape), dtype=action_dtype)
        self.reward = np.zeros((capacity,), dtype=np.float32)
        self.terminated = np.zeros((capacity,), dtype=np.float32)
        self.position = 0
        self.size = 0

    def __len__(self) -> int:
        return self.size

    def add(self, obs, action, reward, next_obs, terminated) -> None:
        i = self.position
        self.obs[i] = obs
        self.action[i] = action
        self.reward[i] = reward
        self.next_obs[i] = next_obs
        self.terminated[i] = terminated
        self.position = (i + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)

    def sample(self, batch_size: int, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
        """A uniform minibatch (with replacement), in :attr:`FIELDS` order."""
        idx = rng.integers(0, self.size, size=batch_size)
        return tuple(getattr(self, name)[idx] for name in self.FIELDS)

    def sample_stacked(self, k: int, batch_size: int, rng: np.random.Generator) -> list[np.ndarray]:
        """``k`` minibatches stacked on a leading axis (for K gradient steps in one compiled call);
        the same draw as one ``sample(k * batch_size)``."""
        return [x.reshape(k, batch_size, *x.shape[1:]) for x in self.sample(k * batch_size, rng)]

    def state_dict(self) -> dict[str, np.ndarray]:
        """Arrays for a checkpoint (only the filled part)."""
        state = {name: getattr(self, name)[: self.size] for name in self.FIELDS}
        state["position"] = np.array(self.position)
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        size = len(state["reward"])
        if size > self.capacity:
            raise ValueError(f"checkpoint holds {size} transitions, memory capacity is {self.capacity}")
        for name in self.FIELDS:
            getattr(self, name)[:size] = state[name]
        self.size = size
        self.position = int(state["position"]) % self.capacity

    @property
    def full(self) -> bool:
        return self.size == self.capacity

    @property
    def nbytes(self) -> int:
        """What its arrays take, allocated in full."""
        return sum(getattr(self, name).nbytes for name in self.FIELDS)


class FrameStackReplay:
    """A replay memory for stacks of ``k`` frames (H x W x k, ``uint8``) that keeps each frame once.

    Consecutive observations of a stacked env share k - 1 frames, so each transition adds only the
    newest frame of its next observation (an episode's first transition adds its k starting frames
    too). A transition's observation is the k frames before its own, its next observation those k
    frames shifted by one. For 84 x 84 x 4 Atari stacks this is ~7.1 KB per transition instead of the
    56 KB of two full stacks: 100,000 transitions take ~0.7 GB (:attr:`nbytes`; a test measures it).

    Slots form a ring of ``capacity`` frames; a transition is drawn only while all k + 1 of its frames
    are still in it. Same interface as :class:`ReplayMemory`.
    """

    FIELDS = ReplayMemory.FIELDS

    def __init__(self, capacity: int, obs_shape: tuple[int, ...]):
        *frame_shape, self.k = obs_shape
        self.capacity = int(capacity)
        if self.capacity <= self.k:
            raise ValueError(f"a frame-stack memory needs more than {self.k} slots, not {capacity}")
        self.frames = np.zeros((self.capacity, *frame_shape), np.uint8)
        self.action = np.zeros((self.capacity,), np.int32)
        self.reward = np.zeros((self.capacity,), np.float32)
        self.terminated = np.zeros((self.capacity,), np.float32)
        self.ends_transition = np.zeros((self.capacity,), bool)  # the slot is a transition's newest frame
        self.written = 0  # slots written since the start (the ring's position is written % capacity)
        self._last_next = None

    def _write(self, frame, ends: bool, action=0, reward=0.0, terminated=0.0) -> None:
        i = self.written % self.capacity
        self.frames[i], self.ends_transition[i] = frame, ends
        self.action[i], self.reward[i], self.terminated[i] = action, reward, terminated
        self.written += 1

    def add(self, obs, action, reward, next_obs, terminated) -> None:
        if self._last_next is None or not np.array_equal(obs, self._last_next):  # an episode's start
            for j in range(self.k):
                self._write(obs[..., j], False)
        self._write(next_obs[..., -1], True, action, reward, terminated)
        self._last_next = np.array(next_obs)

    def _first_drawable(self) -> int:
        """The oldest slot (absolute) that can end a drawable transition: all k frames before it are kept."""
        return max(0, self.written - self.capacity + self.k)

    def __len__(self) -> int:
        count = int(self.ends_transition.sum())
        if self.written > self.capacity:  # the transitions among the k oldest slots have lost frames
            oldest = np.arange(self.written - self.capacity, self._first_drawable()) % self.capacity
            count -= int(self.ends_transition[oldest].sum())
        return count

    @property
    def full(self) -> bool:
        """Every slot written: it holds what it can (fewer transitions than slots, k frames per episode start)."""
        return self.written >= self.capacity

    def _stacks(self, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(obs, next_obs) of the transitions ending at absolute slots ``ends``, H x W x k each."""
        window = (ends[:, None] - self.k + np.arange(self.k + 1)) % self.capacity  # k + 1 frames each
        frames = np.moveaxis(self.frames[window], 1, -1)  # (B, H, W, k + 1)
        return frames[..., :-1], frames[..., 1:]

    def sample(self, batch_size: int, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
        """A uniform minibatch (with replacement) in :attr:`FIELDS` order: slots drawn among the kept ones,
        those that end no transition (an episode's starting frames, a few in a hundred) drawn again."""
        first, ends = self._first_drawable(), np.empty(0, np.int64)
        while len(ends) < batch_size:
            drawn = rng.integers(first, self.written, size=batch_size - len(ends) + 8)
            ends = np.concatenate([ends, drawn[self.ends_transition[drawn % self.capacity]]])
        ends = ends[:batch_size]
        obs, next_obs = self._stacks(ends)
        i = ends % self.capacity
        return obs, self.action[i], self.reward[i], next_obs, self.terminated[i]

    def sample_stacked(self, k: int, batch_size: int, rng: np.random.Generator) -> list[np.ndarray]:
        return [x.reshape(k, batch_size, *x.shape[1:]) for x in self.sample(k * batch_size, rng)]

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.frames, self.action, self.reward, self.terminated, self.ends_transition))

    ARRAYS = ("frames", "action", "reward", "terminated", "ends_transition")

    def state_dict(self) -> dict[str, np.ndarray]:
        """The slots written, in ring order (views: a checkpoint of 0.7 GB of frames makes no second copy),
        and the count written."""
        used = min(self.written, self.capacity)
        return {**{name: getattr(self, name)[:used] for name in self.ARRAYS}, "written": np.array(self.written)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        if "frames" not in state:
            raise ValueError("the replay file holds full observations, not frames")
        written, used = int(state["written"]), len(state["frames"])
        if used > self.capacity or (written > used and used != self.capacity):
            raise ValueError(f"checkpoint holds a ring of {used} frames, memory capacity is {self.capacity}")
        for name in self.ARRAYS:
            getattr(self, name)[:used] = state[name]
        self.written, self._last_next = written, None


def replay_memory(capacity: int, env):
    """The memory for ``env``: :class:`FrameStackReplay` where a wrapper says it stacks frames on the
    last axis (``stacked_frames``, the Atari preprocessing), else :class:`ReplayMemory` (``uint8`` images);
    one line instead when it would not fit in the machine's free memory."""
    space = env.observation_space
    shape = tuple(space.shape)
    try:
        stacked = env.get_wrapper_attr("stacked_frames")
    except AttributeError:
        stacked = None
    if stacked and len(shape) == 3 and shape[-1] == stacked:
        check_fits(capacity, capacity * (int(np.prod(shape[:-1])) + 13))  # a frame, action, reward, ends
        return FrameStackReplay(capacity, shape)
    dtype = np.dtype(np.uint8 if len(shape) == 3 and space.dtype == np.uint8 else np.float32)
    check_fits(capacity, capacity * (2 * int(np.prod(shape)) * dtype.itemsize + 12))  # obs twice, action, reward, terminated
    return ReplayMemory(capacity, shape, dtype)


def check_fits(capacity: int, nbytes: int) -> None:
    """A one-line error where a memory of ``nbytes`` exceeds what the machine has free: its arrays are only
    touched as it fills, so one too large would end the run hours later, or not start at all."""
    free = available_memory()
    if free is not None and nbytes > free:
        raise UserError(f"--buffer-size {capacity:,}: a replay memory of {nbytes / 1e9:.1f} GB, and this machine "
                        f"has {free / 1e9:.1f} GB free; give a smaller --buffer-size")
