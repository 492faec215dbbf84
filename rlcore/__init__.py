"""Shared core of the package: agents, replay, env pool, tracking, checkpoints, video.

Nothing in here knows an environment by name; experiment packages (``lunar_lander`` ...)
register themselves in :mod:`rlcore.experiment`, and any Gymnasium id is one too
(:mod:`rlcore.gym_experiment`).

The Python API is :mod:`rlcore.api` (a module of its own: ``rlcore.export`` is the export code)::

    from rlcore import api
    run = api.train("CartPole-v1", "ppo", steps=50_000)
    api.evaluate(run, episodes=20)
"""
