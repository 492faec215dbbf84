"""More of what users bring (issue 65): env classes as tutorials write them, registered in every form
``gym.register`` takes. Importing this module registers them.

- ``Bare-v0``: a class whose ``__init__`` takes no arguments (no render_mode, no render);
- ``Own-v0``: a class with its own parameter (``target``), given by the registration's kwargs;
- ``Capped-v0``: registered with ``max_episode_steps`` (its own episodes never end);
- ``Made-v0``: an entry point that is a function, not a class.
"""
import gymnasium as gym
import numpy as np


class Bare(gym.Env):
    def __init__(self):
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.action_space = gym.spaces.Discrete(2)
        self.steps = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.steps = 0
        return self._obs(), {}

    def _obs(self):
        return self.np_random.uniform(-1, 1, 2).astype(np.float32)

    def step(self, action):
        self.steps += 1
        return self._obs(), float(action), self.steps >= 10, False, {}


class Own(Bare):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, target: int = 1, render_mode=None):
        super().__init__()
        self.target, self.render_mode = target, render_mode

    def step(self, action):
        obs, _, terminated, truncated, info = super().step(action)
        return obs, float(action == self.target), terminated, truncated, info

    def render(self):
        return np.full((16, 16, 3), 100 * self.target, np.uint8)


class Endless(Bare):
    def step(self, action):
        obs, reward, _, truncated, info = super().step(action)
        return obs, reward, False, truncated, info


def make_made(**kwargs):
    return Bare()


gym.register("Bare-v0", entry_point=Bare)
gym.register("Own-v0", entry_point="tests.user_envs_more:Own", kwargs={"target": 0})
gym.register("Capped-v0", entry_point=Endless, max_episode_steps=7)
gym.register("Made-v0", entry_point=make_made)
