"""Export a saved model's acting network to where it runs, and prove it acts the same there.

    record = export_model("saved_networks/lunar_lander/dqn", "onnx", "exports/lander_onnx")

The acting network is the part of a model folder that chooses actions: the Q-network (DQN family),
the A2C actor (action probabilities), PPO's actor-critic cut to its policy-logits head, SAC's actor
with its Standardize layer, ending in the mean action ``tanh(mu)``. Formats:

- ``savedmodel``: a TensorFlow SavedModel (Keras ``model.export``), run by TensorFlow;
- ``tflite``: a TFLite / LiteRT flatbuffer (``tf.lite.TFLiteConverter``), run by LiteRT's interpreter;
- ``onnx``: an ONNX file (Keras's export, through tf2onnx), run by onnxruntime.

Before an export counts, its file is loaded by its own runtime and fed observations from the
experiment's own env on evaluation seeds; its outputs must match the Keras model's within
:data:`~rlcore.models.export_parity.ABS_TOLERANCE` (+ a relative part) and choose the same greedy action everywhere (:mod:`rlcore.models.export_parity`).
The folder gets the file and ``export.json`` (source, format, runtime, versions, parity figures),
written in a temporary folder and moved into place only once the check has passed.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable

import numpy as np

from rlcore.algorithms.registry import family
from rlcore.errors import UserError, WriteFailed
from rlcore.files.atomic import library_writes
from rlcore.hyperparams.allowed import flag, setting
from rlcore.models.export_parity import (
    ABS_TOLERANCE,
    GREEDY_AGREEMENT,
    REL_TOLERANCE,
    ParityError,
    collect_observations,
    compare,
    runtime_of,
    versions,
)

FORMATS = ("savedmodel", "tflite", "onnx")
#: what each format writes inside the export folder
FILES = {"savedmodel": "saved_model", "tflite": "model.tflite", "onnx": "model.onnx"}
PARITY_OBSERVATIONS = 256  # observations the parity check feeds both models (default)


def _observations(exp, policy, observations: int | np.ndarray, episodes: int) -> tuple[np.ndarray, object]:
    """The parity check's observations and the seeds they came from (None for an array given)."""
    if isinstance(observations, np.ndarray):
        return observations.astype(policy.dtype, copy=False), None
    return collect_observations(exp, policy, int(observations), episodes)


def _parity(acts, model, obs: np.ndarray, reference, exported, as_trained: str | None) -> dict:
    """The export against the Keras network it came from; a bfloat16 model, exported in float32, also
    against itself as trained (how far the export moved it)."""
    parity = compare(acts.discrete, reference, exported)
    if as_trained is not None:
        parity["vs_as_trained_" + as_trained] = compare(acts.discrete, _outputs(acts.acting_network(model), obs),
                                                        exported, figures_only=True)
    return parity


def export_model(model_dir: str | os.PathLike, fmt: str, out_dir: str | os.PathLike, *,
                 observations: int | np.ndarray = PARITY_OBSERVATIONS, episodes: int = 3,
                 source: str | None = None, experiment: str | None = None, algo: str | None = None) -> dict:
    """Export the acting network of the model in ``model_dir`` as ``fmt`` into the folder ``out_dir``;
    return the record written to ``out_dir/export.json``.

    ``observations``: how many to collect from ``episodes`` episodes of the model's own env on
    evaluation seeds, or an array of observations to use instead. ``source`` names the model in the
    record (default ``model_dir``); ``experiment``/``algo``, when given, must match the folder.
    A missing or foreign model folder, an unknown format, a missing export package or a failed
    parity check raise :class:`UserError` (``ParityError``), and ``out_dir`` is left as it was.
    """
    from rlcore.models.policies import load_policy

    if fmt not in FORMATS:
        raise UserError(f"unknown export format {fmt!r}; choose one of {', '.join(FORMATS)}")
    out_dir = Path(out_dir)
    runtime = runtime_of(fmt)  # the runtime's packages, before any work (a missing one: one line)
    _check_out(out_dir)
    exp, meta, policy = load_policy(model_dir, experiment, algo)
    kind = exp.algo(meta["algo"]).kind
    acts = family(kind)
    acting, as_trained = acting_network(policy.model, acts.acting_network)
    obs, seeds = _observations(exp, policy, observations, episodes)
    reference = _outputs(acting, obs)

    with written(out_dir):
        out_dir.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        path = tmp / FILES[fmt]
        with written(out_dir):  # TensorFlow's, LiteRT's and tf2onnx's writers on a full or read-only disk
            converter = WRITERS[fmt](acting, path)
        exported = runtime.run(path, obs)
        parity = _parity(acts, policy.model, obs, reference, exported, as_trained)
        record = _record(fmt, source or str(model_dir), exp, meta["algo"], acts, acting, obs, reference,
                         as_trained, runtime, converter, parity, seeds)
        if not parity["passed"]:
            raise ParityError(f"{fmt} export of {source or model_dir} failed its parity check: "
                              + summary(record) + f"; nothing written to {out_dir}")
        with written(out_dir):
            (tmp / "export.json").write_text(json.dumps(record, indent=2) + "\n")
            os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp makes 0700
            _move_into_place(tmp, out_dir)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return record


def _record(fmt: str, source: str, exp, algo: str, acts, acting, obs: np.ndarray, reference: np.ndarray,
            as_trained: str | None, runtime, converter: dict, parity: dict, seeds: str | None) -> dict:
    """export.json: what was exported from what, the network's input and output, the runtime, and the
    parity check's figures and rules."""
    return {
        "format": fmt, "file": FILES[fmt], "source_model": source,
        "experiment": exp.name, "algo": algo, "kind": acts.kind,
        "network": {"input": {"name": acting.inputs[0].name, "shape": [None, *obs.shape[1:]],
                              "dtype": str(obs.dtype)},
                    "output": {"shape": [None, reference.shape[1]], "meaning": acts.export_output},
                    "precision": "float32" + (f" (trained in {as_trained})" if as_trained else "")},
        "runtime": {"name": runtime.name, "version": runtime.version},
        "converter": converter,
        "parity": {**parity, "observations": int(len(obs)),
                   "seeds": seeds or "given by the caller",
                   "policy": "sampled from pi as evaluated" if exp.goal else "greedy",
                   "thresholds": {"max_abs_diff": f"<= {ABS_TOLERANCE:g} + {REL_TOLERANCE:g} x max |Keras output|",
                                  **({} if not acts.discrete else
                                     {"greedy_action_agreement": f">= {GREEDY_AGREEMENT:g}, a different "
                                      "action counts only where the Keras scores of the two are "
                                      "within the tolerance (a tie)"})}},
        "versions": versions(fmt),
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }


def summary(record: dict) -> str:
    """The parity figures of an export record in one line."""
    p = record["parity"]
    line = f"max abs diff {p['max_abs_diff']:.3g} (tolerance {p['tolerance']:.3g})"
    if "greedy_action_agreement" in p:
        line += f", identical greedy actions {100 * p['greedy_action_agreement']:.1f}%"
        if p.get("ties"):
            line += f" ({p['ties']} ties within tolerance)"
    else:
        line += " between mean actions"
    return line + f" on {p['observations']} observations"


# -------------------------------------------------------------------------- the acting network
def acting_network(model, cut: Callable):
    """``(float32 acting network, None)``, or for a model trained in bfloat16 ``(its float32 copy,
    "bfloat16")``: TFLite has no bfloat16 kernels, and float32 runs everywhere."""
    precisions = {getattr(layer.dtype_policy, "name", "float32") for layer in model.layers}
    mixed = sorted(p for p in precisions if p.startswith("mixed_"))
    if not mixed:
        return cut(model), None
    copy = type(model).from_config(_float32_config(model.get_config()))
    copy.set_weights(model.get_weights())
    return cut(copy), mixed[0].removeprefix("mixed_")


def _float32_config(config):
    if isinstance(config, dict):
        if config.get("class_name") == "DTypePolicy":
            return {**config, "config": {**config["config"], "name": "float32"}}
        return {key: _float32_config(value) for key, value in config.items()}
    if isinstance(config, list):
        return [_float32_config(value) for value in config]
    return "float32" if config == "bfloat16" else config


def _outputs(network, obs: np.ndarray, batch: int = 256) -> np.ndarray:
    return np.concatenate([np.asarray(network(obs[i:i + batch], training=False), np.float32)
                           for i in range(0, len(obs), batch)])


# -------------------------------------------------------------------------- writers
def _write_savedmodel(network, path: Path) -> dict:
    import keras

    network.export(str(path), format="tf_saved_model", verbose=False)
    return {"name": "keras Model.export(format='tf_saved_model')", "version": keras.__version__,
            "signature": "serve (also serving_default)"}


def _write_tflite(network, path: Path) -> dict:
    import tensorflow as tf

    with tempfile.TemporaryDirectory() as saved:
        network.export(saved, format="tf_saved_model", verbose=False)
        converter = tf.lite.TFLiteConverter.from_saved_model(saved)
        path.write_bytes(converter.convert())  # float32, no quantization: the parity bar is float32's
    return {"name": "tf.lite.TFLiteConverter.from_saved_model", "version": tf.__version__,
            "optimizations": "none (float32)"}


def _write_onnx(network, path: Path) -> dict:
    import logging
    import warnings

    import onnx
    import tf2onnx

    logging.getLogger("tf2onnx").setLevel(logging.ERROR)  # it logs every rewrite at INFO
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # keras's numpy-2 patch of tf2onnx warns about np.object
        network.export(str(path), format="onnx", verbose=False)
    opset = max(entry.version for entry in onnx.load(str(path)).opset_import if entry.domain in ("", "ai.onnx"))
    return {"name": "keras Model.export(format='onnx') via tf2onnx", "version": tf2onnx.__version__,
            "opset": int(opset)}


WRITERS = {"savedmodel": _write_savedmodel, "tflite": _write_tflite, "onnx": _write_onnx}


# -------------------------------------------------------------------------- the output folder
def _check_out(out_dir: Path) -> None:
    """Refuse, before any work, an ``--out`` that is a file or a folder holding something else."""
    if out_dir.exists() and not out_dir.is_dir():
        raise UserError(f"{setting('out', str(out_dir))} is a file; give a folder for the export")
    if out_dir.is_dir() and any(out_dir.iterdir()) and not (out_dir / "export.json").is_file():
        raise UserError(f"{setting('out', str(out_dir))} holds files that are not an export; give a new or empty folder")
    from rlcore.files.atomic import writable_folder

    writable_folder(out_dir.parent, flag("out"))


@contextlib.contextmanager
def written(out_dir: Path):
    """A failed write under ``out_dir`` (ours or a library's) as one line naming it; an earlier export there
    is left whole (the new one is written beside it and moved in only when complete)."""
    try:
        with library_writes(out_dir.parent):
            yield
    except OSError as exc:
        raise WriteFailed(out_dir, exc, then="export again") from None


def _move_into_place(tmp: Path, out_dir: Path) -> None:
    """``tmp`` becomes ``out_dir``; an earlier export there is replaced whole, never mixed with it."""
    if not out_dir.exists():
        os.replace(tmp, out_dir)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.old.", dir=out_dir.parent))
    os.replace(out_dir, old / out_dir.name)
    try:
        os.replace(tmp, out_dir)
    except OSError:
        os.replace(old / out_dir.name, out_dir)  # put the earlier export back
        raise
    finally:
        shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
