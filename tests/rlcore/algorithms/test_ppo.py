"""PPO: the loss and the targets against numpy, the compiled update against a plain eager loop."""
import dataclasses

import numpy as np
import pytest
import tensorflow as tf

from rlcore.algorithms.ppo.agent import PPOAgent, ppo_losses, rollout_targets
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.files.checkpoint import load_checkpoint, save_checkpoint
from tests import numpy_reference as ref

CFG = PPOConfig(num_envs=2, n_steps=8, epochs=3, minibatch=4, lr=1e-3, clip=0.2, entropy_coef=0.05,
                value_coef=0.7, gamma=0.9, gae_lambda=0.8)
OBS = (16, 16, 4)


def _batch(rng, n=32, actions=5):
    return (rng.normal(size=(n, actions)) * 2, rng.normal(size=n), rng.integers(0, actions, n),
            np.log(rng.uniform(0.05, 0.9, n)), rng.normal(size=n), rng.normal(size=n))


@pytest.mark.parametrize("quirks,value_loss", [(False, "mse"), (True, "mse"), (False, "huber")])
def test_loss_matches_numpy(quirks, value_loss):
    rng = np.random.default_rng(1)
    logits, values, actions, logp_old, adv, targets = _batch(rng)
    targets = targets * 2  # errors on both sides of the Huber loss's |e| = 1
    cfg = dataclasses.replace(CFG, article_quirks=quirks, value_loss=value_loss)
    got = ppo_losses(*(tf.constant(x, tf.float32) for x in (logits, values)), tf.constant(actions, tf.int32),
                     *(tf.constant(x, tf.float32) for x in (logp_old, adv, targets)), cfg)
    want = ref.ppo_loss(logits, values, actions, logp_old, adv, targets, cfg.clip, cfg.value_coef,
                        cfg.entropy_coef, quirks, value_loss)
    np.testing.assert_allclose([float(g) for g in got[:4]], want, rtol=1e-4, atol=1e-5)
    logp_new = tf.gather(tf.nn.log_softmax(logits), actions, batch_dims=1).numpy()
    assert float(got[4]) == pytest.approx(ref.approx_kl(logp_new, logp_old), rel=1e-4)
    # clip fraction: the share of samples whose ratio left [1 - clip, 1 + clip]
    p_old = np.exp(logp_old)
    ratio = np.exp(logp_new) / (p_old + 1e-3) if quirks else np.exp(logp_new - logp_old)
    share = np.mean(np.abs(ratio - 1.0) > cfg.clip)
    assert 0 < share < 1 and float(got[5]) == pytest.approx(share)  # both kinds in the batch


def test_ratio_is_clipped_only_where_it_helps():
    # advantage > 0 and ratio 2: the clipped term (1.2 A) wins; advantage < 0 and ratio 2: 2 A wins
    logits = tf.constant([[np.log(0.8), np.log(0.2)]] * 2, tf.float32)
    logp_old = tf.constant([np.log(0.4)] * 2, tf.float32)
    cfg = dataclasses.replace(CFG, value_coef=0.0, entropy_coef=0.0)
    zero = tf.zeros(2)
    pos = ppo_losses(logits, zero, tf.constant([0, 0]), logp_old, tf.constant([1.0, 1.0]), zero, cfg)[1]
    neg = ppo_losses(logits, zero, tf.constant([0, 0]), logp_old, tf.constant([-1.0, -1.0]), zero, cfg)[1]
    assert float(pos) == pytest.approx(-1.2, rel=1e-5)
    assert float(neg) == pytest.approx(2.0, rel=1e-5)


@pytest.mark.parametrize("target", ["gae", "td0"])
def test_rollout_targets_match_numpy(target):
    rng = np.random.default_rng(2)
    t, n = 12, 3
    rewards, values, next_values = (rng.normal(size=(t, n)) for _ in range(3))
    terminated = (rng.random((t, n)) < 0.2).astype(float)
    dones = np.maximum(terminated, (rng.random((t, n)) < 0.1))
    cfg = dataclasses.replace(CFG, value_target=target)
    adv, tgt = rollout_targets(*(tf.constant(x, tf.float32) for x in (rewards, values, next_values, terminated,
                                                                      dones)), cfg)
    want_adv = ref.gae(rewards, values, next_values, terminated, dones, cfg.gamma, cfg.gae_lambda)
    want_tgt = (want_adv + values if target == "gae"
                else ref.one_step_td(rewards, next_values, terminated, cfg.gamma))
    np.testing.assert_allclose(adv.numpy(), want_adv, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(tgt.numpy(), want_tgt, rtol=1e-5, atol=1e-5)


def _rollout(rng, cfg=CFG):
    t, n = cfg.n_steps, cfg.num_envs
    f = lambda: rng.normal(size=(t, n)).astype(np.float32)  # noqa: E731
    return (rng.integers(0, 256, (t, n, *OBS), dtype=np.uint8), rng.integers(0, 5, (t, n)).astype(np.int32),
            np.log(rng.uniform(0.1, 0.5, (t, n))).astype(np.float32), f(), f(), f(),
            (rng.random((t, n)) < 0.1).astype(np.float32), (rng.random((t, n)) < 0.15).astype(np.float32))


@pytest.mark.parametrize("target_kl,max_grad_norm", [(0.0, 0.0), (0.0005, 0.0), (0.0, 0.05)])
def test_compiled_update_equals_an_eager_minibatch_loop(target_kl, max_grad_norm):
    """The one-call update does exactly: targets once, then epochs x shuffled minibatches of Adam,
    stopping (with target_kl) before the first step whose minibatch KL passes 1.5 x target_kl, and
    (with max_grad_norm) scaling each minibatch's gradients down to that global norm."""
    cfg = dataclasses.replace(CFG, target_kl=target_kl, max_grad_norm=max_grad_norm)
    tf.keras.utils.set_random_seed(3)
    agent = PPOAgent(OBS, 5, cfg)
    twin = PPOAgent(OBS, 5, cfg)
    twin.model.set_weights(agent.model.get_weights())
    rollout = list(_rollout(np.random.default_rng(4)))
    probs, _ = agent.policy_and_values(rollout[0].reshape(-1, *OBS))  # logp of the acting policy
    rollout[2] = np.log(probs[np.arange(len(probs)), rollout[1].ravel()]).reshape(rollout[1].shape).astype(np.float32)
    report = agent.update(*rollout, np.random.default_rng(5))

    obs, actions, logp, values, next_values, rewards, terminated, dones = rollout
    adv, tgt = rollout_targets(*(tf.constant(x) for x in (rewards, values, next_values, terminated, dones)), cfg)
    size = cfg.n_steps * cfg.num_envs
    flat = [x.reshape(size, *x.shape[2:]) for x in (obs, actions, logp, adv.numpy(), tgt.numpy())]
    rng = np.random.default_rng(5)
    perms = [rng.permutation(size) for _ in range(cfg.epochs)]
    steps = [perm[k * cfg.minibatch:(k + 1) * cfg.minibatch] for perm in perms for k in range(size // cfg.minibatch)]
    taken, kls, norms = 0, [], []
    for idx in steps:
        o, a, lp, ad, tg = (x[idx] for x in flat)
        with tf.GradientTape() as tape:
            logits, v = twin.model(o, training=True)
            loss = ppo_losses(logits, v[:, 0], a, lp, ad, tg, cfg)[0]
        logp_new = tf.gather(tf.nn.log_softmax(logits), a, batch_dims=1).numpy()
        kls.append(ref.approx_kl(logp_new, lp))
        if target_kl and kls[-1] > 1.5 * target_kl:
            break
        grads = [g.numpy() for g in tape.gradient(loss, twin.model.trainable_variables)]
        if max_grad_norm:
            grads, norm = ref.clip_by_global_norm(grads, max_grad_norm)
            norms.append(norm)
        twin.opt.apply_gradients(zip(grads, twin.model.trainable_variables))
        taken += 1
    for got, want in zip(agent.model.get_weights(), twin.model.get_weights()):
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)
    assert int(agent.opt.iterations) == taken
    assert report["update_fraction"] == pytest.approx(taken / len(steps))
    assert report["approx_kl"] == pytest.approx(np.mean(kls), rel=1e-3)  # the stopping minibatch's KL counts
    if max_grad_norm:  # the clip acted on most steps, so it is what the comparison tests
        assert np.mean(np.array(norms) > max_grad_norm) > 0.5, norms
    if target_kl:  # the guard stopped this update part-way
        assert 0 < taken < len(steps)
    else:
        assert taken == len(steps)


def test_the_update_does_not_need_autograph(monkeypatch):
    """Where AutoGraph cannot convert a function it runs it as written, with a warning the quiet console
    hides: a Python loop over tf.range then fails ("Iterating over a symbolic tf.Tensor"), as it did once
    in a `make test` here. The update is a tf.while_loop, built with AutoGraph off: every conversion made
    to fail, it still trains."""
    from tensorflow.python.autograph.impl import api as autograph

    def cannot_convert(*args, **kwargs):
        raise RuntimeError("AutoGraph cannot convert this here")

    monkeypatch.setattr(autograph, "_convert_actual", cannot_convert)
    tf.keras.utils.set_random_seed(3)
    agent = PPOAgent(OBS, 5, CFG)
    before = [w.copy() for w in agent.model.get_weights()]
    report = agent.update(*_rollout(np.random.default_rng(4)), np.random.default_rng(5))
    assert report["update_fraction"] == 1.0 and int(agent.opt.iterations) > 0
    assert any(not np.array_equal(a, b) for a, b in zip(before, agent.model.get_weights()))


def test_update_raises_the_probability_of_advantaged_actions():
    tf.keras.utils.set_random_seed(0)
    cfg = dataclasses.replace(CFG, entropy_coef=0.0, value_coef=0.0, epochs=10, lr=3e-3)
    agent = PPOAgent(OBS, 5, cfg)
    rng = np.random.default_rng(0)
    obs, _, _, values, next_values, _, terminated, dones = _rollout(rng, cfg)
    actions = np.full((cfg.n_steps, cfg.num_envs), 2, np.int32)
    probs, v = agent.policy_and_values(obs.reshape(-1, *OBS))
    logp = np.log(probs[:, 2]).reshape(actions.shape).astype(np.float32)
    rewards = np.ones_like(values)  # every transition better than its (zero) value
    zeros = np.zeros_like(values)
    agent.update(obs, actions, logp, zeros, zeros, rewards, zeros, zeros, rng)
    after, _ = agent.policy_and_values(obs.reshape(-1, *OBS))
    assert after[:, 2].mean() > probs[:, 2].mean() + 0.05


def _skewed_agent(cfg):
    """A PPO agent whose policy head's bias makes pi about (0.05, 0.5, 0.1, 0.3, 0.05) everywhere."""
    agent = PPOAgent(OBS, 5, cfg)
    weights = agent.model.get_weights()
    head = next(i for i, w in enumerate(weights) if w.shape == (5,))  # the policy head's bias
    weights[head] = np.log(np.array([0.05, 0.5, 0.1, 0.3, 0.05], np.float32))
    agent.model.set_weights(weights)
    return agent


@pytest.mark.parametrize("weight", [0.1, -0.1])
def test_entropy_weight_sign_sets_where_the_entropy_goes(weight):
    # no advantage and no value loss: only the entropy term moves pi, up for a bonus, down for a penalty
    tf.keras.utils.set_random_seed(0)
    cfg = dataclasses.replace(CFG, entropy_coef=weight, value_coef=0.0, epochs=5, lr=3e-3)
    agent = _skewed_agent(cfg)  # a skewed start, so the entropy has room both ways
    rng = np.random.default_rng(0)
    obs, actions, logp, values, *_ = _rollout(rng, cfg)
    zeros = np.zeros_like(values)
    before, _ = agent.policy_and_values(obs.reshape(-1, *OBS))
    agent.update(obs, actions, logp, zeros, zeros, zeros, zeros, zeros, rng)
    after, _ = agent.policy_and_values(obs.reshape(-1, *OBS))
    entropy = lambda p: -(p * np.log(p)).sum(axis=1).mean()  # noqa: E731
    change = entropy(after) - entropy(before)
    assert change * np.sign(weight) > 0.01


def test_sampling_follows_pi_and_logp_is_its_log():
    tf.keras.utils.set_random_seed(0)
    agent = _skewed_agent(CFG)  # a skewed policy: a uniform or mis-ordered draw would show
    obs = np.random.default_rng(0).integers(0, 256, (1, *OBS), dtype=np.uint8)
    probs, _ = agent.policy_and_values(obs)
    assert probs[0].max() > 0.4
    batch = np.repeat(obs, 4000, axis=0)
    actions, logp, values = agent.act(batch, np.random.default_rng(1))
    freq = np.bincount(actions, minlength=5) / len(actions)
    np.testing.assert_allclose(freq, probs[0], atol=0.03)
    np.testing.assert_allclose(np.exp(logp), probs[0][actions], rtol=1e-5)


def test_checkpoint_round_trip_restores_weights_and_adam(tmp_path):
    tf.keras.utils.set_random_seed(0)
    agent = PPOAgent(OBS, 5, CFG)
    agent.update(*_rollout(np.random.default_rng(0)), np.random.default_rng(0))
    save_checkpoint(tmp_path / "c.npz", agent.models(), agent.optimizers(), {"rollouts": 1})
    other = PPOAgent(OBS, 5, CFG)
    state, _ = load_checkpoint(tmp_path / "c.npz", other.models(), other.optimizers())
    assert state["rollouts"] == 1
    for a, b in zip(agent.model.get_weights(), other.model.get_weights()):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(agent.opt.variables, other.opt.variables):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    # and both take the same next step
    rollout = _rollout(np.random.default_rng(9))
    agent.update(*rollout, np.random.default_rng(9))
    other.update(*rollout, np.random.default_rng(9))
    for a, b in zip(agent.model.get_weights(), other.model.get_weights()):
        np.testing.assert_allclose(a, b, rtol=1e-6)


def test_a_resume_keeps_the_configured_learning_rate(tmp_path):
    """``--resume --lr X``: Adam's moments and step come back, its rate is the new config's."""
    agent = PPOAgent(OBS, 5, CFG)
    agent.update(*_rollout(np.random.default_rng(0)), np.random.default_rng(0))
    save_checkpoint(tmp_path / "c.npz", agent.models(), agent.optimizers(), {})
    other = PPOAgent(OBS, 5, dataclasses.replace(CFG, lr=2.5e-4))
    load_checkpoint(tmp_path / "c.npz", other.models(), other.optimizers())
    assert float(other.opt.learning_rate) == pytest.approx(2.5e-4)
    assert int(other.opt.iterations) == int(agent.opt.iterations) > 0


def test_nan_in_the_loss_is_caught():
    agent = PPOAgent(OBS, 5, CFG)
    rollout = list(_rollout(np.random.default_rng(0)))
    rollout[5] = np.full_like(rollout[5], np.nan)  # rewards
    with pytest.raises(tf.errors.InvalidArgumentError, match="PPO loss"):
        agent.update(*rollout, np.random.default_rng(0))
