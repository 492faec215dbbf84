"""Generalized advantage estimation as a graph, shared by A2C and PPO."""
from __future__ import annotations

import tensorflow as tf


def gae(rewards, values, next_values, terminated, dones, gamma: float, lam: float):
    """Advantages over a [T, N] rollout (T static or not), computed backwards with ``tf.scan``.

    delta_t = r_t + gamma * (1 - terminated_t) * V(s'_t) - V(s_t)
    A_t     = delta_t + gamma * lam * (1 - done_t) * A_{t+1}

    ``terminated`` stops the bootstrap (a real end); ``dones`` (terminated or truncated) stops the
    sum from running into the next episode. A truncated step bootstraps from ``next_values``.
    """
    deltas = rewards + gamma * (1.0 - terminated) * next_values - values
    carry = gamma * lam * (1.0 - dones)
    return tf.scan(lambda running, x: x[0] + x[1] * running, (deltas, carry),
                   initializer=tf.zeros_like(deltas[0]), reverse=True)
