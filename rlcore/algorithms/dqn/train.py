"""Training of the Q-learning agents (DQN, Double, Dueling, Dueling Double): epsilon-greedy acting in
the shared off-policy episode loop (:mod:`rlcore.algorithms.off_policy`)."""
from __future__ import annotations

import math
from pathlib import Path

import keras
import numpy as np

from rlcore.algorithms.dqn.agent import DQNAgent
from rlcore.algorithms.off_policy import run_episodes
from rlcore.algorithms.replay import replay_memory
from rlcore.training import checkpoints
from rlcore.training.episodes import episode_means
from rlcore.training.session import TrainingSession
from rlcore.training.spec import RunSpec


def train(spec: RunSpec) -> Path:
    """Train until the stop score, episode or step budget; return the model folder."""
    cfg = spec.config
    keras.utils.set_random_seed(spec.seed)
    env = spec.experiment.make_env(max_episode_steps=cfg.max_episode_steps or None)
    agent = DQNAgent(env.observation_space.shape, int(env.action_space.n), cfg)
    memory = replay_memory(cfg.buffer_size, env)
    rng = np.random.default_rng(spec.seed)
    state, arrays = checkpoints.restore(spec, agent, rng, memory)
    session = TrainingSession(spec, state, resumed_arrays=arrays)
    learner = EpsilonGreedy(agent, cfg, rng, state)

    def checkpoint():
        checkpoints.save(session, agent, rng, memory, **learner.counters())

    run_episodes(session, env, memory, rng, learner, cfg, checkpoint, agent.greedy_actions,
                 agent.q_network.get_weights)
    return session.conclude(checkpoint, lambda folder: [agent.save(folder)], agent.q_network.set_weights)


class EpsilonGreedy:
    """The DQN family's part of the episode loop: epsilon-greedy actions, with epsilon decayed per
    episode (article 000) or by env steps (the PyTorch tutorial, article 003)."""
    name, divergence_hint = "DQN", "lower the learning rate"

    def __init__(self, agent: DQNAgent, cfg, rng: np.random.Generator, state: dict | None):
        self.agent, self.cfg, self.rng = agent, cfg, rng
        self.epsilon = state["epsilon"] if state else cfg.eps_start
        self.grad_steps = int(state["grad_steps"]) if state else 0
        self.update_period = cfg.learn_every * cfg.updates_per_call

    def act(self, obs, env_steps):
        if self.cfg.eps_schedule == "steps":
            self.epsilon = step_epsilon(self.cfg, env_steps)
        return self.agent.act(obs, self.epsilon, self.rng)

    def observe(self, obs):
        pass

    def learn(self, batches):
        report = self.agent.train_steps(*batches)
        self.grad_steps += self.cfg.updates_per_call
        return report

    def episode_row(self, losses, episode_steps, info):
        if self.cfg.eps_schedule == "episode":
            self.epsilon = max(self.cfg.eps_end, self.epsilon * self.cfg.eps_decay)
        return {"epsilon": self.epsilon, "grad_steps": self.grad_steps, **episode_means(losses, ("loss", "q_mean"))}

    def counters(self):
        return {"epsilon": self.epsilon, "grad_steps": self.grad_steps}


def step_epsilon(cfg, env_steps: int) -> float:
    """The PyTorch tutorial's schedule: end + (start - end) * exp(-steps / decay_steps)."""
    return cfg.eps_end + (cfg.eps_start - cfg.eps_end) * math.exp(-env_steps / cfg.eps_decay_steps)
