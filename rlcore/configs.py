"""Hyperparameter dataclasses of the agents. TensorFlow-free, so presets can import them cheaply.

Defaults are the article's values; experiment packages define named presets as instances.
"""
from __future__ import annotations

from dataclasses import dataclass, field


def _h(default, text):
    return field(default=default, metadata={"help": text})


@dataclass(frozen=True)
class RunBudget:
    """When a run stops and how it keeps score; shared by every algorithm's config."""
    max_episodes: int = _h(2000, "stop after this many finished episodes")
    max_env_steps: int = _h(0, "stop after this many env steps, all envs together (0 = no limit)")
    max_episode_steps: int = _h(1000, "cap on steps per episode, longer ones are truncated "
                                      "(0 = the env's registered limit)")
    stop_score: float = _h(200.0, "stop once the mean return of the last `window` episodes reaches this")
    window: int = _h(100, "episodes in the moving average")
    checkpoint_every: int = _h(50, "episodes between checkpoints")
    eval_every_steps: int = _h(0, "greedy evaluation every this many env steps, on fixed selection "
                                  "seeds (0 = off); written to evals.csv")
    eval_episodes: int = _h(10, "episodes per periodic evaluation")
    keep_best: bool = _h(False, "save the weights of the best periodic evaluation, not the last ones")
    stop_eval_score: float = _h(0.0, "stop once a periodic evaluation's mean reaches this (0 = off)")


@dataclass(frozen=True)
class DQNConfig(RunBudget):
    """Q-learning with replay and a soft-updated target network (DQN, Double, Dueling)."""
    hidden: tuple[int, ...] = _h((64, 64), "hidden layer sizes of the Q-network (comma separated)")
    dueling: bool = _h(False, "dueling head: Q = V(s) + A(s,a) - mean_a A(s,a)")
    double: bool = _h(False, "double DQN target: the online net picks argmax, the target net values it")
    lr: float = _h(1e-3, "learning rate")
    optimizer: str = _h("adam", "adam | adamw (adamw uses amsgrad, as the PyTorch tutorial)")
    loss: str = _h("mse", "mse | huber")
    grad_clip_value: float = _h(0.0, "clip each gradient element to +-this value (0 = off)")
    gamma: float = _h(0.995, "discount factor")
    buffer_size: int = _h(100_000, "replay memory capacity (transitions)")
    batch_size: int = _h(64, "minibatch size")
    learn_every: int = _h(4, "one gradient step every this many env steps")
    learning_starts: int = _h(64, "env steps collected before the first gradient step")
    updates_per_call: int = _h(1, "gradient steps batched into one compiled call (every "
                                  "learn_every * this env steps); >1 trades update lag for speed")
    tau: float = _h(1e-3, "soft target update rate, applied after every gradient step")
    eps_start: float = _h(1.0, "initial exploration rate")
    eps_end: float = _h(0.01, "final exploration rate")
    eps_schedule: str = _h("episode", "episode: eps *= eps_decay after each episode | "
                                      "steps: eps = end + (start - end) exp(-steps / eps_decay_steps)")
    eps_decay: float = _h(0.995, "epsilon multiplied by this after every episode (eps_schedule episode)")
    eps_decay_steps: float = _h(1000.0, "time constant in env steps (eps_schedule steps)")


@dataclass(frozen=True)
class A2CConfig(RunBudget):
    """Advantage actor-critic: separate Actor and Critic networks, each with its own Adam.

    ``gae_lambda = 0`` is the article's one-step TD target r + gamma V(s'); ``gae_lambda = 1``
    is the n-step return bootstrapped from the end of the rollout.
    """
    actor_hidden: tuple[int, ...] = _h((256, 256), "actor hidden layer sizes")
    critic_hidden: tuple[int, ...] = _h((256, 256), "critic hidden layer sizes")
    actor_lr: float = _h(3e-4, "actor learning rate")
    critic_lr: float = _h(5e-4, "critic learning rate")
    gamma: float = _h(0.995, "discount factor")
    num_envs: int = _h(1, "environments stepped together")
    vec: str = _h("inline", "inline (one process; fastest for cheap envs) | processes (one per env, over Pipes)")
    n_steps: int = _h(4, "env steps per env between updates")
    gae_lambda: float = _h(0.0, "0 = one-step TD target (article), 1 = n-step return, between = GAE")
    reward_scale: float = _h(0.01, "rewards are multiplied by this in the TD target")
    entropy_coef: float = _h(0.0, "entropy bonus weight in the actor loss")
    max_grad_norm: float = _h(0.0, "clip gradients by global norm (0 = off)")
    normalize_advantage: bool = _h(False, "standardize advantages within each update")


@dataclass(frozen=True)
class PPOConfig(RunBudget):
    """PPO with clipped surrogate, GAE and a shared CNN feature (article 001).

    One update = ``epochs`` passes over a rollout of ``n_steps`` x ``num_envs`` transitions in
    shuffled minibatches. ``article_quirks`` restores the article's loss: ratio p / (p_old + 1e-3)
    instead of exp(log p - log p_old), and log p(a) of the taken action in place of the entropy.
    """
    num_envs: int = _h(8, "environments stepped together")
    vec: str = _h("processes", "processes (one per env, over Pipes) | inline (one process)")
    n_steps: int = _h(512, "env steps per env in one rollout")
    epochs: int = _h(10, "passes over each rollout")
    minibatch: int = _h(256, "transitions per gradient step")
    lr: float = _h(1e-4, "Adam learning rate")
    gamma: float = _h(0.99, "discount factor")
    gae_lambda: float = _h(0.97, "GAE lambda")
    clip: float = _h(0.2, "PPO clip range of the probability ratio")
    entropy_coef: float = _h(0.05, "entropy bonus weight")
    value_coef: float = _h(1.0, "value loss weight (the article adds it unweighted)")
    value_target: str = _h("gae", "gae: advantage + V(s) (the lambda-return) | td0: r + gamma V(s')")
    max_grad_norm: float = _h(0.0, "clip gradients by global norm (0 = off)")
    normalize_advantage: bool = _h(False, "standardize advantages within each minibatch")
    article_quirks: bool = _h(False, "the article's ratio p/(p_old+1e-3) and log p(a) as entropy")
    checkpoint_rollouts: int = _h(10, "rollouts between checkpoints")
    stop_success_share: float = _h(0.0, "stop once this share of the last `window` episodes "
                                        "succeeded, e.g. reached the flag (0 = off)")
    init_from: str = _h("", "start from the weights of this model folder (e.g. another level's "
                            "saved_networks/mario_ppo/1-1); empty = random initial weights")


@dataclass(frozen=True)
class SACConfig(RunBudget):
    """Soft actor-critic with a tanh-squashed Gaussian actor, twin critics and a learned temperature."""
    actor_hidden: tuple[int, ...] = _h((256, 256), "actor hidden layer sizes")
    critic_hidden: tuple[int, ...] = _h((256, 256), "hidden layer sizes of each critic (on state and action)")
    actor_lr: float = _h(3e-4, "actor learning rate")
    critic_lr: float = _h(3e-4, "critic learning rate (one Adam over both critics)")
    alpha_lr: float = _h(3e-4, "temperature learning rate")
    init_alpha: float = _h(1.0, "initial entropy temperature")
    target_entropy: float = _h(0.0, "entropy the temperature aims at (0 = -|A|, the default)")
    gamma: float = _h(0.99, "discount factor")
    tau: float = _h(0.005, "soft target update rate, every gradient step")
    batch_size: int = _h(256, "minibatch size")
    buffer_size: int = _h(1_000_000, "replay memory capacity (transitions)")
    learning_starts: int = _h(10_000, "initial env steps with uniform random actions, before any update")
    updates_per_call: int = _h(1, "gradient steps batched into one compiled call, taken every this many "
                                  "env steps (one env step per gradient step either way)")
    log_std_min: float = _h(-20.0, "lower clip of the actor's log standard deviation")
    log_std_max: float = _h(2.0, "upper clip of the actor's log standard deviation")
