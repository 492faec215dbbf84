"""The hyperparameters of PPO (article 001): one dataclass, the article's values as defaults. TensorFlow-free."""
from __future__ import annotations

from dataclasses import dataclass

from rlcore.hyperparams.allowed import (
    COUNT,
    FINITE,
    NON_NEGATIVE,
    POSITIVE,
    UNIT,
    Allowed,
    choices,
    require,
    setting,
)
from rlcore.hyperparams.base import VEC, RunBudget, _h


@dataclass(frozen=True)
class PPOConfig(RunBudget):
    """PPO with clipped surrogate, GAE and a shared CNN feature (article 001); on vector observations
    two tanh MLPs (policy, value) instead of the CNN.

    One update = ``epochs`` passes over a rollout of ``n_steps`` x ``num_envs`` transitions in
    shuffled minibatches. ``article_quirks`` restores the article's loss: ratio p / (p_old + 1e-3)
    instead of exp(log p - log p_old), and log p(a) of the taken action in place of the entropy.
    """
    num_envs: int = _h(8, "environments stepped together", COUNT, defines_run=True)
    vec: str = _h("processes", "processes: one per env, over Pipes; inline: one process", VEC)
    hidden: tuple[int, ...] = _h((64, 64), "hidden layer sizes of the policy MLP and of the value MLP, for "
                                           "vector observations (image observations go through the CNN)",
                                 COUNT, defines_run=True)
    n_steps: int = _h(512, "env steps per env in one rollout", COUNT)
    epochs: int = _h(10, "passes over each rollout", COUNT)
    minibatch: int = _h(256, "transitions per gradient step", COUNT)
    lr: float = _h(1e-4, "Adam learning rate", POSITIVE)
    lr_halve_at: tuple[float, ...] = _h((), "halve the learning rate the first time the success share "
                                            "(as the stop rule reads it) reaches each of these, e.g. 0.3,0.45 "
                                            "(empty = never); --lr is the rate before any halving",
                                        Allowed(low=0, high=1, low_open=True, empty_ok=True))
    gamma: float = _h(0.99, "discount factor", UNIT)
    gae_lambda: float = _h(0.97, "GAE lambda", UNIT)
    clip: float = _h(0.2, "PPO clip range of the probability ratio",
                     Allowed(low=0, high=1, low_open=True, high_open=True))
    entropy_coef: float = _h(0.05, "entropy bonus weight (below 0: a penalty that sharpens pi)", FINITE)
    entropy_halve_at: tuple[float, ...] = _h((), "halve the entropy weight the first time the success share "
                                                 "(as the stop rule reads it) reaches each of these, e.g. "
                                                 "0.1,0.3,0.5 (empty = never); --entropy-coef is the weight "
                                                 "before any halving",
                                             Allowed(low=0, high=1, low_open=True, empty_ok=True))
    value_coef: float = _h(1.0, "value loss weight (the article adds it unweighted)", NON_NEGATIVE)
    value_loss: str = _h("mse", "mse: the squared error (the article); huber: 0.5 e^2 within 1, |e| - 0.5 "
                         "beyond (uvipen's PyTorch Mario), so a few large errors cannot swamp the "
                         "policy's share of a clipped gradient", choices("mse", "huber"))
    value_target: str = _h("gae", "gae: advantage + V(s), the lambda-return; td0: r + gamma V(s')",
                           choices("gae", "td0"))
    max_grad_norm: float = _h(0.0, "clip gradients by global norm (0 = off)", NON_NEGATIVE)
    target_kl: float = _h(0.0, "end an update early, before the first minibatch step whose approx KL "
                               "to the acting policy passes 1.5 x this (SB3's target_kl; 0 = off)",
                          NON_NEGATIVE)
    normalize_advantage: bool = _h(False, "standardize advantages within each minibatch")
    article_quirks: bool = _h(False, "the article's ratio p/(p_old+1e-3) and log p(a) as entropy")
    precision: str = _h("float32", "bfloat16: the CNN's feature layers compute in bfloat16 (weights, heads "
                                   "and losses stay float32); faster only on CPUs with AMX or avx512_bf16 "
                                   "(the docs' speed page; benchmarks/mario.py measures both on yours)",
                        choices("float32", "bfloat16"))
    checkpoint_rollouts: int = _h(10, "rollouts between checkpoints", COUNT)
    stop_success_share: float = _h(0.0, "stop once this share of the last `window` episodes "
                                        "succeeded, e.g. reached the flag (0 = off)", UNIT)
    init_from: str = _h("", "start from the weights of this model folder (e.g. another level's "
                            "saved_networks/mario_ppo/1-1); empty = random initial weights",
                        defines_run="the weights the run started from")

    def __post_init__(self):
        super().__post_init__()
        rollout = self.n_steps * self.num_envs
        require(rollout % self.minibatch == 0,
                f"{setting('minibatch', self.minibatch)} is invalid: it must divide the rollout, n_steps x num_envs = "
                f"{self.n_steps} x {self.num_envs} = {rollout}")
