"""A toy algorithm family, written as docs/developer/adding-an-algorithm.md says a contributor would:
REINFORCE with a mean-return baseline (Williams 1992), one env, one update per episode.

Everything the package asks of a family is in :data:`FAMILY`; the test registers it
(:func:`rlcore.algorithms.registry.register`) and drives it through the ordinary commands.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rlcore.algorithms.family import Family, discrete_on_vectors
from rlcore.hyperparams.allowed import COUNT, POSITIVE, UNIT
from rlcore.hyperparams.base import EpisodeLoop, _h

KIND = "toy_reinforce"
MODEL_FILE = "policy.h5"


@dataclass(frozen=True)
class ReinforceConfig(EpisodeLoop):
    """REINFORCE: the policy gradient of whole-episode returns, minus their mean as a baseline."""
    hidden: tuple[int, ...] = _h((16,), "hidden layer sizes of the policy", COUNT, defines_run=True)
    lr: float = _h(1e-2, "Adam learning rate", POSITIVE)
    gamma: float = _h(0.99, "discount factor", UNIT)


def discounted_returns(rewards: np.ndarray, gamma: float) -> np.ndarray:
    """G_t = r_t + gamma G_{t+1}, the reference the agent's update is checked against."""
    out, running = np.zeros(len(rewards), np.float32), 0.0
    for t in range(len(rewards) - 1, -1, -1):
        running = rewards[t] + gamma * running
        out[t] = running
    return out


class ReinforceAgent:
    def __init__(self, obs_dim: int, n_actions: int, cfg: ReinforceConfig):
        import keras
        import tensorflow as tf

        self.cfg = cfg
        self.model = keras.Sequential([keras.Input((obs_dim,), name="obs")]
                                      + [keras.layers.Dense(u, activation="tanh") for u in cfg.hidden]
                                      + [keras.layers.Dense(n_actions, activation="softmax", name="pi")],
                                      name="policy")
        self.opt = keras.optimizers.Adam(cfg.lr)
        self.opt.build(self.model.trainable_variables)
        self._probs = tf.function(lambda obs: self.model(obs),
                                  input_signature=[tf.TensorSpec([None, obs_dim], tf.float32)])
        self._step = tf.function(self._update_graph)

    def _update_graph(self, states, actions, advantages):
        import tensorflow as tf

        with tf.GradientTape() as tape:
            probs = self.model(states, training=True)
            logp = tf.math.log(tf.maximum(tf.gather(probs, actions, batch_dims=1), 1e-8))
            loss = -tf.reduce_mean(logp * advantages)
        grads = tape.gradient(loss, self.model.trainable_variables)
        self.opt.apply_gradients(zip(grads, self.model.trainable_variables))
        return loss

    def act(self, obs: np.ndarray, rng: np.random.Generator) -> int:
        probs = self._probs(np.asarray(obs, np.float32)[None]).numpy()[0]
        return int(rng.choice(len(probs), p=probs / probs.sum()))

    def greedy_actions(self, obs: np.ndarray) -> np.ndarray:
        return self._probs(np.asarray(obs, np.float32)).numpy().argmax(axis=1)

    def update(self, states, actions, rewards) -> dict:
        returns = discounted_returns(np.asarray(rewards, np.float32), self.cfg.gamma)
        loss = self._step(np.asarray(states, np.float32), np.asarray(actions, np.int32), returns - returns.mean())
        return {"loss": float(loss)}

    # what the shared plumbing calls (rlcore.algorithms.protocol.Agent)
    def models(self) -> dict:
        return {"policy": self.model}

    def optimizers(self) -> dict:
        return {"adam": self.opt}

    def sync_policy_weights(self) -> None:
        """Nothing to refresh: the agent acts through its compiled model."""

    def save(self, folder) -> list[Path]:
        from rlcore.networks.saving import save_keras_model

        return [save_keras_model(self.model, Path(folder) / MODEL_FILE)]

    def get_weights(self):
        return self.model.get_weights()

    def set_weights(self, weights) -> None:
        self.model.set_weights(weights)


def train(spec) -> Path:
    """One episode, one update, until the session says stop; a checkpoint every ``checkpoint_every``."""
    import keras

    from rlcore.training import checkpoints
    from rlcore.training.session import TrainingSession

    cfg = spec.config
    keras.utils.set_random_seed(spec.seed)
    env = spec.experiment.make_env(max_episode_steps=cfg.max_episode_steps or None)
    agent = build_agent(env.observation_space, env.action_space, cfg)
    rng = np.random.default_rng(spec.seed)
    state, _ = checkpoints.restore(spec, agent, rng)
    session = TrainingSession(spec, state)

    def checkpoint():
        checkpoints.save(session, agent, rng)

    seed = session.fresh_env_seeds(1)[0]
    with session.interruptible():
        while not session.should_stop():
            obs, _ = env.reset(seed=seed)
            seed = None
            states, actions, rewards, done = [], [], [], False
            while not done and not session.stop_requested:
                action = agent.act(obs, rng)
                states.append(obs)
                actions.append(action)
                obs, reward, terminated, truncated, _ = env.step(action)
                rewards.append(reward)
                session.env_steps += 1
                done = terminated or truncated
            if not done:  # stopped mid-episode: not counted
                break
            losses = agent.update(states, actions, rewards)
            session.end_episode(float(np.sum(rewards)), losses)
            session.maybe_evaluate(agent.greedy_actions, agent.get_weights)
            if session.book.episodes % cfg.checkpoint_every == 0:
                checkpoint()
    env.close()
    return session.conclude(checkpoint, agent.save, agent.set_weights)


def build_agent(observation_space, action_space, cfg) -> ReinforceAgent:
    return ReinforceAgent(observation_space.shape[0], int(action_space.n), cfg)


def load_policy(path, obs_shape, action_space, cfg):
    from rlcore.networks.acting import Policy

    return Policy(path, obs_shape, int(action_space.n), stochastic=True)


FAMILY = Family(
    kind=KIND, description="REINFORCE with a mean-return baseline (a test's toy family)",
    config=ReinforceConfig, train=train, build_agent=build_agent, policy_file=MODEL_FILE, load_policy=load_policy,
    export_output="action probabilities pi(a|s) (greedy action = argmax)", misfit=discrete_on_vectors,
    variants={"reinforce": ("REINFORCE with a baseline", {})}, stochastic=True)
