"""What every experiment shares, one subpackage per concern, from the bottom up: ``files``, ``host``,
``hyperparams``, ``environments``, ``networks``, ``algorithms`` (a folder per family and the one registry of
families), ``training`` (one run), ``models`` (saved models), ``records`` (reading a run back), ``sweeps``,
``api`` and ``cli``; each ``__init__`` says what it holds and what it may import (docs/developer/layout.md).

Nothing in here knows an environment by name; experiment packages (``lunar_lander`` ...) are found by
:mod:`rlcore.environments.registry`, and any Gymnasium id is one too (:mod:`rlcore.environments.gym_experiment`).

The Python API is :mod:`rlcore.api`::

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
