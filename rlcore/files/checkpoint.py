"""Checkpoints for resuming: weights, optimizer state, counters, RNG state and replay, in one ``.npz``.

One file written atomically: a crash or Ctrl-C during the save leaves the previous checkpoint intact.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.files.atomic import atomic_path

# the format of a checkpoint's state: 1 = unversioned (before 2026-11-27), 2 = versioned, with
# ``command_starts``. A reader refuses a format newer than its own rather than misread it.
CHECKPOINT_VERSION = 2


def save_checkpoint(path: str | Path, models: dict, optimizers: dict, state: dict,
                    arrays: dict[str, np.ndarray] | None = None) -> Path:
    """Write Keras ``models`` and ``optimizers`` (by name), a JSON-able ``state`` and extra ``arrays``."""
    # UTF-8 bytes: a numpy string array would hold 4 bytes per character (Mario's episode list: MBs)
    state = {**state, "checkpoint_version": CHECKPOINT_VERSION}
    payload = {"state_json": np.frombuffer(json.dumps(state, default=str).encode(), np.uint8)}
    for name, model in models.items():
        for i, w in enumerate(model.get_weights()):
            payload[f"model/{name}/{i}"] = w
    for name, opt in optimizers.items():
        for i, v in enumerate(opt.variables):
            payload[f"optimizer/{name}/{i}"] = np.asarray(v)
    for key, value in (arrays or {}).items():
        payload[f"array/{key}"] = value
    path = Path(path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            np.savez(f, **payload)
    return path


def read_checkpoint_state(path: str | Path) -> dict:
    """Only the JSON state (to check which run a checkpoint belongs to before building anything)."""
    path = Path(path)
    if not path.is_file():
        raise UserError(f"no checkpoint at {path}; nothing to resume")
    try:
        with np.load(path) as data:
            text = data["state_json"]
            # checkpoints written before 2026-11-24 hold the JSON as a numpy string
            state = json.loads(text.tobytes().decode() if text.dtype == np.uint8 else str(text))
    except Exception as exc:
        raise UserError(f"checkpoint {path} is damaged or not one of ours ({type(exc).__name__})")
    version = state.get("checkpoint_version", 1)
    if not isinstance(version, int) or version > CHECKPOINT_VERSION:
        raise UserError(f"checkpoint {path} has format {version}, newer than this package reads "
                        f"({CHECKPOINT_VERSION}): update the package (pip install -e . in a newer checkout)")
    return state


def load_checkpoint(path: str | Path, models: dict, optimizers: dict) -> tuple[dict, dict[str, np.ndarray]]:
    """Restore ``models`` and ``optimizers`` in place; return the state and the extra arrays."""
    path = Path(path)
    state = read_checkpoint_state(path)
    with np.load(path) as data:
        files = set(data.files)
        for name, model in models.items():
            weights = [data[f"model/{name}/{i}"] for i in range(len(model.get_weights()))
                       if f"model/{name}/{i}" in files]
            _check_shapes(path, name, [w.shape for w in model.get_weights()], [w.shape for w in weights])
            model.set_weights(weights)
        for name, opt in optimizers.items():
            values = [data[f"optimizer/{name}/{i}"] for i in range(len(opt.variables))
                      if f"optimizer/{name}/{i}" in files]
            _check_shapes(path, name, [tuple(v.shape) for v in opt.variables], [v.shape for v in values])
            for var, value in zip(opt.variables, values):
                if not _is_learning_rate(var):  # the run's config says the rate (``--resume --lr``)
                    var.assign(value)
        arrays = {key[len("array/"):]: data[key] for key in files if key.startswith("array/")}
    return state, arrays


def _is_learning_rate(var) -> bool:
    """Keras 3 keeps an optimizer's rate among its variables; a resume with a new ``--lr`` must keep
    the rate the optimizer was built with, not the one saved in the checkpoint."""
    return getattr(var, "path", "").rsplit("/", 1)[-1] == "learning_rate"


def _check_shapes(path, name, expected, found):
    if [tuple(s) for s in expected] != [tuple(s) for s in found]:
        raise UserError(f"checkpoint {path} does not match this configuration ({name}: "
                        f"{len(found)} arrays, expected {len(expected)} of other shapes); "
                        "it was written by another algorithm or hyperparameters")
