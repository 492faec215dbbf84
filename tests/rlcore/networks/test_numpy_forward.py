"""NumpyForward: the numpy acting copy read off a Keras model, against the model itself."""
import keras
import numpy as np
import pytest
from keras import layers

from rlcore.algorithms.a2c.agent import Actor
from rlcore.algorithms.dqn.agent import build_q_network
from rlcore.algorithms.ppo.agent import build_actor_critic
from rlcore.networks.numpy_forward import NumpyForward

OBS = 6


def _obs(rows=9, seed=0):
    return np.random.default_rng(seed).normal(size=(rows, OBS)).astype(np.float32)


@pytest.mark.parametrize("build", [
    lambda: build_q_network(OBS, 4, (32, 16), dueling=False),
    lambda: build_q_network(OBS, 4, (32, 16), dueling=True),
    lambda: Actor(OBS, 3, 1e-3, (16, 8)).model,
], ids=["q", "dueling-q", "softmax-actor"])
def test_matches_the_keras_model(build):
    model = build()
    np.testing.assert_allclose(NumpyForward(model)(_obs()), model(_obs()).numpy(), rtol=1e-4, atol=1e-6)


def test_two_outputs_and_tanh_come_back_as_a_list():
    obs = keras.Input((OBS,))
    x = layers.Dense(8, activation="tanh")(obs)
    model = keras.Model(obs, [layers.Dense(2)(x), layers.Dense(1)(x)])
    got = NumpyForward(model)(_obs())
    assert isinstance(got, list) and len(got) == 2
    for g, want in zip(got, model(_obs())):
        np.testing.assert_allclose(g, want.numpy(), rtol=1e-4, atol=1e-6)


def test_load_takes_new_weights_and_copies_them():
    model = build_q_network(OBS, 2, (8,))
    forward = NumpyForward(model)
    weights = [w + 0.5 for w in model.get_weights()]
    forward.load(weights)
    weights[-1][:] = 100.0  # the caller's array changes later: the copy must not
    model.set_weights([w + 0.5 for w in model.get_weights()])
    np.testing.assert_allclose(forward(_obs()), model(_obs()).numpy(), rtol=1e-4, atol=1e-5)


def test_an_unknown_layer_is_refused_when_built():
    with pytest.raises(NotImplementedError, match="to_unit"):
        NumpyForward(build_actor_critic((84, 84, 4), 7))  # Rescaling + Conv2D: not for numpy
