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

Where the policy dies most, restarts can go more often (``weights="deaths"``): point k is drawn with
probability proportional to 1 + the failed episodes, among this env's last :data:`DEATHS_KEPT`, that
ended past point k and before point k + 1 (:func:`death_weights`). On 2-2 at rollouts 1000-1140, 55 %
of the failures came between x 1,450 and 2,175 and 2 % past x 2,900, where uniform restarts sent a
quarter of them (95 % of which reached the flag). The failures are counted by the wrapper, so an
episode cut short above it (a stall, a dead end) counts where it stopped; they are not checkpointed,
so a resumed run draws uniformly until its envs have failed again.

Which state a point keeps (``keep``): the one of the latest episode that passed it ("latest", so the
points follow the current policy), or the one of the episode that went furthest past it
("furthest"). The second is for a gap that the policy has stopped crossing. On 1-3, 11 of the first
~2,100 episodes crossed the gap at x ~800 and none of the next ~25,000 did: the policy had settled on
dying there, and with "latest" the points before the gap held states from which it dies. With
"furthest" they keep the states of a crossing (its takeoff, mid-air), so restarts there give the
policy the end of a jump that works, then more of it as it learns: the backward curriculum of
learning from one demonstration (Salimans & Chen 2018), the demonstration being the agent's own
crossing. An episode's reach is the furthest x it reached alive (the flag: past every x); when it
ends, a state it passed is kept where its reach is at least that of the state kept there.

A single restart x can also step itself back towards the start as the restarts from it succeed, a
backward curriculum by rule (``back_step``; :mod:`mario_ppo.curriculum` says how and why).

Evaluation never uses it: both are training-only settings (``Curriculum.env_fields``), so
every evaluation and video starts at the level's start. Restarted episodes are marked
(``info["restarted"]``) and left out of the flag share that the stop rule reads; ``info["start_x"]``
says where each episode started (metrics.csv: which points are hard).

How a point's state is kept, loaded and got back from its route (the emulator's side, nes-py's private
calls included): :mod:`mario_ppo.emulator_states`.

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

from collections import Counter, deque
from collections.abc import Iterable
from typing import NamedTuple

import gymnasium as gym
import numpy as np

from mario_ppo.curriculum import X_KEY, StepBack, stepped_x
from mario_ppo.emulator_states import DUMP_EVERY, Kept, dump, kept_at, load, recent_states, replay

WEIGHTS = ("uniform", "deaths")
KEEPS = ("latest", "furthest")
FLAG = 10**9  # the reach of an episode that got the flag: past every x
DEATHS_KEPT = 100  # failed episodes per env that weigh the points: ~30 rollouts of 8 envs on 2-2


class Point(NamedTuple):
    """A kept restart point: how to start there; with keep="furthest" also the reach of the episode its
    state came from and that episode's route to its reach (what a checkpoint keeps of the point)."""
    kept: Kept
    reach: int = -1
    full_route: bytes | None = None


def death_weights(points: list[int], failures: Iterable[int]) -> np.ndarray:
    """The chance of each kept point (sorted numbers) to be a restart's start: 1 + the number of
    ``failures`` (the point numbers at which failed episodes ended) at that point, normalized. The 1
    keeps every point in play; failures before the first kept point weigh nothing."""
    counts = Counter(failures)
    weights = np.array([1.0 + counts[point] for point in points])
    return weights / weights.sum()


class Restarts(gym.Wrapper):
    """Start a ``share`` of episodes from a state in which an earlier episode passed a restart point.

    The points are ``x`` alone, or ``every``, 2 ``every``, 3 ``every``, ... Wraps the emulator with its
    buttons (``JoypadSpace``), below every reward and frame wrapper, so they all see a restart as an
    ordinary reset. Each time an episode passes a point alive, beyond the furthest point it had passed
    or started at, the emulator's state is kept for that point (replacing the one kept before, so the
    points follow the current policy). From then on, each reset loads one kept state with probability
    ``share``, the point drawn uniformly; both draws come from the env's seeded RNG. The kept states
    live in this env; ``restart_routes`` gets and sets them as routes (a resumed run's pool sets what
    the checkpoint kept). With ``weights="deaths"`` the point is drawn by :func:`death_weights`; with
    ``keep="furthest"`` a point keeps the state of the episode that went furthest past it instead.
    With ``back_step``, ``x`` moves by the rule of :class:`~mario_ppo.curriculum.StepBack`.
    """

    def __init__(self, env: gym.Env, share: float, x: int = 0, every: int = 0, weights: str = "uniform",
                 keep: str = "latest", back_step: int = 0, goal_x: int = 0, back_share: float = 0.5):
        super().__init__(env)
        if bool(x) == bool(every):
            raise ValueError("give one of x (a single restart point) and every (a spacing)")
        if weights not in WEIGHTS:
            raise ValueError(f"unknown restart weights {weights!r}; choose one of {', '.join(WEIGHTS)}")
        if keep not in KEEPS:
            raise ValueError(f"unknown restart keep rule {keep!r}; choose one of {', '.join(KEEPS)}")
        self.x, self.every, self.share, self.weights, self.keep = x, every, share, weights, keep
        self.stepper = StepBack(x, back_step, goal_x, back_share) if back_step else None
        self.failures: deque[int] = deque(maxlen=DEATHS_KEPT)  # the point each failed episode ended at
        self._last: dict | None = None  # the info of this episode's last step (None: no step yet)
        self._points: dict[int, Point] = {}  # point number -> how to start there (and, "furthest", its reach)
        self._recent = recent_states()  # (state, route length) every DUMP_EVERY frames
        self._passed_states: dict[int, Kept] = {}  # this episode's, for keep="furthest"
        self._furthest_x = 0  # this episode's reach so far
        self._furthest_frame = 0  # the length of its route when it got there
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
        if self._last is not None and not self._last.get("flag_get"):
            self.failures.append(self.point(self._last["x_pos"]))
        self._keep_furthest(self._passed_states, self._furthest_x, bytes(self._route[: self._furthest_frame]))
        if self.stepper and self._restarted and self._last is not None and self.stepper.judge(self._furthest_x):
            self._move_to(self.stepper.x)
        self._last = None
        self._passed_states, self._furthest_x, self._furthest_frame = {}, 0, 0
        obs, info = self.env.reset(seed=seed, options=options)
        self._restarted = bool(self._points) and self.np_random.random() < self.share
        self._route = bytearray()
        if self._restarted:
            points = sorted(self._points)
            if self.weights == "deaths":
                pick = self.np_random.choice(len(points), p=death_weights(points, self.failures))
            else:
                pick = self.np_random.integers(len(points))
            kept = self._points[points[pick]].kept
            obs, info = load(self.env, kept)
            self._route = bytearray(kept.route)
        self._passed = self.point(info["x_pos"])
        self._start_x = int(info["x_pos"])
        self._recent = recent_states((dump(self.env), len(self._route)))
        info["restarted"], info["start_x"] = self._restarted, self._start_x
        return obs, info

    def _move_to(self, x: int) -> None:
        """Restart from ``x`` (behind the x the env was built with): its state comes from replaying the
        kept route, which passes it. The env must be reset before its next step."""
        routes = self.restart_routes
        routes.pop(X_KEY, None)
        self.x = x
        self._points = {}  # a flag's reach would outrank its replay's
        self.restart_routes = routes

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._route.append(int(action))
        if len(self._route) - self._recent[-1][1] >= DUMP_EVERY:
            self._recent.append((dump(self.env), len(self._route)))
        self._last = info
        alive = not (terminated or truncated or info.get("is_dying"))
        reached = self.point(info["x_pos"])
        if reached > self._passed:
            if alive:
                state = kept_at(self._recent, bytes(self._route))
                if self.keep == "latest":
                    self._points[reached] = Point(state)
                else:
                    self._passed_states[reached] = state  # kept at the episode's end, by its reach (see reset)
            self._passed = reached
        if alive and info["x_pos"] > self._furthest_x:
            self._furthest_x, self._furthest_frame = int(info["x_pos"]), len(self._route)
        if info.get("flag_get"):
            self._furthest_x = FLAG
        info["restarted"], info["start_x"] = self._restarted, self._start_x
        return obs, reward, terminated, truncated, info

    def _keep_furthest(self, passed: dict[int, Kept], reach: int, full_route: bytes) -> None:
        """keep="furthest": keep each state of ``passed`` (point -> state, from an episode that
        reached x ``reach`` alive along ``full_route``) where ``reach`` is at least the kept state's."""
        for point, state in passed.items():
            if point not in self._points or reach >= self._points[point].reach:
                self._points[point] = Point(state, reach, full_route)

    @property
    def restart_routes(self) -> dict[str, np.ndarray]:
        """The route (uint8 buttons, one per frame) of each kept point, keyed by its number: to the
        point, or with keep="furthest" to the reach of the episode the point's state came from."""
        routes = {point: kept.full_route if self.keep == "furthest" else kept.kept.route
                  for point, kept in self._points.items()}
        kept = {str(point): np.frombuffer(route, np.uint8) for point, route in routes.items()}
        if self.stepper:
            kept[X_KEY] = np.array([self.x], np.int64)
        return kept

    @restart_routes.setter
    def restart_routes(self, routes: dict[str, np.ndarray]) -> None:
        """Keep the points these routes lead to, replayed from the level's start. With keep="latest"
        each route gives the state at its end, kept at its own point; a route that does not reach that
        point alive (from another level, button set or spacing) is left out. With "furthest" each
        route offers every point it passes alive, with the reach of the x where it ends alive. With
        back_step, the env's stepped x comes back first (never past the x it was built with).
        The env must be reset before its next step."""
        routes = dict(routes)
        stepped = stepped_x(routes)
        routes.pop(X_KEY, None)
        if self.stepper and stepped is not None:
            self.x = self.stepper.restore(stepped)
        for key, route in sorted(routes.items(), key=lambda item: int(item[0])):
            route = np.asarray(route, np.uint8)
            passed, end_x = replay(self.env, route, self.point)
            if self.keep == "furthest":
                self._keep_furthest(passed, end_x, route.tobytes())
            elif int(key) in passed and int(key) == max(passed):
                self._points[int(key)] = Point(passed[int(key)])
