"""Saving and loading whole Keras models as ``.h5``, with checks that turn bad files into clear errors."""
from __future__ import annotations

import os
import warnings
from pathlib import Path

import keras

import rlcore.host.quiet  # noqa: F401  drops Keras's "legacy HDF5" log line: .h5 is what we write on purpose
import rlcore.networks.layers  # noqa: F401  registers our custom layers before deserializing
from rlcore.errors import UserError
from rlcore.files.atomic import atomic_path


def save_keras_model(model: keras.Model, path: str | os.PathLike) -> Path:
    """Save architecture + weights to ``path`` (.h5) atomically: a good file is never half-overwritten."""
    path = Path(path)
    with atomic_path(path) as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Keras calls .h5 "legacy"; the articles and our users want it
        model.save(tmp)
    return path


def load_keras_model(path: str | os.PathLike, obs_shape: int | tuple | None = None,
                     n_outputs: int | None = None) -> keras.Model:
    """Load a ``.h5`` model; a missing, corrupt or wrong-shaped file raises :class:`UserError`.

    ``obs_shape`` (an int for flat observations) must match the input; ``n_outputs`` the first
    output (a policy-and-value model is checked on its policy head).
    """
    path = Path(path)
    if not path.is_file():
        raise UserError(f"model file {path} does not exist: a model folder holds its .h5 files beside "
                        f"meta.json, as training writes them")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = keras.models.load_model(path, compile=False)
    except Exception as exc:  # h5py/keras raise many types for truncated or foreign files
        reason = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
        raise UserError(f"cannot load model {path}: the file is damaged or not a Keras .h5 model ({reason})")
    expected_in = (obs_shape,) if isinstance(obs_shape, int) else obs_shape
    in_shape = tuple(model.input_shape[1:])
    first_out = model.output_shape[0] if isinstance(model.output_shape, list) else model.output_shape
    out_shape = tuple(first_out[1:])
    if expected_in is not None and in_shape != tuple(expected_in):
        raise UserError(f"model {path} takes input {in_shape}, this environment gives {tuple(expected_in)}: "
                        "it was trained for another environment")
    if n_outputs is not None and out_shape != (n_outputs,):
        raise UserError(f"model {path} outputs {out_shape}, expected ({n_outputs},): "
                        "it belongs to another algorithm or environment")
    return model
