"""What every algorithm's hyperparameters share: the run's budget and scoring (:class:`RunBudget`), the
episode-driven loop's checkpoints and periodic evaluations (:class:`EpisodeLoop`), and ``_h``, the one
way a field declares its default, help text and allowed values. TensorFlow-free, so presets import it
cheaply. Each family's own config lives in its folder (:mod:`rlcore.algorithms.dqn.config`, ...).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rlcore.hyperparams.allowed import (
    COUNT,
    FINITE,
    OFF_OR_COUNT,
    Allowed,
    check_fields,
    choices,
    flag,
    require,
    setting,
)

TAU = Allowed(low=0, high=1, low_open=True)
VEC = choices("inline", "processes")


def _h(default, text, allowed: Allowed | None = None, defines_run: bool | str = False):
    """A field with its help and allowed values; ``defines_run``: it shapes the env or the networks (or,
    given as words, what they say it defines), so a resume may not change it
    (:func:`rlcore.hyperparams.flags.check_same_run`)."""
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
        is refused (:func:`rlcore.hyperparams.flags.check_no_inert`), not silently ignored."""
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
