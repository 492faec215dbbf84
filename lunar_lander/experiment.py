"""LunarLander-v3: env factory and presets. TensorFlow-free.

Each algorithm has an ``article`` preset (the article's recipe) and a ``default`` preset tuned on
this 2-core machine for wall time to a model that clears our bar (see README, results table).
"""
from __future__ import annotations

import dataclasses

import gymnasium as gym

from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.environments.experiment import AlgoSpec, Bar, Experiment

ENV_ID = "LunarLander-v3"
SOLVED_SCORE = 200.0


def make_env(render_mode: str | None = None, max_episode_steps: int | None = 1000) -> gym.Env:
    """LunarLander-v3, discrete actions. Train with ``render_mode=None``: rgb_array mode is ~2x slower."""
    return gym.make(ENV_ID, render_mode=render_mode, max_episode_steps=max_episode_steps)


# The article's recipe (SPEC.md §1-4): 64-64, Adam 1e-3, replay 100k, gamma 0.995, batch 64,
# learn every 4 steps, tau 1e-3, epsilon 1.0 * 0.995^episode down to 0.01.
_DQN_ARTICLE = DQNConfig()
# Default: the same recipe with 4 gradient steps per compiled call (the same number of updates
# per env step, ~2x the env steps/s here). Every 25k steps the greedy policy plays 50 episodes on
# fixed selection seeds; training stops once that reaches 250 and the best weights are saved.
# Stopping on the training average instead caught noisy highs: DDQN stopped at a 100-episode
# average of 254 with a greedy policy worth 223.
_DQN_DEFAULT = dataclasses.replace(_DQN_ARTICLE, updates_per_call=4, stop_score=10_000.0,
                                   eval_every_steps=25_000, eval_episodes=50, keep_best=True,
                                   stop_eval_score=250.0, max_episodes=2500)


def _dqn_presets(**switches) -> dict:
    return {"article": dataclasses.replace(_DQN_ARTICLE, **switches),
            "default": dataclasses.replace(_DQN_DEFAULT, **switches)}


# A2C as the article ran it: one env, update every 4 steps, one-step TD target, reward x 0.01.
_A2C_ARTICLE = A2CConfig()
_A2C_DEFAULT = dataclasses.replace(
    _A2C_ARTICLE, num_envs=8, n_steps=16, gae_lambda=0.95, gamma=0.99, actor_lr=7e-4, critic_lr=1e-3,
    entropy_coef=0.01, max_grad_norm=0.5, normalize_advantage=True, stop_score=230.0, max_episodes=20000,
    max_env_steps=4_000_000, eval_every_steps=50_000, eval_episodes=20, keep_best=True)

EXPERIMENT = Experiment(
    name="lunar_lander",
    description="LunarLander-v3 (8-d state, 4 actions; solved = 100-episode mean >= 200), article 000",
    make_env=make_env,
    solved_score=SOLVED_SCORE,
    plot_prefix="LunarLander",
    bars={**{algo: Bar("mean", 230.0, "the task is solved at 200; the DQN family is held 30 above it, "
                                     "so a shipped model clears it with room to spare, not by a whisker")
             for algo in ("dqn", "ddqn", "dueling_dqn", "dueling_ddqn")},
          "a2c": Bar("mean", 200.0, "the task's solved score (article 000 reports A2C ending below DQN)")},
    algos={
        "dqn": AlgoSpec("dqn", "dqn", "DQN", _dqn_presets()),
        "ddqn": AlgoSpec("ddqn", "dqn", "Double DQN", _dqn_presets(double=True)),
        "dueling_dqn": AlgoSpec("dueling_dqn", "dqn", "Dueling DQN", _dqn_presets(dueling=True)),
        "dueling_ddqn": AlgoSpec("dueling_ddqn", "dqn", "Dueling Double DQN",
                                 _dqn_presets(dueling=True, double=True)),
        "a2c": AlgoSpec("a2c", "a2c", "Advantage actor-critic",
                        {"article": _A2C_ARTICLE, "default": _A2C_DEFAULT}),
    },
)
