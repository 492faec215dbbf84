"""A user's own env module, as docs/api.md shows one: a Gymnasium env class and its registration.

Importing this module registers ``Chase-v0``: the observation is a target in [-1, 1]; action 1 pays +1
when the target is positive, action 0 when it is negative; 20 steps per episode.
"""
import gymnasium as gym
import numpy as np


class ChaseEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, render_mode=None):
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)
        self.action_space = gym.spaces.Discrete(2)
        self.render_mode = render_mode

    def _obs(self):
        return np.array([self.target, 0.5, -0.5], np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.target = float(self.np_random.uniform(-1, 1))
        return self._obs(), {}

    def step(self, action):
        reward = float((action == 1) == (self.target > 0))
        self.target = float(self.np_random.uniform(-1, 1))
        return self._obs(), reward, False, False, {}

    def render(self):
        frame = np.zeros((32, 32, 3), np.uint8)
        frame[:, : 16 if self.target > 0 else 32] = 200
        return frame


gym.register("Chase-v0", entry_point="tests.user_env:ChaseEnv", max_episode_steps=20, reward_threshold=19.0)
