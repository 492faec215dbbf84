"""Training episodes that start further into the level, where an earlier episode of the same env got.

A level with one hard place far from the start (2-1's springboard before the last wall, ~x 3,000) gives
the policy few tries there: in 3,000 training episodes 235 reached it and 21 got over. Starting a share
of the training episodes from a state the agent itself reached just before that place gives it many
more tries, while the other episodes keep training the whole level. This is the "restart from a
visited state" idea of Go-Explore (Ecoffet et al. 2021) and of learning from a demonstration's states
(Salimans & Chen 2018), with the agent's own play as the source: nothing is hand-made.

Two ways to say where: one x (``restart_x``, a known hard place), or every multiple of a spacing
(``restart_every``, for a level whose hard places are not known yet): a restarted episode then starts
at one of the kept points, drawn uniformly, so the far parts of the level get as many tries as the
near ones.

Evaluation never uses it: both are training-only settings (``Experiment.train_env_fields``), so
every evaluation and video starts at the level's start. Restarted episodes are marked
(``info["restarted"]``) and left out of the flag share that the stop rule reads.

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym


class Restarts(gym.Wrapper):
    """Start a ``share`` of episodes from a state in which an earlier episode passed a restart point.

    The points are ``x`` alone, or ``every``, 2 ``every``, 3 ``every``, ... Wraps the emulator with its
    buttons (``JoypadSpace``), below every reward and frame wrapper, so they all see a restart as an
    ordinary reset. Each time an episode passes a point alive, beyond the furthest point it had passed
    or started at, the emulator's state is kept for that point (replacing the one kept before, so the
    points follow the current policy). From then on, each reset loads one kept state with probability
    ``share``, the point drawn uniformly; both draws come from the env's seeded RNG. The kept states
    live in this env only: a fresh env (a resumed run, say) starts every episode at the level's start
    until one passes a point again.
    """

    def __init__(self, env: gym.Env, share: float, x: int = 0, every: int = 0):
        super().__init__(env)
        if bool(x) == bool(every):
            raise ValueError("give one of x (a single restart point) and every (a spacing)")
        self.x, self.every, self.share = x, every, share
        self._snapshots: dict[int, object] = {}  # point number -> emulator state
        self._restarted = False
        self._passed = 0

    def point(self, x_pos: int) -> int:
        """The number of the furthest restart point at or behind ``x_pos`` (0: none)."""
        if self.every:
            return x_pos // self.every
        return int(x_pos >= self.x)

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._restarted = bool(self._snapshots) and self.np_random.random() < self.share
        if self._restarted:
            points = sorted(self._snapshots)
            base = self.env.unwrapped
            base.load_state(self._snapshots[points[self.np_random.integers(len(points))]])
            base._did_reset()  # the env's own "last" counters (time, x, score) from the loaded state
            obs, info = base.screen, base._get_info()
        self._passed = self.point(info["x_pos"])
        info["restarted"] = self._restarted
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        reached = self.point(info["x_pos"])
        if reached > self._passed:
            if not (terminated or truncated or info.get("is_dying")):
                self._snapshots[reached] = self.env.unwrapped.dump_state()
            self._passed = reached
        info["restarted"] = self._restarted
        return obs, reward, terminated, truncated, info
