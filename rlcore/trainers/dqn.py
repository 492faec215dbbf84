"""Episode loop for the Q-learning agents (DQN, Double, Dueling, Dueling Double)."""
from __future__ import annotations

import math
from pathlib import Path

import keras
import numpy as np

from rlcore.agents.dqn import DQNAgent
from rlcore.replay import ReplayMemory
from rlcore.trainers import checkpoints
from rlcore.trainers.divergence import reported_divergence
from rlcore.trainers.episodes import episode_means
from rlcore.trainers.session import TrainingSession
from rlcore.trainers.spec import RunSpec


def train(spec: RunSpec) -> Path:
    """Train until the stop score, episode or step budget; return the model folder."""
    cfg = spec.config
    keras.utils.set_random_seed(spec.seed)
    env = spec.experiment.make_env(max_episode_steps=cfg.max_episode_steps or None)
    obs_dim, n_actions = env.observation_space.shape[0], int(env.action_space.n)
    agent = DQNAgent(obs_dim, n_actions, cfg)
    memory = ReplayMemory(cfg.buffer_size, (obs_dim,))
    rng = np.random.default_rng(spec.seed)
    epsilon = cfg.eps_start

    state, arrays = checkpoints.restore(spec, agent, rng, memory)
    if state is not None:
        epsilon = state["epsilon"]
    session = TrainingSession(spec, state, resumed_arrays=arrays)
    grad_steps = int(state["grad_steps"]) if state else 0

    def checkpoint():
        checkpoints.save(session, agent, rng, memory, epsilon=epsilon, grad_steps=grad_steps)

    update_period = cfg.learn_every * cfg.updates_per_call
    # a resumed run reseeds from its episode count
    first_seed = session.fresh_env_seeds(1)[0]
    with session.interruptible():
        while not session.should_stop():
            obs, _ = env.reset(seed=first_seed)
            first_seed = None  # later episodes continue the env's own RNG
            episode_return, losses = 0.0, []
            while True:
                if cfg.eps_schedule == "steps":
                    epsilon = step_epsilon(cfg, session.env_steps)
                action = agent.act(obs, epsilon, rng)
                next_obs, reward, terminated, truncated, _ = env.step(action)
                memory.add(obs, action, reward, next_obs, terminated)
                session.env_steps += 1
                episode_return += reward
                obs = next_obs
                if session.env_steps % update_period == 0 and len(memory) >= max(cfg.batch_size,
                                                                                  cfg.learning_starts):
                    stacked = memory.sample_stacked(cfg.updates_per_call, cfg.batch_size, rng)
                    with reported_divergence(session, "DQN", "lower --lr"):
                        losses.append(agent.train_steps(*stacked))
                    grad_steps += cfg.updates_per_call
                session.maybe_evaluate(agent.greedy_actions, agent.q_network.get_weights)
                if terminated or truncated or session.stop_requested:
                    break
            if session.stop_requested:  # partial episode: not counted; its transitions stay in replay
                break
            if cfg.eps_schedule == "episode":
                epsilon = max(cfg.eps_end, epsilon * cfg.eps_decay)
            mean_losses = episode_means(losses, ("loss", "q_mean"))
            session.end_episode(episode_return, {"epsilon": epsilon, "grad_steps": grad_steps, **mean_losses})
            if session.book.episodes % cfg.checkpoint_every == 0:
                checkpoint()
    env.close()
    return session.conclude(checkpoint, lambda folder: [agent.save(folder)], agent.q_network.set_weights)


def step_epsilon(cfg, env_steps: int) -> float:
    """The PyTorch tutorial's schedule: end + (start - end) * exp(-steps / decay_steps)."""
    return cfg.eps_end + (cfg.eps_start - cfg.eps_end) * math.exp(-env_steps / cfg.eps_decay_steps)

