"""Rebuild a policy from a saved model folder alone (its ``meta.json`` says what it is)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from rlcore.cpu import bfloat16_refusal, cpu_flags
from rlcore.errors import UserError
from rlcore.experiment import get_experiment
from rlcore.sampling import sample_categorical, softmax


def read_meta(model_dir: str | Path) -> dict:
    model_dir = Path(model_dir)
    meta_path = model_dir / "meta.json"
    if not model_dir.exists():
        raise UserError(f"{model_dir}: no such model folder")
    if not model_dir.is_dir():
        raise UserError(f"{model_dir} is a file; give the model folder that holds it ({model_dir.parent})"
                        if model_dir.name == "meta.json" else f"{model_dir} is a file, not a model folder")
    if not meta_path.is_file():
        raise UserError(f"{model_dir} has no meta.json: not a model folder of this package (a run's model/ "
                        "folder, or a shipped one under saved_networks/)")
    try:
        return json.loads(meta_path.read_text())
    except json.JSONDecodeError as exc:
        raise UserError(f"{meta_path} is damaged ({exc.msg} at line {exc.lineno})")


def init_from_meta(folder: str | Path, experiment: str, algo: str) -> dict:
    """The meta.json of the model folder a run starts from (PPO's ``init_from``), which must hold a model
    of the same experiment and algorithm: a :class:`UserError` naming it otherwise."""
    from rlcore.allowed import flag, setting

    try:
        meta = read_meta(folder)
    except UserError as exc:
        raise UserError(f"{flag('init_from')}: {exc}") from None
    if not (meta.get("experiment") and meta.get("algo")):
        raise UserError(f"{setting('init_from', str(folder))}: its meta.json does not say which experiment and "
                        f"algorithm its model is for (a {experiment} {algo} model is needed)")
    if (meta["experiment"], meta["algo"]) != (experiment, algo):
        raise UserError(f"{setting('init_from', str(folder))} holds a {meta['experiment']} {meta['algo']} model, "
                        f"not {experiment} {algo}")
    network = Path(folder) / POLICY_FILES[get_experiment(experiment).algo(algo).kind]
    if not network.is_file():
        raise UserError(f"{setting('init_from', str(folder))} has a meta.json but no {network.name}: copy the "
                        "whole model folder")
    return meta


def config_from_meta(exp, meta: dict):
    """The run's hyperparameters, rebuilt as the algorithm's config class."""
    from rlcore.hparams import from_dict

    return from_dict(type(exp.preset(meta["algo"], None)), meta.get("config", {}))


def load_policy(model_dir: str | Path, experiment: str | None = None, algo: str | None = None):
    """Return ``(experiment, meta, policy)``.

    ``policy(obs_batch) -> greedy actions``; ``policy.sample(obs_batch, rng)`` draws from pi for
    the policy-gradient kinds; ``policy.make_env()`` builds the env the model was trained on
    (for Mario, its level and action set). ``experiment``/``algo``, when given, must match the
    folder's meta (a DQN folder cannot be rendered as A2C).
    """
    from rlcore.gym_experiment import names_the_env

    meta = read_meta(model_dir)
    if not (names_the_env(experiment, meta.get("experiment")) and algo in (None, meta.get("algo"))):
        raise UserError(f"model in {model_dir} is {meta.get('experiment')} {meta.get('algo')}, "
                        f"not {experiment} {algo}")
    exp = get_experiment(meta["experiment"], meta.get("env"))
    spec = exp.algo(meta["algo"])
    if spec.kind not in POLICY_FILES:
        raise UserError(f"no policy loader for algorithm kind {spec.kind!r}")
    config = config_from_meta(exp, meta)
    if reason := bfloat16_refusal(getattr(config, "precision", "float32"), cpu_flags()):
        raise UserError(f"{model_dir}: {reason}")
    # the registered episode limit, not the training cap: evaluations are comparable across runs
    make_env = exp.env_factory(config, max_episode_steps=None)
    env = make_env()
    obs_shape, action_space = env.observation_space.shape, env.action_space
    env.close()
    path = Path(model_dir) / POLICY_FILES[spec.kind]
    if spec.kind == "sac":
        policy = MeanActionPolicy(path, obs_shape, action_space.shape[0])
    else:
        policy = Policy(path, obs_shape, int(action_space.n), logits=spec.kind == "ppo",
                        stochastic=spec.kind in ("a2c", "ppo"))
    policy.make_env = make_env
    return exp, meta, policy


#: algorithm kind -> the saved network whose first output ranks the actions
POLICY_FILES = {"dqn": "q_network.h5", "a2c": "actor.h5", "ppo": "actor_critic.h5", "sac": "actor.h5"}


class _SavedNetwork:
    """A saved ``.h5`` network behind one compiled call on its first output."""

    def __init__(self, model_path: Path, obs_shape: tuple, n_outputs: int):
        import tensorflow as tf

        from rlcore.models import load_keras_model

        self.model = load_keras_model(model_path, tuple(obs_shape), n_outputs)
        dtype = self.model.inputs[0].dtype
        self.dtype = np.dtype(dtype if isinstance(dtype, str) else dtype.name)

        def first_output(obs):
            out = self.model(obs)
            return out[0] if isinstance(out, (list, tuple)) else out
        self._first = tf.function(first_output, input_signature=[
            tf.TensorSpec([None, *obs_shape], tf.as_dtype(self.dtype))])
        self.make_env = None

    def scores(self, obs: np.ndarray) -> np.ndarray:
        return self._first(np.asarray(obs, self.dtype)).numpy()


class MeanActionPolicy(_SavedNetwork):
    """SAC's evaluation policy: tanh of the Gaussian mean (the actor outputs mean and log std)."""

    def __init__(self, model_path: Path, obs_shape: tuple, act_dim: int):
        super().__init__(model_path, obs_shape, 2 * act_dim)
        self.act_dim = act_dim

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return np.tanh(self.scores(obs)[:, :self.act_dim]).astype(np.float32)


class Policy(_SavedNetwork):
    """A saved network as a batched policy: argmax of its first output, or a draw from pi.

    ``logits``: the first output is policy logits (PPO) rather than Q-values or probabilities.
    """

    def __init__(self, model_path: Path, obs_shape: tuple, n_actions: int, logits: bool = False,
                 stochastic: bool = False):
        super().__init__(model_path, obs_shape, n_actions)
        self.logits, self.stochastic, self.n_actions = logits, stochastic, n_actions

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return self.scores(obs).argmax(axis=1).astype(np.int32)

    def probs(self, obs: np.ndarray) -> np.ndarray:
        out = self.scores(obs)
        return softmax(out) if self.logits else out / out.sum(axis=1, keepdims=True)

    def sample(self, obs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        if not self.stochastic:
            raise UserError("this policy has no action distribution to sample (it is a Q-network)")
        return sample_categorical(self.probs(obs), rng)
