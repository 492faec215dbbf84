"""Rules that end a Mario episode before the game does: a stall, a known dead end.

Both wrap the stack of :mod:`mario_ppo.env` above the frame skip, so they count agent steps and see
the shaped reward (a rule that ends an episode as a death takes off :data:`DEATH_PENALTY`, the
shaped -50 / 10 of any other death).

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym

from mario_ppo.rewards import DEATH_PENALTY

# A fall of x larger than this in one agent step is a pipe into another area, not running: Mario
# runs at most 12 pixels an agent step of 4 frames (measured: right + B on 1-1).
WARP_DROP = 32


class StallLimit(gym.Wrapper):
    """End the episode once Mario's x has not passed its best for ``steps`` agent steps.

    Seen on 1-2: a policy that jumps onto a ledge below a wall pushes right against the wall until
    the clock runs out (about 1,500 agent steps), so a rollout of 8 x 512 steps held 2-4 episodes,
    nearly all of them at that wall.

    ``outcome="truncate"``: a truncation, not an outcome; PPO bootstraps it from V, as any time
    limit. ``outcome="death"``: the end the clock would bring to a Mario that stays stuck, a
    termination with the article's end penalty (-50 / 10). Bootstrapping from V kept the ledge
    attractive on 1-2 (V there predicts the progress of the states that look like it); as a death,
    standing still has the value it has in the game.

    A pipe into another area puts Mario at that area's own x, which can be far behind the best x
    of the area he left; the count then starts over from there (:data:`WARP_DROP`). Seen on 2-2: the
    exit pipe at x 3,010 leads out of the water to x 2,872, some 140 short of the best, and the
    pipe's own animation takes 11 agent steps, so a Mario who found the pipe had the rest of a
    40-step count to climb the staircase past x 3,010 (before this, no training episode did).
    """
    OUTCOMES = ("truncate", "death")

    def __init__(self, env: gym.Env, steps: int, outcome: str = "truncate"):
        super().__init__(env)
        self.steps, self.as_death = steps, outcome == "death"

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self._best = self._last = info["x_pos"]
        self._since = 0
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        x = info["x_pos"]
        if x > self._best or x < self._last - WARP_DROP:  # a new best, or a new area's x frame
            self._best, self._since = x, 0
        else:
            self._since += 1
        self._last = x
        info["stalled"] = stalled = self._since >= self.steps and not (terminated or truncated)
        if stalled and self.as_death:
            return obs, reward - DEATH_PENALTY, True, truncated, info
        return obs, reward, terminated, truncated or stalled, info


UNDERGROUND = 2  # RAM 0x074E, the area type: 0 water, 1 overworld, 2 underground, 3 castle
# Places a Mario with these buttons can reach but never leave toward the flag, by level:
# test(x_pos, area type).
DEAD_ENDS = {
    # 1-2: the ceiling route past the exit pipe (underground beyond x 2,750) into the warp zone,
    # whose pipes need `down`
    (1, 2): lambda x, area: area == UNDERGROUND and x > 2750,
}


class DeadEnds(gym.Wrapper):
    """End the episode as a death (terminated, -50 / 10) once Mario is in a dead end of its level
    (:data:`DEAD_ENDS`; levels without one are unchanged).

    Seen on 1-2: past the exit pipe, a Mario who runs over the ceiling reaches the warp zone, x 3,056,
    more x than the flag route's staircase (2,930), so the x reward led the policy there (62 % of
    100 episodes) and it stood at the wall until the stall limit. The PyTorch original ends its
    maze levels (4-4, 7-4) the same way when Mario takes a wrong path. A dead end never reaches the
    flag, so evaluating with this rule counts the same flags.
    """

    def __init__(self, env: gym.Env, world: int, stage: int):
        super().__init__(env)
        self.rule = DEAD_ENDS.get((world, stage))

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        dead_end = self.rule is not None and not terminated and self.rule(
            info["x_pos"], int(self.env.unwrapped.ram[0x074E]))
        info["dead_end"] = bool(dead_end)
        if dead_end:
            return obs, reward - DEATH_PENALTY, True, truncated, info
        return obs, reward, terminated, truncated, info
