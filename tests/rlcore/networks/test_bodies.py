"""The shared network bodies (issue 65): the Nature-DQN CNN for 84 x 84 frames, the article's small CNN for
smaller ones, uint8 frames in, and the acting forward pass of a CNN equal to the model's own."""
import numpy as np

from rlcore.algorithms.a2c.agent import A2CAgent
from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.dqn.agent import DQNAgent, build_q_network
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.networks.bodies import cnn_style
from rlcore.networks.numpy_forward import CompiledForward, NumpyForward, acting_forward


def test_84_pixel_frames_get_the_nature_cnn_and_small_frames_the_articles():
    assert cnn_style((84, 84, 4)) == "nature" and cnn_style((20, 20, 3)) == "small"
    nature = build_q_network((84, 84, 4), 6)
    kernels = [layer.kernel.shape for layer in nature.layers if layer.name.startswith("conv_")]
    assert kernels == [(8, 8, 4, 32), (4, 4, 32, 64), (3, 3, 64, 64)]  # Mnih et al. (2015)
    assert nature.get_layer("flatten").output.shape[-1] == 7 * 7 * 64 and nature.inputs[0].dtype == "uint8"
    small = build_q_network((20, 20, 3), 4, dueling=True)
    assert sum(layer.name.startswith("conv_") for layer in small.layers) == 4


def test_a_cnn_acts_through_the_model_and_an_mlp_through_numpy():
    vector = build_q_network(8, 4)
    assert isinstance(acting_forward(vector), NumpyForward)
    image = build_q_network((36, 36, 2), 3, dueling=True)
    forward = acting_forward(image)
    assert isinstance(forward, CompiledForward)
    frames = np.random.default_rng(0).integers(0, 256, (5, 36, 36, 2), dtype=np.uint8)
    np.testing.assert_allclose(forward(frames), image(frames).numpy(), rtol=1e-5, atol=1e-6)


def test_dqn_and_a2c_take_a_gradient_step_on_frames():
    rng = np.random.default_rng(0)
    dqn = DQNAgent((36, 36, 2), 3, DQNConfig(batch_size=4))
    frames = rng.integers(0, 256, (4, 36, 36, 2), dtype=np.uint8)
    before = dqn.greedy_actions(frames)
    losses = dqn.train_step(frames, np.array([0, 1, 2, 0], np.int32), np.ones(4, np.float32), frames,
                            np.zeros(4, np.float32))
    assert np.isfinite(losses["loss"]) and before.shape == (4,)
    cfg = A2CConfig(n_steps=2, num_envs=2)
    a2c = A2CAgent((36, 36, 2), 3, cfg)
    assert a2c.act(frames[:2], rng).shape == (2,)
    before = [w.copy() for w in a2c.actor.model.get_weights()]
    rollout = frames.reshape(2, 2, 36, 36, 2)
    losses = a2c.update(rollout, np.zeros((2, 2), np.int32), np.ones((2, 2), np.float32), rollout,
                        np.zeros((2, 2), np.float32), np.zeros((2, 2), np.float32))
    assert all(np.isfinite(v) for v in losses.values())
    assert any(not np.array_equal(b, a) for b, a in zip(before, a2c.actor.model.get_weights()))
