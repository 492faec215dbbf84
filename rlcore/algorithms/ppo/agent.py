"""PPO with a shared CNN feature, a softmax policy head and a value head (article 001).

The network reads ``uint8`` frame stacks and scales them to [0, 1] itself, so frames cross the
env pool as bytes. It outputs policy logits (pi = softmax(logits)) and V(s). On vector observations
(any Gymnasium env with a 1-D Box) two tanh MLPs, one per output, stand in for the CNN.

One update is one compiled call: GAE over the [T, N] rollout, then ``epochs`` passes of shuffled
minibatches (the shuffles come from the trainer's numpy RNG, so a resumed run replays exactly).

Loss per minibatch::

    ratio  = exp(log pi(a|s) - log pi_old(a|s))
    policy = -mean(min(ratio A, clip(ratio, 1 - eps, 1 + eps) A))
    value  = mean((V(s) - target)^2)
    loss   = policy + value_coef * value - entropy_coef * mean(H(pi(.|s)))
    approx_kl = mean((ratio - 1) - log ratio)      (KL(pi_old || pi), never negative)

With ``target_kl`` set, the update stops (before its gradient step) at the first minibatch whose
approx_kl passes 1.5 x target_kl, as Stable-Baselines3 does; ``update_fraction`` logs the share
of the planned minibatch steps that were taken.

``article_quirks`` swaps in the article's ratio pi / (pi_old + 1e-3) and its entropy stand-in,
-log(pi(a|s) + 1e-3) of the taken action.
"""
from __future__ import annotations

from pathlib import Path

import keras
import numpy as np
import tensorflow as tf
from keras import layers

from rlcore.algorithms.advantages import gae
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.errors import UserError
from rlcore.host.cpu import bfloat16_refusal, cpu_flags
from rlcore.networks.bodies import cnn_features, is_image, mlp_features, obs_dtype, observation_input
from rlcore.networks.sampling import sample_categorical, softmax
from rlcore.networks.saving import save_keras_model

MODEL_FILE = "actor_critic.h5"
_QUIRK_EPS = 1e-3  # the article's constant in pi / (pi_old + 1e-3) and log(pi + 1e-3)


def build_actor_critic(obs_shape: tuple, n_actions: int, precision: str = "float32",
                       hidden: tuple[int, ...] = (64, 64)) -> keras.Model:
    """Images: :func:`build_cnn_actor_critic`; vector observations: :func:`build_mlp_actor_critic`."""
    if is_image(tuple(obs_shape)):
        return build_cnn_actor_critic(tuple(obs_shape), n_actions, precision)
    return build_mlp_actor_critic(tuple(obs_shape), n_actions, hidden)


def build_mlp_actor_critic(obs_shape: tuple, n_actions: int, hidden: tuple[int, ...]) -> keras.Model:
    """Vector observations: two separate tanh MLPs in one model (as CleanRL's and SB3's PPO on
    classic control), so the value loss does not pull on the policy's features. Outputs
    ``[logits, value]`` like the CNN model."""
    obs = keras.Input(obs_shape, dtype="float32", name="obs")
    tower = {head: mlp_features(obs, hidden, "tanh", prefix=f"{head}_") for head in ("policy", "value")}
    logits = layers.Dense(n_actions, name="policy_logits")(tower["policy"])
    value = layers.Dense(1, name="value")(tower["value"])
    return keras.Model(obs, [logits, value], name="actor_critic")


def build_cnn_actor_critic(obs_shape: tuple, n_actions: int, precision: str = "float32") -> keras.Model:
    """Feature: 4 x Conv2D(32, 3, stride 2, same, ReLU) -> Flatten -> Dense 512; then two heads.

    ``precision="bfloat16"`` makes the feature layers compute in bfloat16 (Keras's mixed_bfloat16
    policy: their weights stay float32). The two heads always compute in float32, so logits, values
    and every loss built on them are float32.
    """
    if reason := bfloat16_refusal(precision, cpu_flags()):
        raise UserError(reason)
    body = "mixed_bfloat16" if precision == "bfloat16" else "float32"
    frames = observation_input(obs_shape)
    x = cnn_features(frames, "small", body)
    logits = layers.Dense(n_actions, name="policy_logits", dtype="float32")(x)
    value = layers.Dense(1, name="value", dtype="float32")(x)
    return keras.Model(frames, [logits, value], name="actor_critic")


def ppo_losses(logits, values, actions, logp_old, advantages, targets, cfg: PPOConfig, entropy_coef=None):
    """(total, policy, value, entropy, approx_kl, clip_fraction) of one minibatch; ``entropy_coef`` (a
    variable while --entropy-halve-at may change it) defaults to the config's."""
    entropy_coef = cfg.entropy_coef if entropy_coef is None else entropy_coef
    logp_all = tf.nn.log_softmax(logits)
    logp = tf.gather(logp_all, actions, batch_dims=1)
    if cfg.normalize_advantage:
        advantages = (advantages - tf.reduce_mean(advantages)) / (tf.math.reduce_std(advantages) + 1e-8)
    if cfg.article_quirks:
        ratio = tf.exp(logp) / (tf.exp(logp_old) + _QUIRK_EPS)
        entropy = -tf.reduce_mean(tf.math.log(tf.exp(logp) + _QUIRK_EPS))
    else:
        ratio = tf.exp(logp - logp_old)
        entropy = -tf.reduce_mean(tf.reduce_sum(tf.exp(logp_all) * logp_all, axis=1))
    clipped = tf.clip_by_value(ratio, 1.0 - cfg.clip, 1.0 + cfg.clip)
    policy_loss = -tf.reduce_mean(tf.minimum(ratio * advantages, clipped * advantages))
    err = values - targets
    if cfg.value_loss == "huber":  # = PyTorch's smooth_l1_loss with beta 1
        value_loss = tf.reduce_mean(tf.where(tf.abs(err) < 1.0, 0.5 * tf.square(err), tf.abs(err) - 0.5))
    else:
        value_loss = tf.reduce_mean(tf.square(err))
    total = policy_loss + cfg.value_coef * value_loss - entropy_coef * entropy
    log_ratio = logp - logp_old
    approx_kl = tf.reduce_mean(tf.exp(log_ratio) - 1.0 - log_ratio)
    clip_fraction = tf.reduce_mean(tf.cast(tf.abs(ratio - 1.0) > cfg.clip, tf.float32))
    return total, policy_loss, value_loss, entropy, approx_kl, clip_fraction


def rollout_targets(rewards, values, next_values, terminated, dones, cfg: PPOConfig):
    """(advantages, value targets) of a [T, N] rollout."""
    advantages = gae(rewards, values, next_values, terminated, dones, cfg.gamma, cfg.gae_lambda)
    if cfg.value_target == "td0":
        targets = rewards + cfg.gamma * (1.0 - terminated) * next_values
    else:
        targets = advantages + values
    return advantages, targets


LOSS_NAMES = ("loss", "policy_loss", "value_loss", "entropy", "approx_kl", "clip_fraction")
APPROX_KL = LOSS_NAMES.index("approx_kl")
UPDATE_NAMES = LOSS_NAMES + ("update_fraction",)  # what one update reports


class PPOAgent:
    """Samples actions from pi (numpy RNG) and runs the whole PPO update as one compiled call."""

    def __init__(self, obs_shape: tuple, n_actions: int, cfg: PPOConfig):
        self.obs_shape, self.n_actions, self.cfg = tuple(obs_shape), n_actions, cfg
        self.model = build_actor_critic(self.obs_shape, n_actions, cfg.precision, cfg.hidden)
        self.obs_dtype = obs_dtype(self.obs_shape)  # frames stay uint8 up to the model
        self.opt = keras.optimizers.Adam(cfg.lr)
        self.opt.build(self.model.trainable_variables)
        # a variable, so --entropy-halve-at changes it without retracing the compiled update
        self.entropy_coef = tf.Variable(cfg.entropy_coef, dtype=tf.float32, trainable=False)
        frames = tf.TensorSpec([None, *self.obs_shape], tf.as_dtype(self.obs_dtype))
        self._forward = tf.function(lambda obs: self.model(obs), input_signature=[frames])
        t, n = cfg.n_steps, cfg.num_envs
        vec = tf.TensorSpec([t, n], tf.float32)
        self._update = tf.function(self._update_graph, autograph=False, input_signature=[
            tf.TensorSpec([t, n, *self.obs_shape], tf.as_dtype(self.obs_dtype)), tf.TensorSpec([t, n], tf.int32),
            vec, vec, vec, vec, vec, vec, tf.TensorSpec([cfg.epochs, t * n], tf.int32)])

    # ----------------------------------------------------------------- acting
    def policy_and_values(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(pi(.|s) [B, A], V(s) [B]) for a batch of observations (frame stacks or vectors)."""
        logits, values = self._forward(np.asarray(obs, self.obs_dtype))
        return softmax(logits.numpy()), values.numpy()[:, 0]

    def act(self, obs: np.ndarray, rng: np.random.Generator):
        """Sampled actions, their log-probabilities and V(s), one per row of ``obs``."""
        probs, values = self.policy_and_values(obs)
        actions = sample_categorical(probs, rng)
        logp = np.log(np.maximum(probs[np.arange(len(actions)), actions], 1e-12))
        return actions, logp.astype(np.float32), values.astype(np.float32)

    def sync_policy_weights(self) -> None:
        """Nothing to refresh: PPO acts through the compiled model itself (a CNN is no job for numpy)."""

    def values(self, obs: np.ndarray) -> np.ndarray:
        return self.policy_and_values(obs)[1]

    def greedy_actions(self, obs: np.ndarray) -> np.ndarray:
        return self.policy_and_values(obs)[0].argmax(axis=1)

    # --------------------------------------------------------------- learning
    def _update_graph(self, obs, actions, logp_old, values, next_values, rewards, terminated, dones,
                      perms):
        cfg = self.cfg
        t, n = cfg.n_steps, cfg.num_envs
        advantages, targets = rollout_targets(rewards, values, next_values, terminated, dones, cfg)
        size = t * n
        flat = (tf.reshape(obs, [size, *self.obs_shape]), tf.reshape(actions, [size]),
                tf.reshape(logp_old, [size]), tf.reshape(advantages, [size]), tf.reshape(targets, [size]))
        per_epoch = size // cfg.minibatch
        planned = cfg.epochs * per_epoch
        kl_limit = 1.5 * cfg.target_kl if cfg.target_kl > 0 else float("inf")
        variables = self.model.trainable_variables

        # One minibatch step of the loop below (written as tf.while_loop, not a Python loop for
        # AutoGraph to convert: a conversion that fails falls back silently, and the loop then fails).
        def minibatch(step, sums, evaluated, taken, too_far):
            epoch, k = step // per_epoch, step % per_epoch
            idx = perms[epoch, k * cfg.minibatch:(k + 1) * cfg.minibatch]
            mb_obs, mb_act, mb_logp, mb_adv, mb_tgt = (tf.gather(x, idx) for x in flat)
            with tf.GradientTape() as tape:
                logits, v = self.model(mb_obs, training=True)
                losses = ppo_losses(logits, v[:, 0], mb_act, mb_logp, mb_adv, mb_tgt, cfg, self.entropy_coef)
                total = tf.debugging.check_numerics(losses[0], "PPO loss")
            too_far = losses[APPROX_KL] > kl_limit  # the policy moved too far from the one that acted: stop here

            def step_on():
                grads = tape.gradient(total, variables)
                if cfg.max_grad_norm > 0:
                    grads, _ = tf.clip_by_global_norm(grads, cfg.max_grad_norm)
                self.opt.apply_gradients(zip(grads, variables))
                return taken + 1

            taken = tf.cond(too_far, lambda: taken, step_on)
            return step + 1, sums + tf.stack(losses), evaluated + 1, taken, too_far

        _, sums, evaluated, taken, _ = tf.while_loop(
            lambda step, sums, evaluated, taken, too_far: tf.logical_and(step < planned, tf.logical_not(too_far)),
            minibatch, (tf.constant(0), tf.zeros([len(LOSS_NAMES)]), tf.constant(0), tf.constant(0), tf.constant(False)))
        means = sums / tf.cast(evaluated, tf.float32)  # the minibatch that stopped the update counts
        return tf.concat([means, [tf.cast(taken, tf.float32) / planned]], axis=0)

    def update(self, obs, actions, logp_old, values, next_values, rewards, terminated, dones,
               rng: np.random.Generator) -> dict[str, float]:
        """One PPO update on a [n_steps, num_envs] rollout; returns the mean losses of the minibatches
        evaluated (those stepped on, and the one that stopped the update, as in Stable-Baselines3) and
        ``update_fraction``, the share of the planned steps taken."""
        size = self.cfg.n_steps * self.cfg.num_envs
        perms = np.stack([rng.permutation(size) for _ in range(self.cfg.epochs)]).astype(np.int32)
        means = self._update(obs, actions, logp_old, values, next_values, rewards, terminated, dones, perms)
        return dict(zip(UPDATE_NAMES, (float(x) for x in means.numpy())))

    def set_learning_rate(self, lr: float) -> None:
        """Adam's rate for the next updates (a variable, so the compiled update is not retraced)."""
        self.opt.learning_rate.assign(lr)

    def set_entropy_coef(self, weight: float) -> None:
        """The entropy weight for the next updates (a variable, as the learning rate)."""
        self.entropy_coef.assign(weight)

    # ------------------------------------------------------------ persistence
    def save(self, folder: str | Path) -> list[Path]:
        return [save_keras_model(self.model, Path(folder) / MODEL_FILE)]

    def models(self) -> dict[str, keras.Model]:
        return {"actor_critic": self.model}

    def optimizers(self) -> dict:
        return {"adam": self.opt}

    def get_weights(self) -> list[np.ndarray]:
        return self.model.get_weights()

    def set_weights(self, weights: list[np.ndarray]) -> None:
        self.model.set_weights(weights)
