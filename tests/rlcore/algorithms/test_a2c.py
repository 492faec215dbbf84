"""A2C: targets (one-step TD, n-step, GAE), actor and critic losses against numpy references."""
import numpy as np
import pytest
import tensorflow as tf

from rlcore.algorithms.a2c.agent import A2CAgent, Actor, Critic
from rlcore.algorithms.a2c.config import A2CConfig
from rlcore.algorithms.advantages import gae
from tests import numpy_reference as ref

T, N, OBS, ACTIONS = 5, 3, 8, 4


def rollout(seed=0):
    rng = np.random.default_rng(seed)
    dones = rng.random((T, N)) < 0.25
    terminated = dones & (rng.random((T, N)) < 0.6)  # some episode ends are truncations
    return (rng.normal(size=(T, N)), rng.normal(size=(T, N)), rng.normal(size=(T, N)),
            terminated.astype(np.float32), dones.astype(np.float32))


@pytest.mark.parametrize("lam", [0.0, 0.5, 0.95, 1.0])
def test_gae_matches_numpy(lam):
    rewards, values, next_values, terminated, dones = rollout()
    got = gae(*(tf.constant(x, tf.float32) for x in (rewards, values, next_values, terminated, dones)),
              gamma=0.99, lam=lam).numpy()
    want = ref.gae(rewards, values, next_values, terminated, dones, 0.99, lam)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-5)


def test_lambda_zero_is_the_articles_one_step_td_target():
    rewards, values, next_values, terminated, dones = rollout(1)
    adv = gae(*(tf.constant(x, tf.float32) for x in (rewards, values, next_values, terminated, dones)),
              gamma=0.995, lam=0.0).numpy()
    td_target = ref.one_step_td(rewards, next_values, terminated.astype(bool), 0.995)
    np.testing.assert_allclose(adv + values, td_target, rtol=1e-4, atol=1e-5)  # advantage = td - V(s)


def test_lambda_one_is_the_n_step_return_with_masks():
    """Within a rollout V(s'_t) = V(s_{t+1}); with only terminations, GAE(1) + V = n-step returns."""
    rng = np.random.default_rng(2)
    rewards = rng.normal(size=(T, N))
    v_all = rng.normal(size=(T + 1, N))  # V(s_0..s_T)
    dones = (rng.random((T, N)) < 0.3).astype(np.float32)
    adv = gae(*(tf.constant(x, tf.float32) for x in (rewards, v_all[:-1], v_all[1:], dones, dones)),
              gamma=0.9, lam=1.0).numpy()
    want = ref.n_step_returns(rewards, v_all[-1], dones, 0.9)
    np.testing.assert_allclose(adv + v_all[:-1], want, rtol=1e-4, atol=1e-5)


def test_actor_loss_uses_probabilities_not_logits():
    """The article passed softmax outputs with from_logits=True; ours must equal -log p(a) * A."""
    rng = np.random.default_rng(3)
    logits = rng.normal(size=(6, ACTIONS))
    probs = np.exp(logits) / np.exp(logits).sum(1, keepdims=True)
    actions = rng.integers(0, ACTIONS, 6)
    advantages = rng.normal(size=6)
    loss, policy_loss, entropy = Actor.compute_loss(tf.constant(actions, tf.int32),
                                                    tf.constant(probs, tf.float32),
                                                    tf.constant(advantages, tf.float32), 0.01)
    want_loss, want_entropy = ref.actor_loss(probs, actions, advantages, 0.01)
    assert float(loss) == pytest.approx(want_loss, rel=1e-4)
    assert float(entropy) == pytest.approx(want_entropy, rel=1e-4)


def test_critic_loss_is_mse():
    v_pred = tf.constant([1.0, 2.0, 3.0])
    td = tf.constant([1.5, 2.0, 1.0])
    assert float(Critic.compute_loss(v_pred, td)) == pytest.approx((0.25 + 0 + 4) / 3)


def test_numpy_actor_matches_keras():
    agent = A2CAgent(OBS, ACTIONS, A2CConfig(actor_hidden=(32, 16)))
    obs = np.random.default_rng(4).normal(size=(7, OBS)).astype(np.float32)
    np.testing.assert_allclose(agent.probs(obs), agent.actor.model(obs).numpy(), rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(agent.probs(obs), ref.actor_probs(agent.actor.model.get_weights(), obs),
                               rtol=1e-4, atol=1e-6)


def test_sampling_follows_the_policy():
    agent = A2CAgent(OBS, ACTIONS, A2CConfig(actor_hidden=(8,)))
    weights = agent.actor.model.get_weights()  # a skewed policy: a uniform or mis-ordered draw would show
    weights[-1] = np.log(np.array([0.55, 0.3, 0.1, 0.05][:ACTIONS], np.float32))
    agent.actor.model.set_weights(weights)
    agent.sync_policy_weights()
    obs = np.zeros((20000, OBS), np.float32)
    probs = agent.probs(obs[:1])[0]
    assert probs.max() > 0.5
    counts = np.bincount(agent.act(obs, np.random.default_rng(0)), minlength=ACTIONS) / len(obs)
    np.testing.assert_allclose(counts, probs, atol=0.015)


def test_update_moves_the_taken_action_towards_positive_advantage():
    cfg = A2CConfig(n_steps=T, num_envs=N, actor_hidden=(16,), critic_hidden=(16,), actor_lr=1e-2,
                    reward_scale=1.0, gamma=0.0)
    agent = A2CAgent(OBS, ACTIONS, cfg)
    obs = np.ones((T, N, OBS), np.float32)
    actions = np.full((T, N), 2, np.int32)
    rewards = np.full((T, N), 10.0, np.float32)  # gamma 0: advantage = 10 - V(s) > 0
    zeros = np.zeros((T, N), np.float32)
    before = agent.probs(obs[0, :1])[0, 2]
    for _ in range(5):
        losses = agent.update(obs, actions, rewards, obs, zeros, zeros)
    assert agent.probs(obs[0, :1])[0, 2] > before + 0.05
    assert set(losses) == {"actor_loss", "critic_loss", "entropy"}
    assert agent._update.experimental_get_tracing_count() == 1


@pytest.mark.parametrize("normalize", [False, True])
def test_update_losses_match_numpy_on_a_rollout_with_truncations(normalize):
    """The whole wiring of one update: rewards scaled, GAE with bootstraps on truncation only
    (terminated and dones not swapped), td targets before the advantage is standardized."""
    cfg = A2CConfig(n_steps=T, num_envs=N, actor_hidden=(16,), critic_hidden=(16,), reward_scale=0.1,
                    gamma=0.9, gae_lambda=0.7, entropy_coef=0.05, normalize_advantage=normalize)
    tf.keras.utils.set_random_seed(0)
    agent = A2CAgent(OBS, ACTIONS, cfg)
    rng = np.random.default_rng(6)
    obs, next_obs = (rng.normal(size=(T, N, OBS)).astype(np.float32) for _ in range(2))
    actions = rng.integers(0, ACTIONS, (T, N)).astype(np.int32)
    rewards = rng.normal(scale=20.0, size=(T, N)).astype(np.float32)
    _, _, _, terminated, dones = rollout(seed=2)
    assert (dones > terminated).any() and terminated.any()
    actor_w, critic_w = agent.actor.model.get_weights(), agent.critic.model.get_weights()

    values = ref.mlp(critic_w, obs.reshape(-1, OBS))[:, 0].reshape(T, N)
    next_values = ref.mlp(critic_w, next_obs.reshape(-1, OBS))[:, 0].reshape(T, N)
    adv = ref.gae(rewards * 0.1, values, next_values, terminated, dones, 0.9, 0.7)
    td_targets = adv + values
    want_critic = np.mean((td_targets - values) ** 2)
    adv = adv.ravel()
    if normalize:
        adv = (adv - adv.mean()) / (adv.std() + 1e-8)
    probs = ref.actor_probs(actor_w, obs.reshape(-1, OBS))
    total, want_entropy = ref.actor_loss(probs, actions.ravel(), adv, 0.05)

    got = agent.update(obs, actions, rewards, next_obs, terminated, dones)
    assert got["critic_loss"] == pytest.approx(want_critic, rel=1e-4)
    assert got["entropy"] == pytest.approx(want_entropy, rel=1e-5)
    assert got["actor_loss"] == pytest.approx(total + 0.05 * want_entropy, rel=1e-4, abs=1e-5)


def test_two_clipped_updates_equal_an_eager_loop_with_a_numpy_clip():
    """max_grad_norm scales each network's gradients to that global norm before Adam. Two updates,
    since Adam's first step hardly depends on the gradient's scale."""
    cfg = A2CConfig(n_steps=T, num_envs=N, actor_hidden=(16,), critic_hidden=(16,), reward_scale=1.0,
                    gamma=0.9, gae_lambda=0.5, entropy_coef=0.01, max_grad_norm=0.05, actor_lr=1e-2,
                    critic_lr=1e-2)
    tf.keras.utils.set_random_seed(0)
    agent, twin = A2CAgent(OBS, ACTIONS, cfg), A2CAgent(OBS, ACTIONS, cfg)
    twin.set_weights(agent.get_weights())
    rng = np.random.default_rng(8)
    norms = []
    for _ in range(2):
        obs, next_obs = (rng.normal(size=(T, N, OBS)).astype(np.float32) for _ in range(2))
        actions = rng.integers(0, ACTIONS, (T, N)).astype(np.int32)
        rewards = rng.normal(scale=5.0, size=(T, N)).astype(np.float32)
        _, _, _, terminated, dones = rollout(seed=3)
        agent.update(obs, actions, rewards, next_obs, terminated, dones)

        flat = obs.reshape(-1, OBS)
        values = twin.critic.model(flat).numpy()[:, 0].reshape(T, N)
        next_values = twin.critic.model(next_obs.reshape(-1, OBS)).numpy()[:, 0].reshape(T, N)
        adv = ref.gae(rewards, values, next_values, terminated, dones, 0.9, 0.5)
        targets = tf.constant((adv + values).ravel(), tf.float32)
        with tf.GradientTape() as tape:
            probs = twin.actor.model(flat, training=True)
            loss = Actor.compute_loss(actions.ravel(), probs, tf.constant(adv.ravel(), tf.float32), 0.01)[0]
        grads, norm = ref.clip_by_global_norm([g.numpy() for g in tape.gradient(loss, twin.actor.model.trainable_variables)],
                               0.05)
        twin.actor.opt.apply_gradients(zip(grads, twin.actor.model.trainable_variables))
        norms.append(norm)
        with tf.GradientTape() as tape:
            loss = Critic.compute_loss(twin.critic.model(flat, training=True)[:, 0], targets)
        grads, norm = ref.clip_by_global_norm([g.numpy() for g in tape.gradient(loss, twin.critic.model.trainable_variables)],
                               0.05)
        twin.critic.opt.apply_gradients(zip(grads, twin.critic.model.trainable_variables))
        norms.append(norm)
    assert min(norms) > 0.05 * 2  # the clip acted on every step
    for got, want in zip(agent.get_weights(), twin.get_weights()):
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)
