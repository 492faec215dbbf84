"""The algorithms' math written out in plain numpy, loop by loop, as the tests' ground truth."""
import numpy as np


def dqn_td_target(reward, terminated, q_next_target, q_next_online, gamma, double):
    """r + gamma * Q_target(s', a*) (no bootstrap if terminated); a* from online net if double."""
    out = np.zeros(len(reward))
    for i in range(len(reward)):
        chooser = q_next_online[i] if double else q_next_target[i]
        best = int(np.argmax(chooser))
        out[i] = reward[i] + (0.0 if terminated[i] else gamma * q_next_target[i][best])
    return out


def dueling_combine(value, advantage):
    """Q(s,a) = V(s) + A(s,a) - mean over a of A(s,a), row by row."""
    q = np.zeros_like(advantage)
    for i in range(advantage.shape[0]):
        q[i] = value[i, 0] + advantage[i] - advantage[i].mean()
    return q


def gae(rewards, values, next_values, terminated, dones, gamma, lam):
    """Generalized advantage estimation over a [T, N] rollout, one env and one step at a time."""
    t_len, n = rewards.shape
    adv = np.zeros((t_len, n))
    for env in range(n):
        running = 0.0
        for t in reversed(range(t_len)):
            bootstrap = 0.0 if terminated[t, env] else gamma * next_values[t, env]
            delta = rewards[t, env] + bootstrap - values[t, env]
            if dones[t, env]:
                running = 0.0
            running = delta + gamma * lam * running
            adv[t, env] = running
    return adv


def one_step_td(rewards, next_values, terminated, gamma):
    """The article's td_target: r if the episode terminated, else r + gamma V(s')."""
    return np.where(terminated, rewards, rewards + gamma * next_values)


def n_step_returns(rewards, bootstrap_value, dones, gamma):
    """R_t = r_t + gamma R_{t+1}, reset at episode ends, seeded with V(s_T): article 002's returns."""
    t_len, n = rewards.shape
    returns = np.zeros((t_len, n))
    running = np.array(bootstrap_value, dtype=float)
    for t in reversed(range(t_len)):
        running = rewards[t] + gamma * running * (1.0 - dones[t])
        returns[t] = running
    return returns


def actor_loss(probs, actions, advantages, entropy_coef):
    """mean(-log pi(a|s) * A) - c * mean entropy."""
    n = len(actions)
    ce = np.array([-np.log(probs[i, actions[i]]) for i in range(n)])
    entropy = np.array([-(probs[i] * np.log(probs[i])).sum() for i in range(n)])
    return (ce * advantages).mean() - entropy_coef * entropy.mean(), entropy.mean()


def ppo_loss(logits, values, actions, logp_old, advantages, targets, clip, value_coef, entropy_coef,
             quirks=False, value_loss="mse"):
    """PPO's clipped surrogate + value loss - entropy bonus, sample by sample.

    quirks: the article's ratio p / (p_old + 1e-3) and -log(p(a) + 1e-3) in place of the entropy.
    value_loss: "mse", the squared error; "huber", 0.5 e^2 where |e| < 1, else |e| - 0.5 (PyTorch's
    smooth_l1_loss, as uvipen's PyTorch Mario).
    """
    n = len(actions)
    surrogate, value_sq, entropy = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n):
        z = logits[i] - logits[i].max()
        p = np.exp(z) / np.exp(z).sum()
        p_a, p_old = p[actions[i]], np.exp(logp_old[i])
        ratio = p_a / (p_old + 1e-3) if quirks else np.exp(np.log(p_a) - logp_old[i])
        clipped = min(max(ratio, 1 - clip), 1 + clip)
        surrogate[i] = min(ratio * advantages[i], clipped * advantages[i])
        err = values[i] - targets[i]
        if value_loss == "huber":
            value_sq[i] = 0.5 * err ** 2 if abs(err) < 1 else abs(err) - 0.5
        else:
            value_sq[i] = err ** 2
        entropy[i] = -np.log(p_a + 1e-3) if quirks else -(p * np.log(p)).sum()
    policy = -surrogate.mean()
    return policy + value_coef * value_sq.mean() - entropy_coef * entropy.mean(), policy, value_sq.mean(), entropy.mean()


def clip_by_global_norm(grads, max_norm):
    """Gradients scaled down to global norm ``max_norm`` when above it; returns (grads, the norm)."""
    norm = np.sqrt(sum(float(np.sum(np.asarray(g, np.float64) ** 2)) for g in grads))
    return [g * (max_norm / norm) if norm > max_norm else g for g in grads], norm


def approx_kl(logp_new, logp_old):
    """KL(pi_old || pi) estimated from the taken actions: mean of (r - 1) - log r, r = pi / pi_old."""
    log_ratio = np.asarray(logp_new, np.float64) - np.asarray(logp_old, np.float64)
    return float(np.mean(np.exp(log_ratio) - 1.0 - log_ratio))


def mlp(weights, x, final_relu=False):
    """Dense layers from (kernel, bias) pairs: ReLU between them, linear at the end."""
    for i in range(0, len(weights), 2):
        x = x @ weights[i] + weights[i + 1]
        if i + 2 < len(weights) or final_relu:
            x = np.maximum(x, 0.0)
    return x


def q_values(weights, obs, dueling):
    """The Q-network: ReLU hidden layers, then one head (Q) or two (V, A) combined row by row."""
    if not dueling:
        return mlp(weights, obs)
    x = mlp(weights[:-4], obs, final_relu=True)
    return dueling_combine(x @ weights[-4] + weights[-3], x @ weights[-2] + weights[-1])


def actor_probs(weights, obs):
    """The A2C actor: ReLU hidden layers, softmax over the output row by row."""
    logits = mlp(weights, obs)
    out = np.zeros_like(logits)
    for i, row in enumerate(logits):
        e = np.exp(row - row.max())
        out[i] = e / e.sum()
    return out


def squashed_gaussian(mean, log_std, noise):
    """a = tanh(u), u = mean + std * noise; log pi(a) = log N(u) - sum log(1 - tanh(u)^2), naively."""
    std = np.exp(log_std)
    u = mean + std * noise
    log_normal = -0.5 * ((u - mean) / std) ** 2 - np.log(std) - 0.5 * np.log(2 * np.pi)
    return np.tanh(u), (log_normal - np.log(1.0 - np.tanh(u) ** 2)).sum(axis=1)


def sac_policy(actor_w, obs, noise, act_dim, log_std_min=-20.0, log_std_max=2.0):
    out = mlp(actor_w, obs)
    return squashed_gaussian(out[:, :act_dim], np.clip(out[:, act_dim:], log_std_min, log_std_max), noise)


def q_value(critic_w, obs, action):
    return mlp(critic_w, np.concatenate([obs, action], axis=1))[:, 0]


def sac_critic_target(actor_w, target_ws, alpha, reward, next_obs, terminated, next_noise, gamma, act_dim):
    next_action, next_logp = sac_policy(actor_w, next_obs, next_noise, act_dim)
    next_q = np.minimum(*(q_value(w, next_obs, next_action) for w in target_ws))
    return reward + gamma * (1.0 - terminated) * (next_q - alpha * next_logp)


def sac_actor_and_alpha_loss(actor_w, critic_ws, log_alpha, obs, noise, target_entropy, act_dim):
    action, logp = sac_policy(actor_w, obs, noise, act_dim)
    q = np.minimum(*(q_value(w, obs, action) for w in critic_ws))
    actor = np.mean(np.exp(log_alpha) * logp - q)
    alpha = -np.mean(log_alpha * (logp + target_entropy))
    return actor, alpha


def standardize(obs, mean, var, clip, eps=1e-8):
    """(obs - mean) / sqrt(var + eps), each element clipped to [-clip, clip]."""
    out = np.zeros_like(obs, dtype=np.float64)
    for i in range(obs.shape[0]):
        for j in range(obs.shape[1]):
            z = (obs[i, j] - mean[j]) / np.sqrt(var[j] + eps)
            out[i, j] = min(max(z, -clip), clip)
    return out
