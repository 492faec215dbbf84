"""The parity check of :mod:`rlcore.models.export`: observations from the model's own env, each format's
runtime, and the comparison with the Keras model. The thresholds are declared here, once."""
from __future__ import annotations

import importlib.metadata
import platform
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from rlcore.errors import UserError
from rlcore.host.extras import require

#: an exported output may differ from the Keras model's by at most ABS_TOLERANCE + REL_TOLERANCE x
#: max |Keras output|: float32 kernels that sum in another order (XNNPACK, MLAS) moved LunarLander
#: Q-values of up to ~130 by 2.3e-5 here, a few float32 steps at that size
ABS_TOLERANCE, REL_TOLERANCE = 1e-4, 1e-5
#: share of observations on which the exported network picks the Keras model's greedy action; a
#: different pick counts as agreeing only where the two actions' Keras scores are within the tolerance
GREEDY_AGREEMENT = 1.0
#: a rollout's episodes end at this many steps for the purpose of the check
MAX_EPISODE_STEPS = 1000


class ParityError(UserError):
    """The exported file does not act as the Keras model does."""


# ------------------------------------------------------------------------------ observations
MAX_PARITY_EPISODES = 50  # episodes played at most to collect the observations asked for


def collect_observations(exp, policy, count: int, episodes: int = 3) -> tuple[np.ndarray, str]:
    """``count`` observations spread evenly over ``episodes`` episodes of the model's own env, or more
    episodes where those end before ``count`` steps (up to :data:`MAX_PARITY_EPISODES`), on the
    experiment's first evaluation seeds, played as the model is evaluated (greedy; Mario samples
    from pi with the episode's seeded RNG). Returns the observations and the seeds as text."""
    if count < 1 or episodes < 1:
        raise UserError("the parity check needs at least one observation from at least one episode")
    env = policy.make_env()
    sampled = exp.goal is not None and getattr(policy, "stochastic", False)
    seen = []
    try:
        episode = 0
        while episode < episodes or (len(seen) < count and episode < MAX_PARITY_EPISODES):
            seed = exp.eval_seed_base + episode
            rng = np.random.default_rng(seed)
            obs, _ = env.reset(seed=seed)
            for _ in range(MAX_EPISODE_STEPS):
                seen.append(np.asarray(obs))
                batch = np.asarray(obs)[None]
                action = (policy.sample(batch, rng) if sampled else policy(batch))[0]
                obs, _, terminated, truncated, _ = env.step(action)
                if terminated or truncated:
                    break
            episode += 1
    finally:
        env.close()
    picks = np.linspace(0, len(seen) - 1, min(count, len(seen))).round().astype(int)
    seeds = f"{exp.eval_seed_base}..{exp.eval_seed_base + episode - 1}"
    return np.stack([seen[i] for i in picks]).astype(policy.dtype), seeds


# ------------------------------------------------------------------------------ comparison
def compare(discrete: bool, reference: np.ndarray, exported: np.ndarray, figures_only: bool = False) -> dict:
    """Max absolute difference and, for discrete actions, the share of identical greedy actions."""
    exported = np.asarray(exported, np.float32).reshape(reference.shape)
    diff = float(np.abs(exported - reference).max())
    tolerance = ABS_TOLERANCE + REL_TOLERANCE * float(np.abs(reference).max())
    result = {"max_abs_diff": diff, "tolerance": tolerance}
    passed = diff <= tolerance
    if discrete:
        greedy, picked = reference.argmax(axis=1), exported.argmax(axis=1)
        same = greedy == picked
        rows = np.arange(len(reference))
        ties = ~same & (reference[rows, greedy] - reference[rows, picked] <= tolerance)
        result["greedy_action_agreement"] = float(same.mean())
        result["ties"] = int(ties.sum())
        passed = passed and float((same | ties).mean()) >= GREEDY_AGREEMENT
    else:
        result["max_mean_action_diff"] = diff
    if figures_only:
        result.pop("tolerance")
        return result
    return {**result, "passed": bool(passed)}


# ------------------------------------------------------------------------------ runtimes
@dataclass
class Runtime:
    name: str
    version: str
    run: Callable[[Path, np.ndarray], np.ndarray]


def _version(package: str) -> str:
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def runtime_of(fmt: str) -> Runtime:
    """The runtime that loads ``fmt``; its packages are imported here, so a missing export extra is
    one line before any work."""
    if fmt == "savedmodel":
        return Runtime("tensorflow", _version("tensorflow"), _run_savedmodel)
    if fmt == "tflite":
        try:
            from ai_edge_litert.interpreter import Interpreter  # noqa: F401
            return Runtime("ai-edge-litert (LiteRT Interpreter)", _version("ai-edge-litert"), _run_tflite)
        except ImportError:  # TensorFlow's own copy of the interpreter
            return Runtime("tensorflow (tf.lite.Interpreter)", _version("tensorflow"), _run_tflite)
    if fmt == "onnx":
        for module in ("tf2onnx", "onnx", "onnxruntime"):
            require(module, "ONNX export")
        return Runtime("onnxruntime", _version("onnxruntime"), _run_onnx)
    raise UserError(f"unknown export format {fmt!r}")


def _run_savedmodel(path: Path, obs: np.ndarray) -> np.ndarray:
    import tensorflow as tf

    loaded = tf.saved_model.load(str(path))
    return np.asarray(loaded.serve(tf.constant(obs)))


def _run_tflite(path: Path, obs: np.ndarray) -> np.ndarray:
    from rlcore.host.quiet import filtered_stderr

    try:
        from ai_edge_litert.interpreter import Interpreter
    except ImportError:
        import tensorflow as tf
        Interpreter = tf.lite.Interpreter
    with filtered_stderr():  # LiteRT announces its XNNPACK delegate when it plans the tensors
        interpreter = Interpreter(model_path=str(path))
        given = interpreter.get_input_details()[0]
        interpreter.resize_tensor_input(given["index"], list(obs.shape))
        interpreter.allocate_tensors()
    interpreter.set_tensor(given["index"], obs)
    interpreter.invoke()
    return np.array(interpreter.get_tensor(interpreter.get_output_details()[0]["index"]))


def _run_onnx(path: Path, obs: np.ndarray) -> np.ndarray:
    import onnxruntime

    session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    return session.run(None, {session.get_inputs()[0].name: obs})[0]


def versions(fmt: str) -> dict:
    """The versions that made and checked an export of ``fmt``."""
    packages = ["tensorflow", "keras", "numpy"] + {"savedmodel": [], "tflite": ["ai-edge-litert"],
                                                  "onnx": ["tf2onnx", "onnx", "onnxruntime"]}[fmt]
    return {"python": platform.python_version(), **{name: _version(name) for name in packages}}
