"""Advantage actor-critic with the article's Actor / Critic classes (create_model, compute_loss, train).

One update covers a rollout of ``n_steps`` x ``num_envs`` transitions. Targets are GAE(lambda):
``gae_lambda = 0`` gives the article's one-step ``td_target = r + gamma V(s')`` and
``advantage = td_target - V(s)``; ``gae_lambda = 1`` gives n-step returns bootstrapped from the
rollout's end (article 002). No bootstrap on ``terminated``; a truncated episode bootstraps from
its final observation.

Fix of the article's bug: its actor ends in softmax yet its loss said ``from_logits=True``, which
applied a second softmax. Here the loss takes the probabilities as they are.
"""
from __future__ import annotations

from pathlib import Path

import keras
import numpy as np
import tensorflow as tf
from keras import layers

from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.advantages import gae
from rlcore.networks.bodies import as_shape, features, obs_dtype, observation_input
from rlcore.networks.numpy_forward import acting_forward
from rlcore.networks.sampling import sample_categorical
from rlcore.networks.saving import save_keras_model

_PROB_FLOOR = 1e-8  # keeps log(p) finite when the softmax saturates


def _network(obs_shape: tuple, hidden, out_units: int, out_activation, name: str) -> keras.Model:
    """The MLP ``hidden`` (vectors) or the CNN (images, :mod:`rlcore.networks.bodies`), then ``output``."""
    obs = observation_input(obs_shape)
    output = layers.Dense(out_units, activation=out_activation, name="output")(features(obs, obs_shape, hidden))
    return keras.Model(obs, output, name=name)


def _apply(opt, model, tape, loss, max_grad_norm: float):
    grads = tape.gradient(loss, model.trainable_variables)
    if max_grad_norm > 0:
        grads, _ = tf.clip_by_global_norm(grads, max_grad_norm)
    opt.apply_gradients(zip(grads, model.trainable_variables))


class Actor:
    """Policy network pi(a|s): MLP ending in softmax."""

    def __init__(self, state_dim: int | tuple, action_dim: int, lr: float, hidden=(256, 256), max_grad_norm=0.0):
        self.state_dim, self.action_dim, self.hidden = as_shape(state_dim), action_dim, hidden
        self.max_grad_norm = max_grad_norm
        self.model = self.create_model()
        self.opt = keras.optimizers.Adam(lr)
        self.opt.build(self.model.trainable_variables)

    def create_model(self) -> keras.Model:
        return _network(self.state_dim, self.hidden, self.action_dim, "softmax", "actor")

    @staticmethod
    def compute_loss(actions, probs, advantages, entropy_coef: float = 0.0):
        """Cross-entropy of the taken actions weighted by the (stopped) advantages, minus entropy bonus."""
        probs = tf.maximum(probs, _PROB_FLOOR)
        log_taken = tf.math.log(tf.gather(probs, actions, batch_dims=1))
        policy_loss = -tf.reduce_mean(log_taken * tf.stop_gradient(advantages))
        entropy = -tf.reduce_mean(tf.reduce_sum(probs * tf.math.log(probs), axis=1))
        return policy_loss - entropy_coef * entropy, policy_loss, entropy

    def train(self, states, actions, advantages, entropy_coef: float = 0.0):
        with tf.GradientTape() as tape:
            probs = self.model(states, training=True)
            loss, policy_loss, entropy = self.compute_loss(actions, probs, advantages, entropy_coef)
            loss = tf.debugging.check_numerics(loss, "A2C actor loss")
        _apply(self.opt, self.model, tape, loss, self.max_grad_norm)
        return policy_loss, entropy


class Critic:
    """State-value network V(s)."""

    def __init__(self, state_dim: int | tuple, lr: float, hidden=(256, 256), max_grad_norm=0.0):
        self.state_dim, self.hidden, self.max_grad_norm = as_shape(state_dim), hidden, max_grad_norm
        self.model = self.create_model()
        self.opt = keras.optimizers.Adam(lr)
        self.opt.build(self.model.trainable_variables)

    def create_model(self) -> keras.Model:
        return _network(self.state_dim, self.hidden, 1, "linear", "critic")

    @staticmethod
    def compute_loss(v_pred, td_targets):
        return tf.reduce_mean(tf.square(tf.stop_gradient(td_targets) - v_pred))

    def train(self, states, td_targets):
        with tf.GradientTape() as tape:
            v_pred = tf.squeeze(self.model(states, training=True), axis=1)
            loss = tf.debugging.check_numerics(self.compute_loss(v_pred, td_targets), "A2C critic loss")
        _apply(self.opt, self.model, tape, loss, self.max_grad_norm)
        return loss


class A2CAgent:
    """Actor + Critic, sampling actions from pi and updating both once per rollout."""

    def __init__(self, obs_shape: int | tuple, n_actions: int, cfg: A2CConfig):
        self.obs_shape, self.n_actions, self.cfg = as_shape(obs_shape), n_actions, cfg
        self.actor = Actor(self.obs_shape, n_actions, cfg.actor_lr, cfg.actor_hidden, cfg.max_grad_norm)
        self.critic = Critic(self.obs_shape, cfg.critic_lr, cfg.critic_hidden, cfg.max_grad_norm)
        self.policy = acting_forward(self.actor.model)  # acting's numpy copy of an MLP actor
        t, n = cfg.n_steps, cfg.num_envs
        obs_spec = tf.TensorSpec([t, n, *self.obs_shape], tf.as_dtype(obs_dtype(self.obs_shape)))
        vec = tf.TensorSpec([t, n], tf.float32)
        self._update = tf.function(self._update_graph, input_signature=[
            obs_spec, tf.TensorSpec([t, n], tf.int32), vec, obs_spec, vec, vec])

    # ----------------------------------------------------------------- acting
    def sync_policy_weights(self) -> None:
        self.policy.load(self.actor.model.get_weights())

    def probs(self, obs: np.ndarray) -> np.ndarray:
        """pi(.|s) in numpy (fast acting: a compiled TF call costs ~0.8 ms on this CPU)."""
        return self.policy(obs)

    def act(self, obs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Sample one action per row of ``obs``."""
        return sample_categorical(self.probs(obs), rng)

    def greedy_actions(self, obs: np.ndarray) -> np.ndarray:
        """argmax_a pi(a|s) for a batch of observations."""
        return self.probs(obs).argmax(axis=1)

    # --------------------------------------------------------------- learning
    def _update_graph(self, obs, actions, rewards, next_obs, terminated, dones):
        cfg = self.cfg
        t, n = cfg.n_steps, cfg.num_envs
        flat_obs = tf.reshape(obs, [t * n, *self.obs_shape])
        values = tf.reshape(self.critic.model(flat_obs), [t, n])
        next_values = tf.reshape(self.critic.model(tf.reshape(next_obs, [t * n, *self.obs_shape])), [t, n])
        advantages = gae(rewards * cfg.reward_scale, values, next_values, terminated, dones,
                         cfg.gamma, cfg.gae_lambda)
        td_targets = tf.reshape(advantages + values, [t * n])
        advantages = tf.reshape(advantages, [t * n])
        if cfg.normalize_advantage:
            advantages = (advantages - tf.reduce_mean(advantages)) / (tf.math.reduce_std(advantages) + 1e-8)
        policy_loss, entropy = self.actor.train(flat_obs, tf.reshape(actions, [t * n]), advantages,
                                                cfg.entropy_coef)
        critic_loss = self.critic.train(flat_obs, td_targets)
        losses = {"actor_loss": policy_loss, "critic_loss": critic_loss, "entropy": entropy}
        return losses, self.actor.model.weights

    def update(self, obs, actions, rewards, next_obs, terminated, dones) -> dict[str, float]:
        """One actor and one critic step on a [n_steps, num_envs] rollout; returns named losses."""
        losses, weights = self._update(obs, actions, rewards, next_obs, terminated, dones)
        self.policy.load(weights)
        return {k: float(v) for k, v in losses.items()}

    # ------------------------------------------------------------ persistence
    ACTOR_FILE, CRITIC_FILE = "actor.h5", "critic.h5"

    def save(self, folder: str | Path) -> list[Path]:
        folder = Path(folder)
        return [save_keras_model(self.actor.model, folder / self.ACTOR_FILE),
                save_keras_model(self.critic.model, folder / self.CRITIC_FILE)]

    def models(self) -> dict[str, keras.Model]:
        return {"actor": self.actor.model, "critic": self.critic.model}

    def get_weights(self) -> list[np.ndarray]:
        """Actor then critic weights (a snapshot for keep_best)."""
        return self.actor.model.get_weights() + self.critic.model.get_weights()

    def set_weights(self, weights: list[np.ndarray]) -> None:
        n_actor = len(self.actor.model.get_weights())
        self.actor.model.set_weights(weights[:n_actor])
        self.critic.model.set_weights(weights[n_actor:])
        self.sync_policy_weights()

    def optimizers(self) -> dict:
        return {"actor_opt": self.actor.opt, "critic_opt": self.critic.opt}
