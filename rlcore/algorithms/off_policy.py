"""The episode loop of the off-policy trainers (the DQN family and SAC), written once.

One env, one step at a time: act, keep the transition in the replay memory, and every
``update_period`` env steps (once the memory holds ``max(learning_starts, batch_size)``) learn from
``updates_per_call`` stacked minibatches in one compiled call. Between steps, the session's periodic
evaluation; at each episode's end, the metrics row; every ``checkpoint_every`` episodes, a
checkpoint. Only ``terminated`` (not a time limit) is stored as the end of the return, so a
truncated episode still bootstraps.

What differs between the trainers is a :class:`Learner`: how it acts, what it learns from a batch,
which counters its checkpoint keeps and which numbers its episode row adds.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from rlcore.algorithms.replay import ReplayMemory
from rlcore.training.divergence import reported_divergence
from rlcore.training.session import TrainingSession


class Learner(Protocol):
    name: str  # "DQN", "SAC": the divergence message names it
    divergence_hint: str  # what to try when the losses turn NaN ("lower the learning rate")
    update_period: int  # env steps between two learning calls

    def act(self, obs: np.ndarray, env_steps: int) -> np.ndarray:
        """The action for one observation, ``env_steps`` into the run (before this step)."""

    def observe(self, obs: np.ndarray) -> None:
        """Every observation the env gives, the first of each episode included."""

    def learn(self, batches: tuple) -> dict:
        """``updates_per_call`` gradient steps on stacked minibatches; the report of the losses."""

    def episode_row(self, losses: list[dict], episode_steps: int, info: dict) -> dict:
        """The trainer's numbers for an episode's metrics row (the episode's reports, its length
        and the last step's info)."""

    def counters(self) -> dict:
        """The trainer's own counters for a checkpoint (epsilon, grad_steps, ...)."""


def run_episodes(session: TrainingSession, env, memory: ReplayMemory, rng: np.random.Generator,
                 learner: Learner, cfg, checkpoint: Callable[[], None],
                 greedy_actions: Callable, policy_weights: Callable) -> None:
    """Run episodes until the session says stop (a budget, the stop score, Ctrl-C); ``cfg``: the
    run's config (batch_size, learning_starts, updates_per_call, checkpoint_every)."""
    ready = max(cfg.learning_starts, cfg.batch_size)
    first_seed = session.fresh_env_seeds(1)[0]  # a resumed run reseeds from its episode count
    with session.interruptible():
        while not session.should_stop():
            obs, _ = env.reset(seed=first_seed)
            learner.observe(obs)
            first_seed = None  # later episodes continue the env's own RNG
            episode_return, episode_steps, losses = 0.0, 0, []
            while True:
                action = learner.act(obs, session.env_steps)
                next_obs, reward, terminated, truncated, info = env.step(action)
                memory.add(obs, action, reward, next_obs, terminated)
                learner.observe(next_obs)
                session.env_steps += 1
                episode_return += reward
                episode_steps += 1
                obs = next_obs
                # len(memory): after a resume without its replay file, the memory refills first (a full
                # frame memory holds fewer transitions than slots, and learns then too)
                if session.env_steps % learner.update_period == 0 and (len(memory) >= ready or memory.full):
                    batches = memory.sample_stacked(cfg.updates_per_call, cfg.batch_size, rng)
                    with reported_divergence(session, learner.name, learner.divergence_hint):
                        losses.append(learner.learn(batches))
                session.maybe_evaluate(greedy_actions, policy_weights)
                if terminated or truncated or session.stop_requested:
                    break
            if session.stop_requested:  # partial episode: not counted; its transitions stay in replay
                break
            session.end_episode(episode_return, learner.episode_row(losses, episode_steps, info))
            if session.book.episodes % cfg.checkpoint_every == 0:
                checkpoint()
    env.close()
