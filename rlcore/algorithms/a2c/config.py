"""The hyperparameters of A2C (articles 000 and 002): one dataclass, the article's values as defaults. TensorFlow-free."""
from __future__ import annotations

from dataclasses import dataclass

from rlcore.hyperparams.allowed import (
    COUNT,
    NON_NEGATIVE,
    POSITIVE,
    UNIT,
)
from rlcore.hyperparams.base import VEC, EpisodeLoop, _h


@dataclass(frozen=True)
class A2CConfig(EpisodeLoop):
    """Advantage actor-critic: separate Actor and Critic networks, each with its own Adam.

    ``gae_lambda = 0`` is the article's one-step TD target r + gamma V(s'); ``gae_lambda = 1``
    is the n-step return bootstrapped from the end of the rollout.
    """
    actor_hidden: tuple[int, ...] = _h((256, 256), "actor hidden layer sizes", COUNT, defines_run=True)
    critic_hidden: tuple[int, ...] = _h((256, 256), "critic hidden layer sizes", COUNT, defines_run=True)
    actor_lr: float = _h(3e-4, "actor learning rate", POSITIVE)
    critic_lr: float = _h(5e-4, "critic learning rate", POSITIVE)
    gamma: float = _h(0.995, "discount factor", UNIT)
    num_envs: int = _h(1, "environments stepped together", COUNT, defines_run=True)
    vec: str = _h("inline", "inline: one process, fastest for cheap envs; processes: one per env, over Pipes",
                  VEC)
    n_steps: int = _h(4, "env steps per env between updates", COUNT)
    gae_lambda: float = _h(0.0, "0 = one-step TD target (article), 1 = n-step return, between = GAE", UNIT)
    reward_scale: float = _h(0.01, "rewards are multiplied by this in the TD target", POSITIVE)
    entropy_coef: float = _h(0.0, "entropy bonus weight in the actor loss", NON_NEGATIVE)
    max_grad_norm: float = _h(0.0, "clip gradients by global norm (0 = off)", NON_NEGATIVE)
    normalize_advantage: bool = _h(False, "standardize advantages within each update")
