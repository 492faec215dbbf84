"""DQN agent: targets, dueling head, forward pass and update against numpy references."""
import dataclasses

import numpy as np
import pytest
import tensorflow as tf

from rlcore.algorithms.dqn.agent import DQNAgent, build_q_network
from rlcore.algorithms.dqn.config import DQNConfig
from rlcore.errors import UserError
from rlcore.networks.layers import DuelingCombine
from rlcore.networks.numpy_forward import NumpyForward
from tests import numpy_reference as ref

OBS, ACTIONS, BATCH = 8, 4, 32


def random_batch(seed=0):
    rng = np.random.default_rng(seed)
    return (rng.normal(size=(BATCH, OBS)).astype(np.float32),
            rng.integers(0, ACTIONS, BATCH).astype(np.int32),
            rng.normal(size=BATCH).astype(np.float32),
            rng.normal(size=(BATCH, OBS)).astype(np.float32),
            (rng.random(BATCH) < 0.3).astype(np.float32))


def agent_with_distinct_target(double, dueling=False):
    agent = DQNAgent(OBS, ACTIONS, DQNConfig(double=double, dueling=dueling, hidden=(16, 16)))
    rng = np.random.default_rng(1)  # make target differ from online, so double vs plain matters
    agent.target_network.set_weights([w + rng.normal(scale=0.5, size=w.shape).astype(np.float32)
                                      for w in agent.target_network.get_weights()])
    return agent


@pytest.mark.parametrize("double", [False, True])
def test_td_target_matches_numpy(double):
    agent = agent_with_distinct_target(double)
    _, _, reward, next_obs, terminated = random_batch()
    got = agent.td_target(reward, next_obs, terminated).numpy()
    want = ref.dqn_td_target(reward, terminated, agent.target_network(next_obs).numpy(),
                             agent.q_network(next_obs).numpy(), agent.cfg.gamma, double)
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5)


def test_double_and_plain_targets_differ_when_nets_disagree():
    _, _, reward, next_obs, terminated = random_batch()
    plain = agent_with_distinct_target(False)
    double = agent_with_distinct_target(True)
    double.q_network.set_weights(plain.q_network.get_weights())
    double.target_network.set_weights(plain.target_network.get_weights())
    assert not np.allclose(plain.td_target(reward, next_obs, terminated),
                           double.td_target(reward, next_obs, terminated))


def test_terminated_transitions_do_not_bootstrap():
    agent = agent_with_distinct_target(False)
    _, _, reward, next_obs, _ = random_batch()
    got = agent.td_target(reward, next_obs, np.ones(BATCH, np.float32)).numpy()
    np.testing.assert_allclose(got, reward, rtol=1e-6)


def test_dueling_combine_matches_numpy():
    rng = np.random.default_rng(2)
    value = rng.normal(size=(5, 1)).astype(np.float32)
    advantage = rng.normal(size=(5, ACTIONS)).astype(np.float32)
    got = DuelingCombine()([value, advantage]).numpy()
    np.testing.assert_allclose(got, ref.dueling_combine(value, advantage), rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("dueling", [False, True])
def test_keras_forward_matches_numpy_forward(dueling):
    model = build_q_network(OBS, ACTIONS, (32, 16), dueling)
    obs = random_batch()[0]
    np.testing.assert_allclose(model(obs).numpy(), ref.q_values(model.get_weights(), obs, dueling),
                               rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(NumpyForward(model)(obs), model(obs).numpy(), rtol=1e-4, atol=1e-5)


def test_update_with_constant_weights_matches_hand_computed_loss():
    """Zero hidden weights: Q(s, .) = output bias b for every s; everything is computable by hand."""
    cfg = DQNConfig(hidden=(4,), gamma=0.5, lr=1e-3, tau=0.1)
    agent = DQNAgent(OBS, 2, cfg)
    bias = np.array([1.0, 3.0], np.float32)
    weights = [np.zeros((OBS, 4), np.float32), np.zeros(4, np.float32), np.zeros((4, 2), np.float32), bias]
    agent.q_network.set_weights(weights)
    agent.target_network.set_weights(weights)
    obs = np.ones((2, OBS), np.float32)
    action = np.array([0, 0], np.int32)
    reward = np.array([1.0, 0.0], np.float32)
    terminated = np.array([0.0, 1.0], np.float32)
    # targets: 1 + 0.5 * max(1, 3) = 2.5 and 0 (terminated); Q taken: 1 and 1 (all Q: mean 2)
    # loss = mean((2.5 - 1)^2, (0 - 1)^2) = (2.25 + 1) / 2 = 1.625
    losses = agent.train_step(obs, action, reward, obs, terminated)
    assert losses["loss"] == pytest.approx(1.625, rel=1e-5)
    assert losses["q_mean"] == pytest.approx(1.0, rel=1e-5)  # of the actions taken, not of every Q
    # Adam's first step moves a bias with a non-zero gradient by lr (d loss / d b0 = -0.5 < 0: up);
    # action 1 was not taken, so its bias stays. The target moves tau of the way.
    new_bias = agent.q_network.get_weights()[-1]
    np.testing.assert_allclose(new_bias, bias + np.array([1e-3, 0.0]), rtol=0, atol=1e-6)
    target_bias = agent.target_network.get_weights()[-1]
    np.testing.assert_allclose(target_bias, 0.9 * bias + 0.1 * new_bias, rtol=0, atol=1e-7)
    assert abs(target_bias[0] - bias[0]) > 5e-5  # and that move is larger than the tolerance
    np.testing.assert_allclose(agent.policy.weights[-1], new_bias)  # acting sees the update


def test_huber_loss_by_hand():
    cfg = DQNConfig(hidden=(4,), gamma=0.0, loss="huber")
    agent = DQNAgent(OBS, 2, cfg)
    weights = [np.zeros((OBS, 4), np.float32), np.zeros(4, np.float32), np.zeros((4, 2), np.float32),
               np.array([0.0, 0.0], np.float32)]
    agent.q_network.set_weights(weights)
    agent.target_network.set_weights(weights)
    obs = np.ones((2, OBS), np.float32)
    # errors 0.5 and 3: huber = 0.5 * 0.25 = 0.125 and 3 - 0.5 = 2.5 -> mean 1.3125
    losses = agent.train_step(obs, np.array([0, 1], np.int32), np.array([0.5, 3.0], np.float32), obs,
                              np.zeros(2, np.float32))
    assert losses["loss"] == pytest.approx(1.3125, rel=1e-5)


def test_stacked_updates_equal_sequential_updates():
    batches = [random_batch(s) for s in range(3)]
    one = DQNAgent(OBS, ACTIONS, DQNConfig(hidden=(16,)))
    many = DQNAgent(OBS, ACTIONS, DQNConfig(hidden=(16,)))
    many.q_network.set_weights(one.q_network.get_weights())
    many.target_network.set_weights(one.target_network.get_weights())
    for b in batches:
        one.train_step(*b)
    many.train_steps(*(np.stack(x) for x in zip(*batches)))
    for a, b in zip(one.q_network.get_weights(), many.q_network.get_weights()):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)


def test_train_step_does_not_retrace():
    agent = DQNAgent(OBS, ACTIONS, DQNConfig(hidden=(16,)))
    for seed in range(4):
        agent.train_step(*random_batch(seed))
    assert agent._compiled(1).experimental_get_tracing_count() == 1


def test_nan_loss_is_caught():
    agent = DQNAgent(OBS, ACTIONS, DQNConfig(hidden=(16,)))
    obs, action, reward, next_obs, terminated = random_batch()
    reward[0] = np.nan
    with pytest.raises(tf.errors.InvalidArgumentError, match="DQN loss"):
        agent.train_step(obs, action, reward, next_obs, terminated)


def test_epsilon_greedy_explores_and_exploits():
    agent = DQNAgent(OBS, ACTIONS, DQNConfig(hidden=(16,)))
    rng = np.random.default_rng(0)
    obs = random_batch()[0][0]
    greedy = agent.greedy_actions(obs[None])[0]
    assert {agent.act(obs, 0.0, rng) for _ in range(20)} == {greedy}
    assert len({agent.act(obs, 1.0, rng) for _ in range(200)}) == ACTIONS


def test_saved_model_loads_with_shape_checks(tmp_path):
    from rlcore.networks.saving import load_keras_model

    agent = DQNAgent(OBS, ACTIONS, dataclasses.replace(DQNConfig(), dueling=True))
    path = agent.save(tmp_path)
    model = load_keras_model(path, OBS, ACTIONS)
    obs = random_batch()[0]
    np.testing.assert_allclose(model(obs).numpy(), agent.q_network(obs).numpy(), rtol=1e-6)
    with pytest.raises(UserError, match="takes input"):
        load_keras_model(path, OBS + 1, ACTIONS)
    with pytest.raises(UserError, match="outputs"):
        load_keras_model(path, OBS, ACTIONS + 1)


def test_tutorial_epsilon_schedule():
    from cartpole.experiment import DQN_ARTICLE
    from rlcore.algorithms.dqn.train import step_epsilon

    assert step_epsilon(DQN_ARTICLE, 0) == pytest.approx(0.9)
    assert step_epsilon(DQN_ARTICLE, 1000) == pytest.approx(0.05 + 0.85 / np.e)
    assert step_epsilon(DQN_ARTICLE, 100_000) == pytest.approx(0.05, abs=1e-12)


def test_two_updates_with_clipped_gradients_equal_an_eager_loop_with_a_numpy_clip():
    """grad_clip_value clips each gradient element to [-c, c] before the optimizer (CartPole's
    tutorial: AdamW, amsgrad). Two steps, since the first hardly depends on the gradient's scale."""
    cfg = DQNConfig(hidden=(16,), lr=1e-2, optimizer="adamw", loss="mse", grad_clip_value=0.05, tau=0.1)
    tf.keras.utils.set_random_seed(0)
    agent, twin = DQNAgent(OBS, ACTIONS, cfg), DQNAgent(OBS, ACTIONS, cfg)
    for mine, theirs in zip(agent.models().values(), twin.models().values()):
        theirs.set_weights(mine.get_weights())
    clipped_share = []
    for seed in (1, 2):
        obs, action, reward, next_obs, terminated = random_batch(seed)
        reward = reward * 10  # large errors, so most gradient elements pass the clip
        agent.train_step(obs, action, reward, next_obs, terminated)
        target = twin.td_target(reward, next_obs, terminated)
        with tf.GradientTape() as tape:
            q = tf.gather(twin.q_network(obs, training=True), action, batch_dims=1)
            loss = tf.reduce_mean(tf.square(target - q))
        grads = [g.numpy() for g in tape.gradient(loss, twin.q_network.trainable_variables)]
        clipped_share.append(np.mean(np.concatenate([np.abs(g).ravel() > 0.05 for g in grads])))
        twin.optimizer.apply_gradients(zip([np.clip(g, -0.05, 0.05) for g in grads],
                                           twin.q_network.trainable_variables))
        twin.soft_update()
    assert min(clipped_share) > 0.2, clipped_share
    for mine, theirs in zip(agent.models().values(), twin.models().values()):
        for got, want in zip(mine.get_weights(), theirs.get_weights()):
            np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)
