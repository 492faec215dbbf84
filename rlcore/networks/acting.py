"""A saved ``.h5`` network as a batched policy, one compiled call per batch: argmax of Q or pi, a draw
from pi, or SAC's mean action. Which one a saved model is, its family says
(:attr:`rlcore.algorithms.family.Family.load_policy`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from rlcore.errors import UserError
from rlcore.networks.sampling import sample_categorical, softmax


class _SavedNetwork:
    """A saved ``.h5`` network behind one compiled call on its first output."""

    def __init__(self, model_path: Path, obs_shape: tuple, n_outputs: int):
        import tensorflow as tf

        from rlcore.networks.saving import load_keras_model

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
    """SAC's evaluation policy: tanh of the Gaussian mean (the actor outputs mean and log std);
    ``sample`` draws from the squashed Gaussian, its log std clipped to the run's bounds."""

    def __init__(self, model_path: Path, obs_shape: tuple, act_dim: int,
                 log_std_bounds: tuple[float, float] = (-20.0, 2.0)):
        super().__init__(model_path, obs_shape, 2 * act_dim)
        self.act_dim, self.log_std_bounds = act_dim, log_std_bounds

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        return np.tanh(self.scores(obs)[:, :self.act_dim]).astype(np.float32)

    def sample(self, obs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        out = self.scores(obs)
        mean, log_std = out[:, :self.act_dim], np.clip(out[:, self.act_dim:], *self.log_std_bounds)
        return np.tanh(mean + np.exp(log_std) * rng.standard_normal(mean.shape)).astype(np.float32)


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
