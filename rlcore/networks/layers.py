"""Custom Keras layers, registered so saved ``.h5`` models load without Lambda layers."""
import keras
from keras import layers, ops


@keras.saving.register_keras_serializable(package="rlcore")
class DuelingCombine(layers.Layer):
    """Q(s, a) = V(s) + A(s, a) - mean_a A(s, a), from inputs ``[value (B,1), advantage (B,A)]``."""

    def call(self, inputs):
        value, advantage = inputs
        return value + advantage - ops.mean(advantage, axis=-1, keepdims=True)


@keras.saving.register_keras_serializable(package="rlcore")
class Standardize(layers.Layer):
    """(x - mean) / sqrt(var + 1e-8), clipped to [-clip, clip]. ``mean`` and ``var`` are weights that
    training does not touch: the trainer sets them from running statistics (:class:`RunningMeanStd`),
    and they travel inside the saved ``.h5``, so an evaluation standardizes as training did."""

    EPS = 1e-8

    def __init__(self, clip: float = 10.0, **kwargs):
        super().__init__(**kwargs)
        self.clip = float(clip)

    def build(self, input_shape):
        dim = input_shape[-1]
        self.mean = self.add_weight(shape=(dim,), initializer="zeros", trainable=False, name="mean")
        self.var = self.add_weight(shape=(dim,), initializer="ones", trainable=False, name="var")

    def call(self, x):
        return ops.clip((x - self.mean) / ops.sqrt(self.var + self.EPS), -self.clip, self.clip)

    def get_config(self):
        return {**super().get_config(), "clip": self.clip}
