"""The emulator's side of restarts: how a restart point's state is kept, loaded, and got back from its
route. The one module that calls nes-py's state dumps and its private methods.

A kept point is an emulator state and its route: the buttons, one per NES frame, that lead to it
from the level's start (through the routes of the restarts it came from). The emulator is
deterministic, so a checkpoint keeps the routes (``restart_routes``, a few KB each) and a resumed run
replays them to get its points back; the emulator's own state cannot be written to a file. With
"furthest", the route a checkpoint keeps for a point is that of its episode up to the episode's reach,
and a replayed route offers every point it passes with the reach of where it ends: the points and
reaches come back, even when the spacing or the restart x has changed.

A restart does not load the point's own state but one 16-19 frames before it (a state is kept every
:data:`DUMP_EVERY` frames, not every frame: a dump costs ~2 % of a frame), and replays the route from
there: the last :data:`WARMUP` frames it shows (``info["warmup_frames"]``) let the frame stack above
start as it was in the episode that passed the point, not as one frame four times.
Mid-jump, that is the difference between a Mario seen rising and one hanging still (from the states
of 1-3's old crossings, before the warm-up, the policy crossed in up to 8 of 8 tries from x 630 and in
0-1 of 8 from x 620, a few frames earlier in the same jumps).

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import NamedTuple

import gymnasium as gym
import numpy as np

WARMUP = 16  # frames shown from a restart's replay: 4 agent steps of 4 frames, what the frame stacks show
DUMP_EVERY = 4  # frames between the states kept for a warm-up (a dump costs ~2 % of a frame)


class Kept(NamedTuple):
    """How a restart starts at a point: load ``earlier``, then play the last ``warmup`` frames of
    ``route`` (the buttons from the level's start to the point)."""
    earlier: object
    route: bytes
    warmup: int


def dump(env: gym.Env) -> object:
    """The emulator's state now (nes-py's ``dump_state``)."""
    return env.unwrapped.dump_state()


def recent_states(*first: tuple[object, int]) -> deque:
    """Room for the (state, route length) pairs of the last WARMUP + DUMP_EVERY frames."""
    return deque(first, maxlen=WARMUP // DUMP_EVERY + 2)


def kept_at(recent: deque, route: bytes) -> Kept:
    """The point just passed at the end of ``route``, from the newest of the ``recent`` states at
    least WARMUP frames before it (else the oldest)."""
    earlier, length = next((s for s in reversed(recent) if len(route) - s[1] >= WARMUP), recent[0])
    return Kept(earlier, route, len(route) - length)


def load(env: gym.Env, kept: Kept):
    """Start ``env`` (the emulator with its buttons) at ``kept``'s point: load its earlier state and play
    the route's last frames; the last screen and info, with the last WARMUP screens played in
    ``info["warmup_frames"]``."""
    base = env.unwrapped
    base.load_state(kept.earlier)
    base._did_reset()  # the env's own "last" counters (time, x, score) from the loaded state
    obs, info, frames = base.screen, base._get_info(), []
    for action in kept.route[len(kept.route) - kept.warmup:]:
        obs, _, _, _, info = env.step(action)
        frames.append(np.array(obs))
    info["warmup_frames"] = frames[-WARMUP:]
    return obs, info


def replay(env: gym.Env, route: np.ndarray, point: Callable[[int], int]) -> tuple[dict[int, Kept], int]:
    """How to start at each point (``point(x)``: the number of the furthest point at or behind x) that
    ``route``, played from the level's start, passes alive, and the x where it ends (nothing if it dies
    or ends before its last frame). Resets ``env``."""
    env.reset()
    recent = recent_states((dump(env), 0))
    info = {"x_pos": -1}
    passed, furthest = {}, 0
    for frame, action in enumerate(route):
        _, _, terminated, truncated, info = env.step(int(action))
        if (frame + 1) % DUMP_EVERY == 0:
            recent.append((dump(env), frame + 1))
        if terminated or truncated:
            return {}, 0
        reached = point(info["x_pos"])
        if reached > furthest and not info.get("is_dying"):
            passed[reached] = kept_at(recent, route[: frame + 1].tobytes())
            furthest = reached
    return ({}, 0) if info.get("is_dying") else (passed, int(info["x_pos"]))
