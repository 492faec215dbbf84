"""SAC: the squashed-Gaussian log-probability, one full update against numpy, and checkpoints."""
import dataclasses
import math

import numpy as np
import pytest
import tensorflow as tf

from rlcore.algorithms.sac.agent import SACAgent, squashed_gaussian
from rlcore.algorithms.sac.config import SACConfig
from rlcore.files.checkpoint import load_checkpoint, save_checkpoint
from tests import numpy_reference as ref

OBS, ACT = 6, 3
CFG = SACConfig(actor_hidden=(16, 16), critic_hidden=(16, 16), gamma=0.9, tau=0.1, init_alpha=0.5,
                actor_lr=1e-3, critic_lr=1e-3, alpha_lr=1e-3)


def test_log_prob_has_the_tanh_correction():
    rng = np.random.default_rng(0)
    mean, log_std, noise = rng.normal(size=(50, ACT)), rng.normal(size=(50, ACT)) * 0.5, rng.normal(size=(50, ACT))
    action, logp = squashed_gaussian(*(tf.constant(x, tf.float32) for x in (mean, log_std, noise)))
    want_a, want_logp = ref.squashed_gaussian(mean, log_std, noise)
    np.testing.assert_allclose(action.numpy(), want_a, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(logp.numpy(), want_logp, rtol=1e-4, atol=1e-4)


def test_squashed_density_integrates_to_one_on_the_action_interval():
    """In 1-D, exp(log pi(a)) over a in (-1, 1) must integrate to 1: the correction is right."""
    a = np.linspace(-0.999999, 0.999999, 200_001)
    u = np.arctanh(a)
    mean, log_std = 0.3, math.log(0.8)
    noise = (u - mean) / math.exp(log_std)
    _, logp = squashed_gaussian(*(tf.constant(np.full((len(a), 1), v), tf.float64)
                                  for v in (mean, log_std)), tf.constant(noise[:, None]))
    assert np.trapezoid(np.exp(logp.numpy()), a) == pytest.approx(1.0, abs=2e-3)


def test_stable_log_det_matches_the_naive_one_where_both_work():
    u = tf.constant(np.linspace(-5, 5, 101)[:, None])
    _, logp = squashed_gaussian(u, tf.zeros_like(u), tf.zeros_like(u))
    naive = -0.5 * np.log(2 * np.pi) - np.log(1 - np.tanh(u.numpy()[:, 0]) ** 2)
    np.testing.assert_allclose(logp.numpy(), naive, rtol=1e-8)


def _batch(rng, n=32):
    return (rng.normal(size=(1, n, OBS)).astype(np.float32), rng.uniform(-1, 1, (1, n, ACT)).astype(np.float32),
            rng.normal(size=(1, n)).astype(np.float32), rng.normal(size=(1, n, OBS)).astype(np.float32),
            (rng.random((1, n)) < 0.3).astype(np.float32))


def test_one_update_matches_numpy_step_by_step():
    tf.keras.utils.set_random_seed(0)
    agent = SACAgent(OBS, ACT, CFG)
    perturb = np.random.default_rng(5)  # targets start as copies of the critics: make them differ,
    for target in agent.targets:        # so a target computed from the online critics would show
        target.set_weights([w + perturb.normal(scale=0.5, size=w.shape).astype(np.float32)
                            for w in target.get_weights()])
    obs, action, reward, next_obs, terminated = _batch(np.random.default_rng(1))
    actor_w = agent.actor.get_weights()
    target_ws = [t.get_weights() for t in agent.targets]
    log_alpha = float(agent.log_alpha.numpy())
    # the agent draws next-action noise, then current-action noise, from the RNG it is given
    noise_rng = np.random.default_rng(7)
    next_noise = noise_rng.standard_normal(action.shape)[0]
    noise = noise_rng.standard_normal(action.shape)[0]

    y = ref.sac_critic_target(actor_w, target_ws, math.exp(log_alpha), reward[0], next_obs[0], terminated[0],
                              next_noise, CFG.gamma, ACT)
    critic_ws = [c.get_weights() for c in agent.critics]
    want_critic = sum(np.mean((ref.q_value(w, obs[0], action[0]) - y) ** 2) for w in critic_ws)

    losses = agent.train_steps(obs, action, reward, next_obs, terminated, np.random.default_rng(7))
    assert losses["critic_loss"] == pytest.approx(want_critic, rel=1e-4)
    # the actor step sees the critics after their own step, as in TF-Agents
    updated_critics = [c.get_weights() for c in agent.critics]
    want_actor, want_alpha = ref.sac_actor_and_alpha_loss(actor_w, updated_critics, log_alpha, obs[0], noise,
                                                          -float(ACT), ACT)
    assert losses["actor_loss"] == pytest.approx(want_actor, rel=1e-4, abs=1e-5)
    assert losses["alpha_loss"] == pytest.approx(want_alpha, rel=1e-4, abs=1e-6)
    assert losses["alpha"] == pytest.approx(math.exp(log_alpha), rel=1e-6)
    # Adam's first step moves log_alpha by lr against the gradient's sign
    grad_sign = np.sign(-np.mean(ref.sac_policy(actor_w, obs[0], noise, ACT)[1] - ACT))
    assert float(agent.log_alpha.numpy()) == pytest.approx(log_alpha - CFG.alpha_lr * grad_sign, abs=1e-6)
    # targets moved tau of the way toward the updated critics
    for target, before, critic in zip(agent.targets, target_ws, updated_critics):
        for t, b, c in zip(target.get_weights(), before, critic):
            np.testing.assert_allclose(t, CFG.tau * c + (1 - CFG.tau) * b, rtol=1e-5, atol=1e-7)
    # and the numpy acting copy of the actor is the updated actor
    for w, v in zip(agent.policy.weights, agent.actor.get_weights()):
        np.testing.assert_array_equal(w, v)


class ScriptedNormal:
    """Stands in for the RNG: hands out prepared arrays for successive ``standard_normal`` calls."""

    def __init__(self, arrays):
        self.arrays = list(arrays)

    def standard_normal(self, shape):
        out = self.arrays.pop(0)
        assert out.shape == shape
        return out


def test_stacked_updates_equal_sequential_ones():
    tf.keras.utils.set_random_seed(0)
    one = SACAgent(OBS, ACT, CFG)
    two = SACAgent(OBS, ACT, dataclasses.replace(CFG, updates_per_call=2))
    for a, b in zip(one.models().values(), two.models().values()):
        b.set_weights(a.get_weights())
    batches = [_batch(np.random.default_rng(i)) for i in (1, 2)]
    rng = np.random.default_rng(3)
    next_noise, noise = ([rng.standard_normal((1, 32, ACT)) for _ in batches] for _ in range(2))
    for i, batch in enumerate(batches):  # each call draws its next-action noise, then its noise
        one.train_steps(*batch, ScriptedNormal([next_noise[i], noise[i]]))
    stacked = [np.concatenate([b[i] for b in batches]) for i in range(5)]
    two.train_steps(*stacked, ScriptedNormal([np.concatenate(next_noise), np.concatenate(noise)]))
    for a, b in zip(one.actor.get_weights(), two.actor.get_weights()):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)


def test_greedy_is_tanh_of_the_mean_and_sampling_stays_in_bounds():
    agent = SACAgent(OBS, ACT, CFG)
    obs = np.random.default_rng(0).normal(size=(5, OBS)).astype(np.float32)
    out = agent.actor(obs).numpy()
    np.testing.assert_allclose(agent.greedy_actions(obs), np.tanh(out[:, :ACT]), rtol=1e-5, atol=1e-6)
    sampled = agent.act(np.repeat(obs, 200, axis=0), np.random.default_rng(0))
    assert sampled.shape == (1000, ACT) and np.all(np.abs(sampled) <= 1.0)


def test_sampled_actions_are_tanh_of_the_gaussian_the_actor_gives():
    """Known mean and std (a zero kernel leaves the output layer's bias): the pre-tanh samples have
    that mean and std, per action dimension, and a seed gives exactly tanh(mean + std * normal)."""
    agent = SACAgent(OBS, ACT, CFG)
    weights = agent.actor.get_weights()
    weights[-2] = np.zeros_like(weights[-2])
    mean, log_std = np.array([0.5, -0.2, 0.0], np.float32), np.array([-1.0, 0.0, -2.0], np.float32)
    weights[-1] = np.concatenate([mean, log_std])
    agent.actor.set_weights(weights)
    agent.sync_policy_weights()
    obs = np.random.default_rng(0).normal(size=(20_000, OBS)).astype(np.float32)
    sampled = agent.act(obs, np.random.default_rng(5))
    pre_tanh = np.arctanh(np.clip(sampled.astype(np.float64), -1 + 1e-7, 1 - 1e-7))
    std = np.exp(log_std)
    np.testing.assert_allclose(pre_tanh.mean(axis=0), mean, atol=4 * std.max() / np.sqrt(len(obs)))
    np.testing.assert_allclose(pre_tanh.std(axis=0), std, rtol=0.03)
    want = np.tanh(mean + std * np.random.default_rng(5).standard_normal((len(obs), ACT)))
    np.testing.assert_allclose(sampled, want, rtol=1e-5, atol=1e-6)


def test_checkpoint_round_trip_restores_all_five_networks_and_three_adams(tmp_path):
    tf.keras.utils.set_random_seed(0)
    agent = SACAgent(OBS, ACT, CFG)
    agent.train_steps(*_batch(np.random.default_rng(1)), np.random.default_rng(2))
    save_checkpoint(tmp_path / "c.npz", agent.models(), agent.optimizers(),
                    {"log_alpha": float(agent.log_alpha.numpy())})
    other = SACAgent(OBS, ACT, CFG)
    state, _ = load_checkpoint(tmp_path / "c.npz", other.models(), other.optimizers())
    other.log_alpha.assign(state["log_alpha"])
    for name, model in agent.models().items():
        for a, b in zip(model.get_weights(), other.models()[name].get_weights()):
            np.testing.assert_array_equal(a, b)
    for name, opt in agent.optimizers().items():
        for a, b in zip(opt.variables, other.optimizers()[name].variables):
            np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    batch = _batch(np.random.default_rng(5))
    assert agent.train_steps(*batch, np.random.default_rng(6)) == other.train_steps(*batch, np.random.default_rng(6))


def test_nan_reward_is_caught():
    agent = SACAgent(OBS, ACT, CFG)
    batch = list(_batch(np.random.default_rng(0)))
    batch[2][:] = np.nan
    with pytest.raises(FloatingPointError, match="SAC critic_loss is NaN"):
        agent.train_steps(*batch, np.random.default_rng(0))


def test_log_std_is_clipped_to_its_bounds_when_acting_and_learning():
    agent = SACAgent(OBS, ACT, CFG)
    weights = agent.actor.get_weights()
    weights[-2] = np.zeros_like(weights[-2])  # the output is its bias: mean 0.3, log std 8, -25 and 0
    weights[-1] = np.array([0.3] * ACT + [8.0, -25.0, 0.0], np.float32)
    agent.actor.set_weights(weights)
    agent.sync_policy_weights()
    obs = np.random.default_rng(0).normal(size=(4, OBS)).astype(np.float32)
    bounds = [CFG.log_std_max, CFG.log_std_min, 0.0]
    np.testing.assert_allclose(agent.mean_and_log_std(obs)[1], np.tile(bounds, (4, 1)))  # acting (numpy)
    noise = np.random.default_rng(1).normal(size=(4, ACT)).astype(np.float32) * 0.3
    action, logp = agent._policy(tf.constant(obs), tf.constant(noise))  # learning (TF)
    want_a, want_logp = squashed_gaussian(tf.fill([4, ACT], 0.3), tf.constant(np.tile(bounds, (4, 1)), tf.float32),
                                          tf.constant(noise))
    np.testing.assert_allclose(action.numpy(), want_a.numpy(), rtol=1e-6)
    np.testing.assert_allclose(logp.numpy(), want_logp.numpy(), rtol=1e-5)
