"""The hyperparameters of SAC (article 004): one dataclass, the article's values as defaults. TensorFlow-free."""
from __future__ import annotations

from dataclasses import dataclass

from rlcore.hyperparams.allowed import (
    COUNT,
    FINITE,
    NON_NEGATIVE,
    POSITIVE,
    UNIT,
    require,
    setting,
)
from rlcore.hyperparams.base import TAU, EpisodeLoop, _batch_fits_replay, _h


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
