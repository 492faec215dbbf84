"""The hyperparameters of DQN and its double and dueling switches: one dataclass, the article's values as defaults. TensorFlow-free."""
from __future__ import annotations

from dataclasses import dataclass

from rlcore.hyperparams.allowed import (
    COUNT,
    NON_NEGATIVE,
    POSITIVE,
    UNIT,
    choices,
    setting,
)
from rlcore.hyperparams.base import TAU, EpisodeLoop, _batch_fits_replay, _h


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
