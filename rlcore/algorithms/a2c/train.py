"""Rollout loop for A2C over the env pool (``num_envs`` envs, in-process or one process each).

Each step's next observation is kept (a truncated episode's final one in its place,
:func:`rlcore.environments.vector.bootstrap_observations`) and the update values them all: vector observations are
small. PPO keeps values instead of observations, for Mario's frames (:class:`rlcore.algorithms.ppo.train.Rollout`).
"""
from __future__ import annotations

from functools import partial
from pathlib import Path

import keras
import numpy as np

from rlcore.algorithms.a2c.agent import A2CAgent
from rlcore.environments.vector import EnvPool, bootstrap_observations
from rlcore.networks.bodies import obs_dtype
from rlcore.training import checkpoints
from rlcore.training.divergence import reported_divergence
from rlcore.training.session import TrainingSession
from rlcore.training.spec import RunSpec


def train(spec: RunSpec) -> Path:
    cfg = spec.config
    keras.utils.set_random_seed(spec.seed)
    make_env = partial(spec.experiment.make_env, max_episode_steps=cfg.max_episode_steps or None)
    envs = EnvPool([make_env] * cfg.num_envs, mode=cfg.vec)
    with envs.closed_on_error():  # a start that fails (a damaged checkpoint, say) ends them quietly
        obs_shape, n_actions = envs.single_observation_space.shape, int(envs.single_action_space.n)
        agent = A2CAgent(obs_shape, n_actions, cfg)
        rng = np.random.default_rng(spec.seed)

        state, arrays = checkpoints.restore(spec, agent, rng)
        session = TrainingSession(spec, state, resumed_arrays=arrays)

        def checkpoint():
            checkpoints.save(session, agent, rng)

        t, n = cfg.n_steps, cfg.num_envs
        buf_obs = np.zeros((t, n, *obs_shape), obs_dtype(obs_shape))  # frames stay uint8
        buf_next = np.zeros_like(buf_obs)
        buf_actions = np.zeros((t, n), np.int32)
        buf_rewards, buf_term, buf_done = (np.zeros((t, n), np.float32) for _ in range(3))
        running = np.zeros(n)
        losses = {"actor_loss": float("nan"), "critic_loss": float("nan"), "entropy": float("nan")}
        # a resumed run starts fresh episodes, reseeded from its episode count
        obs, _ = envs.reset(seed=session.fresh_env_seeds(n))
        next_checkpoint = (session.book.episodes // cfg.checkpoint_every + 1) * cfg.checkpoint_every
    with envs, session.interruptible():
        while not session.should_stop():
            for step in range(t):
                actions = agent.act(obs, rng)
                next_obs, rewards, terminated, truncated, infos = envs.step(actions)
                done = terminated | truncated
                buf_obs[step], buf_actions[step], buf_rewards[step] = obs, actions, rewards
                buf_next[step] = bootstrap_observations(next_obs, infos)
                buf_term[step], buf_done[step] = terminated, done
                session.env_steps += n
                running += rewards
                for i in np.flatnonzero(done):
                    session.end_episode(running[i], losses)
                    running[i] = 0.0
                obs = next_obs
            with reported_divergence(session, "A2C", "lower the learning rates"):
                losses = agent.update(buf_obs, buf_actions, buf_rewards, buf_next, buf_term, buf_done)
            session.maybe_evaluate(agent.greedy_actions, agent.get_weights)
            if session.book.episodes >= next_checkpoint:
                checkpoint()
                next_checkpoint += cfg.checkpoint_every
    return session.conclude(checkpoint, agent.save, agent.set_weights)
