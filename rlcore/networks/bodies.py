"""The layers between an observation and a network's heads, shared by every family: an MLP for vector
observations, a CNN for images (H x W x C, ``uint8``, scaled to [0, 1] inside the network, so saved and
exported models take the env's frames as they come).

Two CNNs: ``"nature"``, the DQN of Mnih et al. (2015) for frames of 36 pixels a side or more (84 x 84
Atari frames); ``"small"``, the Mario article's 4 x Conv2D(32, 3, stride 2), for smaller frames and
PPO's networks (whose layer names its shipped models keep).
"""
from __future__ import annotations

import keras
import numpy as np
from keras import layers

NATURE = ((32, 8, 4), (64, 4, 2), (64, 3, 1))  # (filters, kernel, stride) of Mnih et al. (2015)
SMALL = ((32, 3, 2),) * 4
FEATURE_UNITS = 512


def is_image(obs_shape: tuple) -> bool:
    """A frame or a frame stack, H x W x C; anything else is a vector."""
    return len(tuple(obs_shape)) == 3


def as_shape(obs_shape: int | tuple) -> tuple[int, ...]:
    """An observation shape; an int is a vector's length (the agents' older signature)."""
    return (int(obs_shape),) if isinstance(obs_shape, (int, np.integer)) else tuple(int(n) for n in obs_shape)


def obs_dtype(obs_shape: tuple) -> np.dtype:
    """Frames stay ``uint8`` up to the network; vectors are float32."""
    return np.dtype(np.uint8) if is_image(obs_shape) else np.dtype(np.float32)


def observation_input(obs_shape: tuple, name: str = "obs") -> keras.KerasTensor:
    """The model's input: ``uint8`` frames for images (named ``frames``), float32 vectors otherwise."""
    if is_image(obs_shape):
        return keras.Input(tuple(obs_shape), dtype="uint8", name="frames")
    return keras.Input(tuple(obs_shape), dtype="float32", name=name)


def cnn_style(obs_shape: tuple) -> str:
    """``"nature"`` where its 8-pixel kernels and strides fit the frame, else ``"small"``."""
    return "nature" if min(obs_shape[:2]) >= 36 else "small"


def cnn_features(frames, style: str, dtype: str = "float32"):
    """Frames -> /255 -> the style's convolutions (ReLU) -> Flatten -> Dense 512 (ReLU).
    ``dtype``: Keras's layer policy (``"mixed_bfloat16"`` computes in bfloat16, weights stay float32)."""
    padding, convs = {"nature": ("valid", NATURE), "small": ("same", SMALL)}[style]
    x = layers.Rescaling(1.0 / 255.0, name="to_unit", dtype=dtype)(frames)
    for i, (filters, kernel, stride) in enumerate(convs):
        x = layers.Conv2D(filters, kernel, strides=stride, padding=padding, activation="relu",
                          name=f"conv_{i}", dtype=dtype)(x)
    x = layers.Flatten(name="flatten", dtype=dtype)(x)
    return layers.Dense(FEATURE_UNITS, activation="relu", name="feature", dtype=dtype)(x)


def mlp_features(x, hidden, activation: str = "relu", prefix: str = ""):
    """Dense layers ``{prefix}hidden_{i}`` of the given widths."""
    for i, units in enumerate(hidden):
        x = layers.Dense(units, activation=activation, name=f"{prefix}hidden_{i}")(x)
    return x


def features(obs, obs_shape: tuple, hidden, activation: str = "relu"):
    """The CNN (its style by frame size) for images, the MLP ``hidden`` for vectors."""
    if is_image(obs_shape):
        return cnn_features(obs, cnn_style(obs_shape))
    return mlp_features(obs, hidden, activation)
