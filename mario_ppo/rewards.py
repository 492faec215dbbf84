"""Mario's rewards: the classic per-frame reward and the article's shaping of an episode's end.

gym-super-mario-bros 9 pays a different reward (new-best x only, plus score, coins, power-ups and
a completion term, unclipped). The article trained on the classic one, rebuilt here from ``info``:
change of x (ignored when it jumps more than 5, e.g. on a warp), the clock's tick (-1 each time it
decreases), -25 while dying or dead, the sum clipped to [-15, 15]. The PyTorch original that the
default preset follows (uvipen's) also adds the change of the game score / 40 (``score_reward``
0.025): stomping a Goomba (100 points) then pays 2.5, a coin (200) 5. The article then adds +50 at the
flag, -50 at any other end, and divides by 10 (:class:`ArticleShaping`).

Its own module so that the wrappers that end an episode as a death (:mod:`mario_ppo.episode_ends`) take
the same penalty without importing the env stack. TensorFlow-free: env-pool worker processes import it.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np


def classic_reward(x_pos: int, x_last: int, time: int, time_last: int, dying: bool) -> float:
    """The pre-9.x per-frame reward of gym-super-mario-bros, from two consecutive infos."""
    dx = x_pos - x_last
    if dx < -5 or dx > 5:  # a warp or a reset, not running
        dx = 0
    dt = min(time - time_last, 0)  # the clock only counts down; an increase is a reset
    death = -25 if dying else 0
    return float(np.clip(dx + dt + death, -15, 15))


class ClassicReward(gym.Wrapper):
    """Replace the env's reward with :func:`classic_reward`, plus ``score_reward`` x the change of
    the game score (unclipped, as uvipen's); keep the env's own reward in ``info``."""

    def __init__(self, env: gym.Env, score_reward: float = 0.0):
        super().__init__(env)
        self.score_reward = score_reward

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._x_last, self._time_last, self._score_last = info["x_pos"], info["time"], info["score"]
        return obs, info

    def step(self, action):
        obs, env_reward, terminated, truncated, info = self.env.step(action)
        reward = classic_reward(info["x_pos"], self._x_last, info["time"], self._time_last,
                                info["is_dying"] or info["is_dead"])
        if self.score_reward:
            reward += self.score_reward * (info["score"] - self._score_last)
        self._x_last, self._time_last, self._score_last = info["x_pos"], info["time"], info["score"]
        info["env_reward"] = env_reward
        return obs, reward, terminated, truncated, info


class ArticleShaping(gym.Wrapper):
    """+50 when the episode ends at the flag, -50 when it ends otherwise, then every reward / 10.

    Only a real end (``terminated``) is shaped; a time-limit truncation is not an outcome.
    """
    END_BONUS, SCALE = 50.0, 10.0

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated:
            reward += self.END_BONUS if info["flag_get"] else -self.END_BONUS
        return obs, reward / self.SCALE, terminated, truncated, info


# what a wrapper that ends an episode as a death (a stall, a dead end) takes off: the shaped -50 / 10
DEATH_PENALTY = ArticleShaping.END_BONUS / ArticleShaping.SCALE
