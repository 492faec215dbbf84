"""Shared core of the package: agents, replay, env pool, tracking, checkpoints, video.

Nothing in here knows an environment by name; experiment packages (``lunar_lander`` ...)
register themselves in :mod:`rlcore.experiment`.
"""
