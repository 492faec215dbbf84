"""A restart x that steps itself back: a backward curriculum by rule, for one hard place.

With ``--restart-x`` and ``--restart-keep furthest`` (:mod:`mario_ppo.restarts`) a restart starts
from the run-up of an old crossing of a gap. ``--restart-back-step`` moves that x by rule, in each
env on its own (:class:`StepBack`): back by the step once at least ``--restart-back-share`` of the
env's last :data:`BACK_WINDOW` restarted episodes got past ``--restart-goal-x`` alive, and the
point's state is found again by replaying the kept route, which passes it. That is the backward
curriculum of learning from one demonstration (Salimans & Chen 2018). By hand on 1-3, from x 630 to
600, each step of 10 took 15-90 rollouts, whatever the hour.

When at most :data:`FORWARD_SHARE` of the window got past, the x steps forward again (never past
``--restart-x``), so each env stays where its restarts succeed sometimes but not mostly: the starts
of intermediate difficulty of reverse curriculum generation (Florensa et al. 2017, bounds 0.1 and
0.9). On 1-3 an env stepped from x 520, where 23-29 % got past, to 510, the takeoff of the jump onto
the low treetop, where none of ~650 did; without the forward step it would have stayed there.

An env whose route never crosses never steps: on 1-3, envs 2, 3, 5 and 6 held a route that falls at
x 780 and sat at x 600 while the others stepped to 510-570 in 40 minutes. So a resumed run gives the
envs still at its ``--restart-x`` the routes and x of the envs that stepped back, in turn
(:func:`lend_routes`). ``info["start_x"]`` (metrics.csv, and ``main.py status``) shows where each
restart started; a checkpoint keeps each env's x with its routes (:data:`X_KEY`).

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

from collections import deque
from itertools import cycle

import numpy as np

BACK_WINDOW = 40  # restarted episodes per env that decide a step back: ~6 rollouts of 8 envs on 1-3
X_KEY = "x"  # with back_step, the restart_routes entry that holds the env's stepped x
FORWARD_SHARE = 0.1  # with back_step: at most this share of the window got past the goal -> step forward


class StepBack:
    """Where one env's restarts start (``x``), moved by their outcomes: ``step`` towards the start
    when at least ``back_share`` of the last ``window`` restarted episodes got past ``goal_x`` alive
    (while the x stays above 0; behind the level's start, restarts start there), ``step`` forward
    when at most :data:`FORWARD_SHARE` did (never past the x it began at)."""

    def __init__(self, x: int, step: int, goal_x: int, back_share: float = 0.5, window: int = BACK_WINDOW):
        if not (x and goal_x > x):
            raise ValueError("a restart x steps back only from a single x (x) towards a goal past it (goal_x > x)")
        self.x, self.built_x, self.step, self.goal_x, self.back_share = x, x, step, goal_x, back_share
        self.outcomes: deque[bool] = deque(maxlen=window)  # the restarted episodes: got past goal_x?

    def judge(self, reach: int) -> bool:
        """Count a restarted episode that got to x ``reach`` alive; True when the x moved (the
        window then starts again, so the new x is judged on its own restarts)."""
        self.outcomes.append(reach >= self.goal_x)
        if len(self.outcomes) < self.outcomes.maxlen:
            return False
        share = np.mean(self.outcomes)
        if share >= self.back_share and self.x > self.step:
            self.x -= self.step
        elif share <= FORWARD_SHARE and self.x + self.step <= self.built_x:
            self.x += self.step
        else:
            return False
        self.outcomes.clear()
        return True

    def restore(self, kept_x: int) -> int:
        """The x a resumed env carries on from: the one its checkpoint kept, never past where it began."""
        self.x = min(self.built_x, kept_x)
        return self.x


def lend_routes(per_env: list[dict], config) -> list[dict]:
    """What each env of a resumed pool gets (``Curriculum.share_memory``): with a stepping restart
    x (the routes hold :data:`X_KEY`), the envs still at the run's ``restart_x`` (whose restarts never
    got past the goal often enough to step back) take the routes and x of the envs that stepped back,
    in turn; the others keep their own."""
    xs = [stepped_x(kept) for kept in per_env]
    stuck = [x is not None and x >= config.restart_x for x in xs]
    ahead = [kept for kept, x in zip(per_env, xs) if x is not None and x < config.restart_x]
    if not (ahead and any(stuck)):
        return per_env
    lenders = cycle(ahead)
    return [dict(next(lenders)) if at_start else kept for kept, at_start in zip(per_env, stuck)]


def stepped_x(routes: dict) -> int | None:
    """The stepped x an env's routes (``restart_routes``) hold, None when they hold none."""
    return int(np.asarray(routes[X_KEY]).ravel()[0]) if X_KEY in routes else None
