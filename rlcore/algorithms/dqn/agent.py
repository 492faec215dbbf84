"""Deep Q-learning: DQN, Double DQN, Dueling DQN and Dueling Double DQN in one agent.

- Dueling lives in the network (:func:`build_q_network`), Double in the target
  (:meth:`DQNAgent.td_target`): the four LunarLander variants are two switches.
- The whole update (target, loss, gradient step, soft target update) is one ``tf.function``.
"""
from __future__ import annotations

from pathlib import Path

import keras
import numpy as np
import tensorflow as tf
from keras import layers

from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.networks.bodies import as_shape, features, obs_dtype, observation_input
from rlcore.networks.layers import DuelingCombine
from rlcore.networks.numpy_forward import acting_forward
from rlcore.networks.saving import save_keras_model


def build_q_network(obs_shape: int | tuple, n_actions: int, hidden=(64, 64), dueling: bool = False,
                    name: str = "q_network") -> keras.Model:
    """A Functional network from observations to one Q-value per action: the MLP ``hidden`` for
    vectors (an int ``obs_shape`` is a vector's length), the CNN of :mod:`rlcore.networks.bodies` for
    images."""
    obs_shape = as_shape(obs_shape)
    obs = observation_input(obs_shape)
    x = features(obs, obs_shape, hidden)
    if dueling:
        value = layers.Dense(1, name="value")(x)
        advantage = layers.Dense(n_actions, name="advantage")(x)
        q_values = DuelingCombine(name="q_values")([value, advantage])
    else:
        q_values = layers.Dense(n_actions, name="q_values")(x)
    return keras.Model(obs, q_values, name=name)


class DQNAgent:
    """Epsilon-greedy Q-learning agent with a target network that tracks the online one softly."""

    def __init__(self, obs_shape: int | tuple, n_actions: int, cfg: DQNConfig):
        self.obs_shape, self.n_actions, self.cfg = as_shape(obs_shape), n_actions, cfg
        self.q_network = build_q_network(self.obs_shape, n_actions, cfg.hidden, cfg.dueling)
        self.target_network = build_q_network(self.obs_shape, n_actions, cfg.hidden, cfg.dueling,
                                              name="target_q_network")
        self.target_network.set_weights(self.q_network.get_weights())
        # adam, or the PyTorch tutorial's AdamW(amsgrad=True), weight decay 0.01 (the config refuses others)
        self.optimizer = (keras.optimizers.AdamW(cfg.lr, weight_decay=0.01, amsgrad=True) if cfg.optimizer == "adamw"
                          else keras.optimizers.Adam(cfg.lr))
        self.optimizer.build(self.q_network.trainable_variables)
        self.policy = acting_forward(self.q_network)  # acting's numpy copy for an MLP, see act()
        self._compiled_updates = {}  # number of stacked minibatches -> tf.function

    # ----------------------------------------------------------------- acting
    def greedy_actions(self, obs: np.ndarray) -> np.ndarray:
        """argmax_a Q(s, a) for a batch of observations (numpy forward pass, see below)."""
        return self.policy(obs).argmax(axis=1)

    def act(self, obs: np.ndarray, epsilon: float, rng: np.random.Generator) -> int:
        """Epsilon-greedy action for one observation.

        An MLP acts in numpy on a copy of its weights that every train step returns: on this 2-core
        CPU a compiled TF call costs ~0.8 ms, the numpy pass ~0.03 ms. A CNN acts through a compiled call.
        """
        if rng.random() < epsilon:
            return int(rng.integers(self.n_actions))
        return int(self.greedy_actions(obs[None])[0])

    def sync_policy_weights(self) -> None:
        """Refresh the numpy copy of the online weights (after loading or restoring)."""
        self.policy.load(self.q_network.get_weights())

    # --------------------------------------------------------------- learning
    def td_target(self, reward, next_obs, terminated):
        """r + gamma * Q_target(s', a*) unless terminated (truncated episodes still bootstrap).

        a* = argmax of the target net (DQN) or of the online net (Double DQN).
        """
        next_q_target = self.target_network(next_obs)
        chooser = self.q_network(next_obs) if self.cfg.double else next_q_target
        next_action = tf.argmax(chooser, axis=1, output_type=tf.int32)
        next_value = tf.gather(next_q_target, next_action, batch_dims=1)
        return reward + self.cfg.gamma * (1.0 - terminated) * next_value

    def _train_graph(self, obs, action, reward, next_obs, terminated):
        td_target = tf.stop_gradient(self.td_target(reward, next_obs, terminated))
        with tf.GradientTape() as tape:
            q_values = self.q_network(obs, training=True)
            q_taken = tf.gather(q_values, action, batch_dims=1)
            error = td_target - q_taken
            if self.cfg.loss == "huber":  # delta = 1, PyTorch's SmoothL1Loss
                abs_error = tf.abs(error)
                per_sample = tf.where(abs_error < 1.0, 0.5 * tf.square(error), abs_error - 0.5)
            else:
                per_sample = tf.square(error)
            loss = tf.debugging.check_numerics(tf.reduce_mean(per_sample), "DQN loss")
        grads = tape.gradient(loss, self.q_network.trainable_variables)
        if self.cfg.grad_clip_value > 0:
            grads = [tf.clip_by_value(g, -self.cfg.grad_clip_value, self.cfg.grad_clip_value)
                     for g in grads]
        self.optimizer.apply_gradients(zip(grads, self.q_network.trainable_variables))
        self.soft_update()
        return {"loss": loss, "q_mean": tf.reduce_mean(q_taken)}

    def soft_update(self):
        """target <- tau * online + (1 - tau) * target."""
        tau = self.cfg.tau
        for target_var, online_var in zip(self.target_network.weights, self.q_network.weights):
            target_var.assign(tau * online_var + (1.0 - tau) * target_var)

    def _compiled(self, n_updates: int):
        """One tf.function doing ``n_updates`` gradient steps on stacked minibatches.

        Each compiled call has a fixed cost (~0.8 ms here); batching updates amortizes it.
        """
        if n_updates not in self._compiled_updates:
            def updates(obs, action, reward, next_obs, terminated):
                history = [self._train_graph(obs[i], action[i], reward[i], next_obs[i], terminated[i])
                           for i in range(n_updates)]
                means = {k: tf.reduce_mean(tf.stack([h[k] for h in history])) for k in history[0]}
                return means, self.q_network.weights

            obs_spec = tf.TensorSpec([n_updates, None, *self.obs_shape], tf.as_dtype(obs_dtype(self.obs_shape)))
            vec_spec = tf.TensorSpec([n_updates, None], tf.float32)
            self._compiled_updates[n_updates] = tf.function(updates, input_signature=[
                obs_spec, tf.TensorSpec([n_updates, None], tf.int32), vec_spec, obs_spec, vec_spec])
        return self._compiled_updates[n_updates]

    def train_steps(self, obs, action, reward, next_obs, terminated) -> dict[str, float]:
        """Gradient steps on K stacked minibatches (leading axis K); returns mean named losses."""
        losses, weights = self._compiled(len(obs))(obs, action, reward, next_obs, terminated)
        self.policy.load(weights)
        return {k: float(v) for k, v in losses.items()}

    def train_step(self, obs, action, reward, next_obs, terminated) -> dict[str, float]:
        """One gradient step on one minibatch; returns the named losses as floats."""
        return self.train_steps(*(np.asarray(x)[None] for x in (obs, action, reward, next_obs, terminated)))

    # ------------------------------------------------------------ persistence
    MODEL_FILE = "q_network.h5"

    def save(self, folder: str | Path) -> Path:
        return save_keras_model(self.q_network, Path(folder) / self.MODEL_FILE)

    def models(self) -> dict[str, keras.Model]:
        return {"q_network": self.q_network, "target_network": self.target_network}

    def optimizers(self) -> dict[str, keras.optimizers.Optimizer]:
        return {"optimizer": self.optimizer}

