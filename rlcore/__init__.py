"""Shared core of the package: agents, replay, env pool, tracking, checkpoints, video.

Nothing in here knows an environment by name; experiment packages (``lunar_lander`` ...)
register themselves in :mod:`rlcore.experiment`, and any Gymnasium id is one too
(:mod:`rlcore.gym_experiment`).

The Python API is :mod:`rlcore.api` (a module of its own: ``rlcore.export`` is the export code)::

    from rlcore import api
    run = api.train("CartPole-v1", "ppo", steps=50_000)
    api.evaluate(run, episodes=20)
"""
import os as _os
import sys as _sys

# The package is TensorFlow's: Keras 3 must run on its TensorFlow backend here, whatever KERAS_BACKEND or
# ~/.keras/keras.json choose for the user's other work (Keras reads both when it is first imported).
if "keras" not in _sys.modules:
    _os.environ["KERAS_BACKEND"] = "tensorflow"
elif (_backend := _sys.modules["keras"].backend.backend()) != "tensorflow":
    raise ImportError(f"rlcore runs on Keras's TensorFlow backend, but this process imported Keras with the "
                      f"{_backend!r} backend first; import rlcore before keras, or set KERAS_BACKEND=tensorflow")
