"""Rebuild a greedy policy from a saved model folder alone (its ``meta.json`` says what it is)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.experiment import get_experiment


def read_meta(model_dir: str | Path) -> dict:
    model_dir = Path(model_dir)
    meta_path = model_dir / "meta.json"
    if not meta_path.is_file():
        raise UserError(f"{model_dir} has no meta.json: not a model folder of this package "
                        "(train one with `main.py train`, or pass --model)")
    try:
        return json.loads(meta_path.read_text())
    except json.JSONDecodeError as exc:
        raise UserError(f"{meta_path} is damaged ({exc.msg} at line {exc.lineno})")


def load_policy(model_dir: str | Path, experiment: str | None = None, algo: str | None = None):
    """Return ``(experiment, meta, policy)``; ``policy(obs_batch) -> actions``.

    ``experiment``/``algo``, when given, must match the folder's meta (a DQN folder cannot be
    rendered as A2C).
    """
    meta = read_meta(model_dir)
    for key, wanted in (("experiment", experiment), ("algo", algo)):
        if wanted is not None and meta.get(key) != wanted:
            raise UserError(f"model in {model_dir} is {meta.get('experiment')} {meta.get('algo')}, "
                            f"not {experiment} {algo}")
    exp = get_experiment(meta["experiment"])
    spec = exp.algo(meta["algo"])
    env = exp.make_env()
    obs_dim, n_actions = env.observation_space.shape[0], int(env.action_space.n)
    env.close()
    if spec.kind not in POLICY_FILES:
        raise UserError(f"no policy loader for algorithm kind {spec.kind!r}")
    return exp, meta, GreedyPolicy(Path(model_dir) / POLICY_FILES[spec.kind], obs_dim, n_actions)


#: algorithm kind -> the saved network whose argmax is the greedy action
POLICY_FILES = {"dqn": "q_network.h5", "a2c": "actor.h5"}


class GreedyPolicy:
    """argmax over a saved model's outputs (Q-values or action probabilities), batched."""

    def __init__(self, model_path: Path, obs_dim: int, n_actions: int):
        import tensorflow as tf

        from rlcore.models import load_keras_model

        self.model = load_keras_model(model_path, obs_dim, n_actions)
        self._greedy = tf.function(lambda obs: tf.argmax(self.model(obs), axis=1, output_type=tf.int32),
                                   input_signature=[tf.TensorSpec([None, obs_dim], tf.float32)])

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return self._greedy(np.asarray(obs, np.float32)).numpy()
