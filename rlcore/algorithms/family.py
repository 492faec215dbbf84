"""What the rest of the package asks of an algorithm family, declared once in the family's folder
(``rlcore/algorithms/<kind>/__init__.py``) and looked up in :mod:`rlcore.algorithms.registry`.

TensorFlow-free: a family's callables import their Keras code when they are called, so the command
line, the env pool's workers and ``main.py list`` can read the registry cheaply.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:
    import gymnasium

    from rlcore.training.spec import RunSpec


@dataclass(frozen=True)
class Family:
    """An algorithm family: its config, agent, training loop and saved policy.

    ``variants``: algorithm names it offers on any Gymnasium env -> (description, config switches),
    e.g. ``"ddqn": ("Double DQN", {"double": True})``.
    ``policy_file``: the saved network that acts; ``load_policy(path, obs_shape, action_space, config)``
    rebuilds a batched policy from it (:mod:`rlcore.networks.acting`).
    ``acting_network(model)``: the Keras model cut to the output that acts, for export;
    ``export_output`` says what that output means.
    ``misfit(observation_space, action_space)``: why it cannot train on these spaces, or None.
    ``discrete``: it picks among discrete actions (exports compare greedy actions); ``stochastic``: its
    saved policy can draw from pi; ``env_pool``: it steps ``num_envs`` envs together (a cheap
    Gymnasium env runs them in-process).
    """
    kind: str
    description: str
    config: type
    train: Callable[[RunSpec], Path]
    build_agent: Callable[[Any, Any, Any], Any]
    policy_file: str
    load_policy: Callable[[Path, tuple, Any, Any], Any]
    export_output: str
    misfit: Callable[[Any, Any], str | None]
    variants: dict[str, tuple[str, dict]] = field(default_factory=dict)
    acting_network: Callable[[Any], Any] = lambda model: model
    discrete: bool = True
    stochastic: bool = False
    env_pool: bool = False


# ---------------------------------------------------------------- what spaces fit, in words
def is_vector(space: gymnasium.Space) -> bool:
    from gymnasium import spaces

    return isinstance(space, spaces.Box) and len(space.shape) == 1


def is_image(space: gymnasium.Space) -> bool:
    from gymnasium import spaces

    return isinstance(space, spaces.Box) and len(space.shape) == 3 and space.dtype == np.uint8


def needs_discrete_actions(action_space: gymnasium.Space) -> str | None:
    from gymnasium import spaces

    if not isinstance(action_space, spaces.Discrete):
        return f"it needs discrete actions (a Discrete space), and the env's are {action_space}"
    return None


def needs_vector_observations(observation_space: gymnasium.Space) -> str | None:
    if not is_vector(observation_space):
        return f"it needs vector observations (a 1-D Box), and the env's are {observation_space}"
    return None


def needs_vectors_or_images(observation_space: gymnasium.Space) -> str | None:
    if not (is_vector(observation_space) or is_image(observation_space)):
        return (f"it needs vector observations (a 1-D Box) or uint8 images (H x W x C), and the env's are "
                f"{observation_space}")
    return None


def discrete_on_vectors(observation_space: gymnasium.Space, action_space: gymnasium.Space) -> str | None:
    """Discrete actions, vector observations (an MLP-only family, such as the tests' toy one)."""
    return needs_discrete_actions(action_space) or needs_vector_observations(observation_space)


def discrete_on_vectors_or_images(observation_space: gymnasium.Space, action_space: gymnasium.Space) -> str | None:
    """The DQN family's, A2C's and PPO's fit: discrete actions; vectors (MLP) or images (CNN)."""
    return needs_discrete_actions(action_space) or needs_vectors_or_images(observation_space)
