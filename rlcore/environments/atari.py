"""Atari games (``ALE/*`` ids, the ``atari`` extra: ale-py) with the preprocessing of the DQN papers,
done by Gymnasium's own wrappers: no-op starts, 4-frame skip with max-pooling, 84 x 84 grayscale,
then the last 4 frames stacked on the last axis (84 x 84 x 4, ``uint8``), the layout the CNNs take.
The settings are recorded in the run's meta.json (``env.atari_preprocessing``). TensorFlow-free.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rlcore.errors import UserError
from rlcore.host.extras import require
from rlcore.host.quiet import filtered_stderr

if TYPE_CHECKING:
    import gymnasium

# Gymnasium's AtariPreprocessing arguments (Machado et al. 2018's v5 envs keep sticky actions, 0.25)
PREPROCESSING = {"noop_max": 30, "frame_skip": 4, "screen_size": 84, "terminal_on_life_loss": False,
                 "grayscale_obs": True, "scale_obs": False}
STACK = 4


def is_atari(env_id: str) -> bool:
    return env_id.startswith("ALE/")


def register_atari() -> None:
    """Register the ``ALE/*`` ids (importing ale-py), or a one-line error without the atari extra."""
    import gymnasium as gym

    with filtered_stderr():  # its banner, on every import
        ale_py = require("ale_py", "Atari (ALE/* ids)")
    gym.register_envs(ale_py)


def record() -> dict:
    """What a run's meta.json keeps of the preprocessing, so evaluate, render and export rebuild it."""
    return {**PREPROCESSING, "frame_stack": STACK, "observation": "84 x 84 x 4 uint8, newest frame last"}


def make_atari(env_id: str, render_mode: str | None, max_episode_steps: int | None,
               env_kwargs: dict) -> gymnasium.Env:
    """``gym.make`` with frame skipping left to the preprocessing, then the stack, channels last;
    ``max_episode_steps`` counts the agent's steps (4 frames each)."""
    import gymnasium as gym

    register_atari()
    if "frameskip" in env_kwargs:
        raise UserError(f"--env-kwargs: frameskip is the Atari preprocessing's ({PREPROCESSING['frame_skip']} frames "
                        "per step, max-pooled), not the env's; give the others")
    with filtered_stderr():  # the emulator's banner, on every env
        env = gym.make(env_id, **{"frameskip": 1, **({"render_mode": render_mode} if render_mode else {}), **env_kwargs})
    env = gym.wrappers.AtariPreprocessing(env, **PREPROCESSING)
    env = gym.wrappers.FrameStackObservation(env, STACK)
    space = env.observation_space
    frames_last = gym.spaces.Box(0, 255, (*space.shape[1:], STACK), np.uint8)
    env = gym.wrappers.TransformObservation(env, lambda obs: np.moveaxis(obs, 0, -1), frames_last)
    if max_episode_steps:
        env = gym.wrappers.TimeLimit(env, max_episode_steps)
    env.stacked_frames = STACK  # FrameStackReplay keeps each frame once
    return env
