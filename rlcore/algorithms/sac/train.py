"""Training of SAC: random actions for ``learning_starts`` env steps, then the policy's samples, in
the shared off-policy episode loop (:mod:`rlcore.algorithms.off_policy`), one gradient step per env step.

Like TF-Agents' driver, a time-limit truncation still bootstraps (only ``terminated``, a fall,
stops it). The replay memory is saved beside each checkpoint (``replay.npz``), so a resumed run
continues where it stopped; without that file it continues with an empty memory that refills first.
"""
from __future__ import annotations

from pathlib import Path

import keras
import numpy as np

from rlcore.algorithms.off_policy import run_episodes
from rlcore.algorithms.replay import ReplayMemory
from rlcore.algorithms.sac.agent import SACAgent
from rlcore.training import checkpoints
from rlcore.training.episodes import episode_means
from rlcore.training.session import TrainingSession
from rlcore.training.spec import RunSpec


def train(spec: RunSpec) -> Path:
    cfg = spec.config
    keras.utils.set_random_seed(spec.seed)
    env = spec.experiment.make_env(max_episode_steps=cfg.max_episode_steps or None)
    obs_dim, act_dim = env.observation_space.shape[0], env.action_space.shape[0]
    agent = SACAgent(obs_dim, act_dim, cfg)
    memory = ReplayMemory(cfg.buffer_size, (obs_dim,), action_shape=(act_dim,), action_dtype=np.float32)
    rng = np.random.default_rng(spec.seed)
    state, arrays = checkpoints.restore(spec, agent, rng, memory)
    if state is not None:
        agent.log_alpha.assign(state["log_alpha"])
        agent.restore_obs_stats(state.get("obs_stats"))
    session = TrainingSession(spec, state, resumed_arrays=arrays)
    learner = SoftActorCritic(agent, cfg, rng, state, spec.experiment.info_keys)

    def checkpoint():
        checkpoints.save(session, agent, rng, memory, **learner.counters())

    run_episodes(session, env, memory, rng, learner, cfg, checkpoint, agent.greedy_actions, agent.get_weights)
    return session.conclude(checkpoint, agent.save, agent.set_weights)


class SoftActorCritic:
    """SAC's part of the episode loop: uniform random actions before ``learning_starts``, then
    samples of the policy; every observation goes to the running statistics (``obs_norm``)."""
    name, divergence_hint = "SAC", "lower the learning rates"

    def __init__(self, agent: SACAgent, cfg, rng: np.random.Generator, state: dict | None,
                 info_keys: tuple[str, ...]):
        self.agent, self.cfg, self.rng, self.info_keys = agent, cfg, rng, info_keys
        self.grad_steps = int(state["grad_steps"]) if state else 0
        self.update_period = cfg.updates_per_call  # one gradient step per env step

    def act(self, obs, env_steps):
        if env_steps < self.cfg.learning_starts:
            return self.rng.uniform(-1.0, 1.0, self.agent.act_dim).astype(np.float32)
        return self.agent.act(obs[None], self.rng)[0]

    def observe(self, obs):
        self.agent.observe(obs)

    def learn(self, batches):
        report = self.agent.train_steps(*batches, self.rng)
        self.grad_steps += self.cfg.updates_per_call
        return report

    def episode_row(self, losses, episode_steps, info):
        # episode_steps: how long it stood (Minitaur: a fall ends it before the time limit)
        ends = {key: float(info.get(key, float("nan"))) for key in self.info_keys}
        return {"episode_steps": episode_steps, **ends, "grad_steps": self.grad_steps,
                **episode_means(losses, ("critic_loss", "actor_loss", "alpha", "entropy", "q_mean"))}

    def counters(self):
        return {"grad_steps": self.grad_steps, "log_alpha": float(self.agent.log_alpha.numpy()),
                "obs_stats": self.agent.obs_stats_state()}
