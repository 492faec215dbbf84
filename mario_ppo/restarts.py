"""Training episodes that start further into the level, where an earlier episode of the same env got.

A level with one hard place far from the start (2-1's springboard before the last wall, ~x 3,000) gives
the policy few tries there: in 3,000 training episodes 235 reached it and 21 got over. Starting a share
of the training episodes from a state the agent itself reached just before that place gives it many
more tries, while the other episodes keep training the whole level. This is the "restart from a
visited state" idea of Go-Explore (Ecoffet et al. 2021) and of learning from a demonstration's states
(Salimans & Chen 2018), with the agent's own play as the source: nothing is hand-made.

Evaluation never uses it: ``restart_x`` is a training-only setting (``Experiment.train_env_fields``),
so every evaluation and video starts at the level's start. Restarted episodes are marked
(``info["restarted"]``) and left out of the flag share that the stop rule reads.

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym


class Restarts(gym.Wrapper):
    """Start a ``share`` of episodes from the state in which an earlier episode first passed ``x``.

    Wraps the emulator with its buttons (``JoypadSpace``), below every reward and frame wrapper, so
    they all see a restart as an ordinary reset. Each time an episode that started at the level's
    start passes ``x`` alive, the emulator's state is kept (replacing the one kept before, so the
    restart point follows the current policy). From then on, each reset loads it with probability
    ``share``, drawn from the env's seeded RNG. The kept state lives in this env only: a fresh env
    (a resumed run, say) starts every episode at the level's start until one passes ``x`` again.
    """

    def __init__(self, env: gym.Env, x: int, share: float):
        super().__init__(env)
        self.x, self.share = x, share
        self._snapshot = None
        self._restarted = False
        self._below = True

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._restarted = self._snapshot is not None and self.np_random.random() < self.share
        if self._restarted:
            base = self.env.unwrapped
            base.load_state(self._snapshot)
            base._did_reset()  # the env's own "last" counters (time, x, score) from the loaded state
            obs, info = base.screen, base._get_info()
        self._below = info["x_pos"] < self.x
        info["restarted"] = self._restarted
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        passed = self._below and info["x_pos"] >= self.x
        if passed and not (self._restarted or terminated or truncated or info.get("is_dying")):
            self._snapshot = self.env.unwrapped.dump_state()
        self._below = info["x_pos"] < self.x
        info["restarted"] = self._restarted
        return obs, reward, terminated, truncated, info
