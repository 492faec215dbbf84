"""Shared core of the package: agents, replay, env pool, tracking, checkpoints, video.

Nothing in here knows an environment by name; experiment packages (``lunar_lander`` ...)
register themselves in :mod:`rlcore.experiment`, and any Gymnasium id is one too
(:mod:`rlcore.gym_experiment`).

The Python API (:mod:`rlcore.api`) is exported here::

    import rlcore
    run = rlcore.train("CartPole-v1", "ppo", steps=50_000)
    rlcore.evaluate(run.model_dir, episodes=20)
"""
from rlcore.api import (Experiment, ModelRef, Policy, ProgressCallback, Run, UserError, evaluate, export, load,
                        render, train)

__all__ = ["train", "load", "evaluate", "render", "export", "Run", "Policy", "ModelRef", "ProgressCallback",
           "Experiment", "UserError"]
