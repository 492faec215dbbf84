"""Soft actor-critic (article 004): a tanh-squashed Gaussian actor, twin critics with target
copies and a learned entropy temperature, all updated in one compiled call.

The actor outputs the mean and the log standard deviation (clipped to [log_std_min, log_std_max])
of a Gaussian u; the action is tanh(u), and its log-probability carries the change of variables:

    log pi(a|s) = sum_i [ log N(u_i; mu_i, sigma_i) - log(1 - tanh(u_i)^2) ]
    log(1 - tanh(u)^2) = 2 (log 2 - u - softplus(-2u))          (stable form)

One gradient step, in this order (as TF-Agents' SacAgent):

    y       = r + gamma (1 - terminated) (min_j Q'_j(s', a') - alpha log pi(a'|s')),  a' ~ pi(s')
    critics: minimize sum_j mean((Q_j(s, a) - y)^2)
    actor:   minimize mean(alpha log pi(a~|s) - min_j Q_j(s, a~)),                    a~ ~ pi(s)
    alpha:   minimize mean(-log_alpha (log pi(a~|s) + target_entropy))
    targets: Q'_j <- tau Q_j + (1 - tau) Q'_j

The Gaussian noise comes from the trainer's numpy RNG, so runs and resumes are exact. Acting
runs the actor in numpy (a compiled TF call costs ~0.8 ms on this CPU).
"""
from __future__ import annotations

import math
from pathlib import Path

import keras
import numpy as np
import tensorflow as tf
from keras import layers

from rlcore.algorithms.running_stats import RunningMeanStd
from rlcore.algorithms.sac.config import SACConfig
from rlcore.networks.layers import Standardize
from rlcore.networks.numpy_forward import NumpyForward
from rlcore.networks.saving import save_keras_model

ACTOR_FILE = "actor.h5"
LOG_2PI = math.log(2.0 * math.pi)


def build_actor(obs_dim: int, act_dim: int, hidden, standardize: Standardize | None = None) -> keras.Model:
    """obs -> (standardize) -> ReLU MLP -> [mean (act_dim), log_std (act_dim)] concatenated."""
    return keras.Sequential(
        [keras.Input((obs_dim,), name="obs")] + ([standardize] if standardize is not None else [])
        + [layers.Dense(u, activation="relu", name=f"hidden_{i}") for i, u in enumerate(hidden)]
        + [layers.Dense(2 * act_dim, name="mean_and_log_std")], name="actor")


def build_critic(obs_dim: int, act_dim: int, hidden, name: str,
                 standardize: Standardize | None = None) -> keras.Model:
    """Q(s, a): the (standardized) state and the action concatenated, then a ReLU MLP."""
    obs = keras.Input((obs_dim,), name="obs")
    action = keras.Input((act_dim,), name="action")
    state = standardize(obs) if standardize is not None else obs
    x = layers.Concatenate(name="state_action")([state, action])
    for i, u in enumerate(hidden):
        x = layers.Dense(u, activation="relu", name=f"hidden_{i}")(x)
    return keras.Model([obs, action], layers.Dense(1, name="q")(x), name=name)


def squashed_gaussian(mean, log_std, noise):
    """(action = tanh(mean + std * noise), its log-probability under the squashed Gaussian)."""
    std = tf.exp(log_std)
    u = mean + std * noise
    log_normal = -0.5 * tf.square(noise) - log_std - 0.5 * LOG_2PI
    log_det = 2.0 * (math.log(2.0) - u - tf.nn.softplus(-2.0 * u))
    return tf.tanh(u), tf.reduce_sum(log_normal - log_det, axis=1)


# The update is compiled with XLA, which fuses the small dense layers: ~6.7 ms per update here instead
# of ~10.3 ms, for ~2 s of compiling each time an agent is built (measured 2026-11-27). The tests of a
# trainer's bookkeeping on toy tasks build many short-lived agents and turn it off (tests/conftest.py,
# sac_without_xla); tests/rlcore/algorithms/test_sac.py checks the compiled update itself against numpy.
XLA = True


class SACAgent:
    def __init__(self, obs_dim: int, act_dim: int, cfg: SACConfig):
        self.obs_dim, self.act_dim, self.cfg = obs_dim, act_dim, cfg
        self.target_entropy = cfg.target_entropy or -float(act_dim)
        # with obs_norm, one Standardize layer (its mean and var) is shared by all five networks
        self.standardize = Standardize(name="standardize") if cfg.obs_norm else None
        self.obs_stats = RunningMeanStd(obs_dim) if cfg.obs_norm else None
        self._unseen: list[np.ndarray] = []  # observations not yet folded into obs_stats
        self.actor = build_actor(obs_dim, act_dim, cfg.actor_hidden, self.standardize)
        self.critics = [build_critic(obs_dim, act_dim, cfg.critic_hidden, f"critic_{j}", self.standardize)
                        for j in (1, 2)]
        self.targets = [build_critic(obs_dim, act_dim, cfg.critic_hidden, f"target_critic_{j}", self.standardize)
                        for j in (1, 2)]
        for target, critic in zip(self.targets, self.critics):
            target.set_weights(critic.get_weights())
        self.log_alpha = tf.Variable(math.log(cfg.init_alpha), dtype=tf.float32, name="log_alpha")
        self.actor_opt = keras.optimizers.Adam(cfg.actor_lr)
        self.critic_opt = keras.optimizers.Adam(cfg.critic_lr)
        self.alpha_opt = keras.optimizers.Adam(cfg.alpha_lr)
        self.actor_opt.build(self.actor.trainable_variables)
        self.critic_opt.build(self._critic_variables())
        self.alpha_opt.build([self.log_alpha])
        self.policy = NumpyForward(self.actor)  # acting's numpy copy of the actor
        k, a, o = cfg.updates_per_call, act_dim, obs_dim
        obs_spec, vec = tf.TensorSpec([k, None, o], tf.float32), tf.TensorSpec([k, None], tf.float32)
        act_spec = tf.TensorSpec([k, None, a], tf.float32)
        self._updates = tf.function(self._updates_graph, jit_compile=XLA, input_signature=[
            obs_spec, act_spec, vec, obs_spec, vec, act_spec, act_spec])

    def _critic_variables(self):
        return self.critics[0].trainable_variables + self.critics[1].trainable_variables

    # ----------------------------------------------------------------- acting
    def sync_policy_weights(self) -> None:
        self.policy.load(self.actor.get_weights())

    def mean_and_log_std(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = self.policy(obs)
        mean, log_std = out[:, :self.act_dim], out[:, self.act_dim:]
        return mean, np.clip(log_std, self.cfg.log_std_min, self.cfg.log_std_max)

    def act(self, obs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """tanh(mean + std * noise) for a batch of observations."""
        mean, log_std = self.mean_and_log_std(obs)
        return np.tanh(mean + np.exp(log_std) * rng.standard_normal(mean.shape)).astype(np.float32)

    def greedy_actions(self, obs: np.ndarray) -> np.ndarray:
        """tanh(mean): the policy's mean action (the article's evaluation policy)."""
        return np.tanh(self.mean_and_log_std(obs)[0]).astype(np.float32)

    @property
    def alpha(self) -> float:
        return float(tf.exp(self.log_alpha))

    # --------------------------------------------------------------- learning
    def _policy(self, obs, noise):
        out = self.actor(obs, training=True)
        mean = out[:, :self.act_dim]
        log_std = tf.clip_by_value(out[:, self.act_dim:], self.cfg.log_std_min, self.cfg.log_std_max)
        return squashed_gaussian(mean, log_std, noise)

    def critic_targets(self, reward, next_obs, terminated, next_noise):
        cfg = self.cfg
        next_action, next_logp = self._policy(next_obs, next_noise)
        next_q = tf.minimum(*(t([next_obs, next_action])[:, 0] for t in self.targets))
        soft_value = next_q - tf.exp(self.log_alpha) * next_logp
        return tf.stop_gradient(reward + cfg.gamma * (1.0 - terminated) * soft_value)

    def _train_graph(self, obs, action, reward, next_obs, terminated, next_noise, noise):
        y = self.critic_targets(reward, next_obs, terminated, next_noise)
        with tf.GradientTape() as tape:
            q1, q2 = (c([obs, action], training=True)[:, 0] for c in self.critics)
            critic_loss = tf.reduce_mean(tf.square(q1 - y)) + tf.reduce_mean(tf.square(q2 - y))
        variables = self._critic_variables()
        self.critic_opt.apply_gradients(zip(tape.gradient(critic_loss, variables), variables))

        alpha = tf.exp(self.log_alpha)
        with tf.GradientTape() as tape:
            new_action, logp = self._policy(obs, noise)
            q_new = tf.minimum(*(c([obs, new_action])[:, 0] for c in self.critics))
            actor_loss = tf.reduce_mean(alpha * logp - q_new)
        variables = self.actor.trainable_variables
        self.actor_opt.apply_gradients(zip(tape.gradient(actor_loss, variables), variables))

        with tf.GradientTape() as tape:
            alpha_loss = -tf.reduce_mean(self.log_alpha * tf.stop_gradient(logp + self.target_entropy))
        self.alpha_opt.apply_gradients([(tape.gradient(alpha_loss, self.log_alpha), self.log_alpha)])

        tau = self.cfg.tau
        for target, critic in zip(self.targets, self.critics):
            for t_var, var in zip(target.weights, critic.weights):
                t_var.assign(tau * var + (1.0 - tau) * t_var)
        return {"critic_loss": critic_loss, "actor_loss": actor_loss, "alpha_loss": alpha_loss,
                "alpha": alpha, "entropy": -tf.reduce_mean(logp), "q_mean": tf.reduce_mean(q1)}

    def _updates_graph(self, obs, action, reward, next_obs, terminated, next_noise, noise):
        history = [self._train_graph(obs[i], action[i], reward[i], next_obs[i], terminated[i],
                                     next_noise[i], noise[i]) for i in range(self.cfg.updates_per_call)]
        means = {k: tf.reduce_mean(tf.stack([h[k] for h in history])) for k in history[0]}
        return means, self.actor.weights

    def observe(self, obs: np.ndarray) -> None:
        """Keep an observation for the running statistics (``obs_norm``; else nothing). It is
        folded in with the others at the next update or checkpoint, not once per env step."""
        if self.obs_stats is not None:
            self._unseen.append(obs)

    def obs_stats_state(self) -> dict | None:
        """The running statistics with every observation so far, for a checkpoint."""
        if self.obs_stats is None:
            return None
        self._fold_unseen()
        return self.obs_stats.state()

    def restore_obs_stats(self, state: dict | None) -> None:
        if self.obs_stats is not None:
            self.obs_stats, self._unseen = RunningMeanStd(self.obs_dim, state), []

    def _fold_unseen(self) -> None:
        if self._unseen:
            self.obs_stats.update(np.stack(self._unseen))
            self._unseen = []

    def _push_obs_stats(self) -> None:
        """The running statistics into the networks' Standardize layer (before each update)."""
        if self.obs_stats is not None:
            self._fold_unseen()
            self.standardize.mean.assign(self.obs_stats.mean.astype(np.float32))
            self.standardize.var.assign(self.obs_stats.var.astype(np.float32))

    def train_steps(self, obs, action, reward, next_obs, terminated, rng: np.random.Generator) -> dict:
        """``updates_per_call`` gradient steps on stacked minibatches (leading axis K)."""
        self._push_obs_stats()
        noise_shape = (*np.shape(action),)
        next_noise = rng.standard_normal(noise_shape).astype(np.float32)
        noise = rng.standard_normal(noise_shape).astype(np.float32)
        losses, weights = self._updates(obs, action, reward, next_obs, terminated, next_noise, noise)
        losses = {k: float(v) for k, v in losses.items()}
        bad = [k for k, v in losses.items() if not math.isfinite(v)]
        if bad:  # XLA drops check_numerics, so the check is here, after the call
            raise FloatingPointError(f"SAC {bad[0]} is NaN/Inf")
        self.policy.load(weights)
        return losses

    # ------------------------------------------------------------ persistence
    def save(self, folder: str | Path) -> list[Path]:
        return [save_keras_model(self.actor, Path(folder) / ACTOR_FILE)]

    def models(self) -> dict[str, keras.Model]:
        return {"actor": self.actor, "critic_1": self.critics[0], "critic_2": self.critics[1],
                "target_critic_1": self.targets[0], "target_critic_2": self.targets[1]}

    def optimizers(self) -> dict:
        return {"actor_opt": self.actor_opt, "critic_opt": self.critic_opt, "alpha_opt": self.alpha_opt}

    def get_weights(self) -> list[np.ndarray]:
        return self.actor.get_weights()

    def set_weights(self, weights: list[np.ndarray]) -> None:
        self.actor.set_weights(weights)
        self.sync_policy_weights()
