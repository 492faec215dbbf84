"""Custom Keras layers, registered so saved ``.h5`` models load without Lambda layers."""
import keras
from keras import layers, ops


@keras.saving.register_keras_serializable(package="rlcore")
class DuelingCombine(layers.Layer):
    """Q(s, a) = V(s) + A(s, a) - mean_a A(s, a), from inputs ``[value (B,1), advantage (B,A)]``."""

    def call(self, inputs):
        value, advantage = inputs
        return value + advantage - ops.mean(advantage, axis=-1, keepdims=True)
