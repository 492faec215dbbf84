"""CartPole-v1 and CartPole-v0: env factories and presets. TensorFlow-free (pool workers import it).

``cartpole`` is CartPole-v1 (episodes capped at 500); ``cartpole_v0`` is CartPole-v0 (capped at
200), where article 002 ran its A2C.
"""
from __future__ import annotations

import dataclasses
from functools import partial

import gymnasium as gym

from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.environments.experiment import AlgoSpec, Bar, Experiment


def make_env(render_mode: str | None = None, max_episode_steps: int | None = None,
             env_id: str = "CartPole-v1") -> gym.Env:
    """CartPole with its registered time limit unless ``max_episode_steps`` is given."""
    return gym.make(env_id, render_mode=render_mode, max_episode_steps=max_episode_steps)


# Article 003, the PyTorch tutorial: 128-128, replay 10k, batch 128, gamma 0.99, epsilon 0.9 -> 0.05
# exponential over steps (time constant 1000), AdamW 1e-4 amsgrad, Huber, clip by value 100,
# soft update tau 0.005 after every step, 600 episodes.
DQN_ARTICLE = DQNConfig(
    hidden=(128, 128), buffer_size=10_000, batch_size=128, gamma=0.99, eps_start=0.9, eps_end=0.05,
    eps_schedule="steps", eps_decay_steps=1000.0, lr=1e-4, optimizer="adamw", loss="huber",
    grad_clip_value=100.0, tau=0.005, learn_every=1, learning_starts=128, max_episodes=600,
    max_episode_steps=0, stop_score=10_000.0)
# Default: the same recipe, 4 updates per compiled call, and a greedy evaluation every 2,000 steps
# whose best weights are kept (the tutorial's learner oscillates; this ships its best moment).
DQN_DEFAULT = dataclasses.replace(DQN_ARTICLE, updates_per_call=4, eval_every_steps=2000,
                                  eval_episodes=10, keep_best=True)


def a2c_presets() -> dict:
    # Article 002: 8 envs, 5-step returns (GAE lambda 1), one hidden layer of 256 each, Adam 1e-3,
    # loss actor + 0.5 critic - 0.001 entropy (separate Adams: the 0.5 does not change Adam's step),
    # a test every 100 frames (= 800 env steps), 20,000 frames.
    article = A2CConfig(
        actor_hidden=(256,), critic_hidden=(256,), actor_lr=1e-3, critic_lr=1e-3, gamma=0.99,
        num_envs=8, n_steps=5, gae_lambda=1.0, reward_scale=1.0, entropy_coef=0.001,
        max_env_steps=20_000 * 8, max_episodes=100_000, max_episode_steps=0,
        stop_score=10_000.0, eval_every_steps=800, eval_episodes=10, checkpoint_every=200)
    default = dataclasses.replace(article, keep_best=True, max_env_steps=60_000 * 8)
    return {"article": article, "default": default}


def _experiment(name: str, env_id: str, cap: int, shipped: tuple[str, ...]) -> Experiment:
    return Experiment(
        name=name,
        description=f"{env_id} (4-d state, 2 actions, episodes capped at {cap}), articles 002/003",
        make_env=partial(make_env, env_id=env_id),
        # Gymnasium's: a mean of 475 (v0: 195) solves the task; our bar below is the cap itself
        solved_score=float(gym.spec(env_id).reward_threshold),
        algos={
            "dqn": AlgoSpec("dqn", "dqn", "DQN (PyTorch tutorial)", {"article": DQN_ARTICLE,
                                                                      "default": DQN_DEFAULT}),
            "a2c": AlgoSpec("a2c", "a2c", "A2C, 8 envs, 5-step", a2c_presets()),
        },
        score_label="duration (steps)",
        bars={algo: Bar("mean", float(cap), f"the episode cap: every greedy episode balances for all {cap} steps")
              for algo in shipped},
    )


EXPERIMENT = _experiment("cartpole", "CartPole-v1", 500, shipped=("dqn", "a2c"))
EXPERIMENT_V0 = _experiment("cartpole_v0", "CartPole-v0", 200, shipped=("a2c",))  # the article's A2C
