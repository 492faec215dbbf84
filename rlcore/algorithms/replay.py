"""Replay memory as preallocated numpy ring buffers."""
from __future__ import annotations

import numpy as np


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
