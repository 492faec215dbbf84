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
(``info["restarted"]``) and left out of the flag share that the stop rule reads; ``info["start_x"]``
says where each episode started (metrics.csv: which points are hard).

A kept point is an emulator state and its route: the buttons, one per NES frame, that lead to it
from the level's start (through the routes of the restarts it came from). The emulator is
deterministic, so a checkpoint keeps the routes (``restart_routes``, a few KB each) and a resumed run
replays them to get its points back; the emulator's own state cannot be written to a file.

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np


class Restarts(gym.Wrapper):
    """Start a ``share`` of episodes from a state in which an earlier episode passed a restart point.

    The points are ``x`` alone, or ``every``, 2 ``every``, 3 ``every``, ... Wraps the emulator with its
    buttons (``JoypadSpace``), below every reward and frame wrapper, so they all see a restart as an
    ordinary reset. Each time an episode passes a point alive, beyond the furthest point it had passed
    or started at, the emulator's state is kept for that point (replacing the one kept before, so the
    points follow the current policy). From then on, each reset loads one kept state with probability
    ``share``, the point drawn uniformly; both draws come from the env's seeded RNG. The kept states
    live in this env; ``restart_routes`` gets and sets them as routes (a resumed run's pool sets what
    the checkpoint kept).
    """

    def __init__(self, env: gym.Env, share: float, x: int = 0, every: int = 0):
        super().__init__(env)
        if bool(x) == bool(every):
            raise ValueError("give one of x (a single restart point) and every (a spacing)")
        self.x, self.every, self.share = x, every, share
        self._snapshots: dict[int, tuple[object, bytes]] = {}  # point number -> (emulator state, route)
        self._restarted = False
        self._passed = 0
        self._start_x = 0
        self._route = bytearray()  # this episode's buttons, one per frame, from the level's start

    def point(self, x_pos: int) -> int:
        """The number of the furthest restart point at or behind ``x_pos`` (0: none)."""
        if self.every:
            return x_pos // self.every
        return int(x_pos >= self.x)

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._restarted = bool(self._snapshots) and self.np_random.random() < self.share
        self._route = bytearray()
        if self._restarted:
            points = sorted(self._snapshots)
            snapshot, route = self._snapshots[points[self.np_random.integers(len(points))]]
            base = self.env.unwrapped
            base.load_state(snapshot)
            base._did_reset()  # the env's own "last" counters (time, x, score) from the loaded state
            obs, info = base.screen, base._get_info()
            self._route = bytearray(route)
        self._passed = self.point(info["x_pos"])
        self._start_x = int(info["x_pos"])
        info["restarted"], info["start_x"] = self._restarted, self._start_x
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._route.append(int(action))
        reached = self.point(info["x_pos"])
        if reached > self._passed:
            if not (terminated or truncated or info.get("is_dying")):
                self._snapshots[reached] = (self.env.unwrapped.dump_state(), bytes(self._route))
            self._passed = reached
        info["restarted"], info["start_x"] = self._restarted, self._start_x
        return obs, reward, terminated, truncated, info

    @property
    def restart_routes(self) -> dict[str, np.ndarray]:
        """The route (uint8 buttons, one per frame) of each kept point, keyed by its number."""
        return {str(point): np.frombuffer(route, np.uint8) for point, (_, route) in self._snapshots.items()}

    @restart_routes.setter
    def restart_routes(self, routes: dict[str, np.ndarray]) -> None:
        """Keep the points these routes lead to, replayed from the level's start; a route that does
        not reach its point alive (from another level or button set) is left out. The env must be
        reset before its next step."""
        for key, route in routes.items():
            route = np.asarray(route, np.uint8)
            snapshot = self._replay(route, int(key))
            if snapshot is not None:
                self._snapshots[int(key)] = (snapshot, route.tobytes())

    def _replay(self, route: np.ndarray, point: int):
        """The emulator state at the end of ``route`` from the level's start, if it is at ``point``
        and alive; else None."""
        self.env.reset()
        info = {"x_pos": -1}
        for action in route:
            _, _, terminated, truncated, info = self.env.step(int(action))
            if terminated or truncated:
                return None
        if self.point(info["x_pos"]) != point or info.get("is_dying"):
            return None
        return self.env.unwrapped.dump_state()
