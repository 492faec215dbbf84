"""Hyperparameter dataclasses of the agents. TensorFlow-free, so presets can import them cheaply.

Defaults are the article's values; experiment packages define named presets as instances. Each
field declares the values it allows beside its help text (``rlcore.allowed``); a config with a bad
value cannot be built, so the command line, a preset and a checkpoint are all checked the same way.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rlcore.allowed import (COUNT, FINITE, NON_NEGATIVE, OFF_OR_COUNT, POSITIVE, UNIT, Allowed,
                            check_fields, choices, flag, require, setting)

TAU = Allowed(low=0, high=1, low_open=True)
VEC = choices("inline", "processes")


def _h(default, text, allowed: Allowed | None = None, defines_run: bool | str = False):
    """A field with its help and allowed values; ``defines_run``: it shapes the env or the networks (or,
    given as words, what they say it defines), so a resume may not change it
    (:func:`rlcore.hparams.check_same_run`)."""
    return field(default=default, metadata={"help": text, "allowed": allowed, "defines_run": defines_run})


def _batch_fits_replay(cfg) -> None:
    require(cfg.batch_size <= cfg.buffer_size, f"{setting('batch_size', cfg.batch_size)} is invalid: it must "
                                               f"not exceed {setting('buffer_size', cfg.buffer_size)}")
    # learning waits for this many stored transitions; a smaller memory would never hold them
    require(cfg.learning_starts <= cfg.buffer_size, f"{setting('learning_starts', cfg.learning_starts)} is "
                                                    f"invalid: it must not exceed {setting('buffer_size', cfg.buffer_size)}")


@dataclass(frozen=True)
class RunBudget:
    """When a run stops and how it keeps score; shared by every algorithm's config."""
    max_episodes: int = _h(2000, "stop after this many finished episodes (A2C and PPO: checked after each "
                                 "rollout, so a run may finish more)", COUNT)
    max_env_steps: int = _h(0, "stop after this many env steps, all envs together (0 = no limit)",
                            OFF_OR_COUNT)
    max_episode_steps: int = _h(1000, "cap on steps per episode, longer ones are truncated "
                                      "(0 = the env's registered limit)", OFF_OR_COUNT, defines_run=True)
    stop_score: float = _h(200.0, "stop once the mean return of the last `window` episodes reaches this",
                           FINITE)
    window: int = _h(100, "episodes in the moving average", COUNT)

    def __post_init__(self):
        check_fields(self)

    def inert_fields(self) -> dict[str, str]:
        """Fields whose value does nothing with the other values -> why; a flag given for one of them
        is refused (:func:`rlcore.hparams.check_no_inert`), not silently ignored."""
        return {}


@dataclass(frozen=True)
class EpisodeLoop(RunBudget):
    """The budget plus what the episode-driven trainers (DQN, A2C, SAC) do on the way: a checkpoint
    every N episodes and periodic greedy evaluations that can keep the best weights or stop the run."""
    checkpoint_every: int = _h(50, "episodes between checkpoints", COUNT)
    eval_every_steps: int = _h(0, "greedy evaluation every this many env steps, on fixed selection "
                                  "seeds (0 = off); written to evals.csv", OFF_OR_COUNT)
    eval_episodes: int = _h(10, "episodes per periodic evaluation", COUNT)
    keep_best: bool = _h(False, "save the weights of the best periodic evaluation, not the last ones")
    stop_eval_score: float = _h(0.0, "stop once a periodic evaluation's mean reaches this (0 = off)", FINITE)

    def inert_fields(self) -> dict[str, str]:
        inert = super().inert_fields()
        if not self.eval_every_steps:
            inert.update(dict.fromkeys(("eval_episodes", "keep_best", "stop_eval_score"),
                                       f"periodic evaluations are off; add {flag('eval_every_steps')}"))
        return inert


@dataclass(frozen=True)
class DQNConfig(EpisodeLoop):
    """Q-learning with replay and a soft-updated target network (DQN, Double, Dueling)."""
    hidden: tuple[int, ...] = _h((64, 64), "hidden layer sizes of the Q-network (comma separated)", COUNT, defines_run=True)
    dueling: bool = _h(False, "dueling head: Q = V(s) + A(s,a) - mean_a A(s,a)", defines_run=True)
    double: bool = _h(False, "double DQN target: the online net picks argmax, the target net values it", defines_run=True)
    lr: float = _h(1e-3, "learning rate", POSITIVE)
    optimizer: str = _h("adam", "adamw uses amsgrad, as the PyTorch tutorial", choices("adam", "adamw"), defines_run=True)
    loss: str = _h("mse", "loss on the TD error", choices("mse", "huber"))
    grad_clip_value: float = _h(0.0, "clip each gradient element to +-this value (0 = off)",
                                NON_NEGATIVE)
    gamma: float = _h(0.995, "discount factor", UNIT)
    buffer_size: int = _h(100_000, "replay memory capacity (transitions)", COUNT, defines_run=True)
    batch_size: int = _h(64, "minibatch size", COUNT)
    learn_every: int = _h(4, "one gradient step every this many env steps", COUNT)
    learning_starts: int = _h(64, "env steps collected before the first gradient step", NON_NEGATIVE)
    updates_per_call: int = _h(1, "gradient steps batched into one compiled call (every "
                                  "learn_every * this env steps); >1 trades update lag for speed", COUNT)
    tau: float = _h(1e-3, "soft target update rate, applied after every gradient step", TAU)
    eps_start: float = _h(1.0, "initial exploration rate", UNIT)
    eps_end: float = _h(0.01, "final exploration rate", UNIT)
    eps_schedule: str = _h("episode", "episode: eps *= eps_decay after each episode; steps: eps = end + "
                                      "(start - end) exp(-steps / eps_decay_steps)",
                           choices("episode", "steps"))
    eps_decay: float = _h(0.995, "epsilon multiplied by this after every episode (eps_schedule episode)", TAU)
    eps_decay_steps: float = _h(1000.0, "time constant in env steps (eps_schedule steps)", POSITIVE)

    def __post_init__(self):
        super().__post_init__()
        _batch_fits_replay(self)

    def inert_fields(self) -> dict[str, str]:
        inert = super().inert_fields()
        if self.eps_schedule == "episode":
            inert["eps_decay_steps"] = (f"it is the time constant of {setting('eps_schedule', 'steps')}, and the "
                                        f"schedule is episode")
        else:
            inert["eps_decay"] = f"it is the factor of {setting('eps_schedule', 'episode')}, and the schedule is steps"
        return inert


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


@dataclass(frozen=True)
class SACConfig(EpisodeLoop):
    """Soft actor-critic with a tanh-squashed Gaussian actor, twin critics and a learned temperature."""
    actor_hidden: tuple[int, ...] = _h((256, 256), "actor hidden layer sizes", COUNT, defines_run=True)
    critic_hidden: tuple[int, ...] = _h((256, 256), "hidden layer sizes of each critic (on state and action)",
                                        COUNT, defines_run=True)
    actor_lr: float = _h(3e-4, "actor learning rate", POSITIVE)
    critic_lr: float = _h(3e-4, "critic learning rate (one Adam over both critics)", POSITIVE)
    alpha_lr: float = _h(3e-4, "temperature learning rate", POSITIVE)
    init_alpha: float = _h(1.0, "initial entropy temperature", POSITIVE)
    target_entropy: float = _h(0.0, "entropy the temperature aims at (0 = -|A|, the default)", FINITE)
    gamma: float = _h(0.99, "discount factor", UNIT)
    tau: float = _h(0.005, "soft target update rate, every gradient step", TAU)
    batch_size: int = _h(256, "minibatch size", COUNT)
    buffer_size: int = _h(1_000_000, "replay memory capacity (transitions)", COUNT, defines_run=True)
    learning_starts: int = _h(10_000, "initial env steps with uniform random actions, before any update",
                              NON_NEGATIVE)
    updates_per_call: int = _h(1, "gradient steps batched into one compiled call, taken every this many "
                                  "env steps (one env step per gradient step either way)", COUNT)
    log_std_min: float = _h(-20.0, "lower clip of the actor's log standard deviation", FINITE)
    log_std_max: float = _h(2.0, "upper clip of the actor's log standard deviation", FINITE)
    obs_norm: bool = _h(False, "standardize observations with the running mean and std of every "
                               "observation so far (clipped to +-10), kept inside the saved networks", defines_run=True)

    def __post_init__(self):
        super().__post_init__()
        _batch_fits_replay(self)
        require(self.log_std_min < self.log_std_max,
                f"{setting('log_std_min', self.log_std_min)} is invalid: it must be below "
                f"{setting('log_std_max', self.log_std_max)}")

