"""Step loop for SAC: one env step per gradient step, after ``learning_starts`` random steps.

Like TF-Agents' driver, a time-limit truncation still bootstraps (only ``terminated``, a fall,
stops it). The replay memory is saved beside each checkpoint (``replay.npz``), so a resumed run
continues where it stopped; without that file it continues with an empty memory that refills first.
"""
from __future__ import annotations

from pathlib import Path

import keras
import numpy as np

from rlcore.agents.sac import SACAgent
from rlcore.replay import ReplayMemory
from rlcore.trainers import checkpoints
from rlcore.trainers.divergence import reported_divergence
from rlcore.trainers.episodes import episode_means
from rlcore.trainers.session import TrainingSession
from rlcore.trainers.spec import RunSpec


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
    grad_steps = int(state["grad_steps"]) if state else 0

    def checkpoint():
        checkpoints.save(session, agent, rng, memory, grad_steps=grad_steps,
                         log_alpha=float(agent.log_alpha.numpy()),
                         obs_stats=agent.obs_stats_state())

    k = cfg.updates_per_call
    # a resumed run reseeds from its episode count
    first_seed = session.fresh_env_seeds(1)[0]
    with session.interruptible():
        while not session.should_stop():
            obs, _ = env.reset(seed=first_seed)
            agent.observe(obs)
            first_seed = None  # later episodes continue the env's own RNG
            episode_return, episode_steps, losses = 0.0, 0, []
            while True:
                if session.env_steps < cfg.learning_starts:
                    action = rng.uniform(-1.0, 1.0, act_dim).astype(np.float32)
                else:
                    action = agent.act(obs[None], rng)[0]
                next_obs, reward, terminated, truncated, info = env.step(action)
                memory.add(obs, action, reward, next_obs, terminated)
                agent.observe(next_obs)
                session.env_steps += 1
                episode_return += reward
                episode_steps += 1
                obs = next_obs
                # len(memory): after a resume without its replay file, the memory refills first
                if len(memory) >= max(cfg.learning_starts, cfg.batch_size) and session.env_steps % k == 0:
                    stacked = memory.sample_stacked(k, cfg.batch_size, rng)
                    with reported_divergence(session, "SAC", "lower the learning rates"):
                        losses.append(agent.train_steps(*stacked, rng))
                    grad_steps += k
                session.maybe_evaluate(agent.greedy_actions, agent.get_weights)
                if terminated or truncated or session.stop_requested:
                    break
            if session.stop_requested:  # partial episode: not counted; its transitions stay in replay
                break
            means = episode_means(losses, ("critic_loss", "actor_loss", "alpha", "entropy", "q_mean"))
            # episode_steps: how long it stood (Minitaur: a fall ends it before the time limit)
            ends = {key: float(info.get(key, float("nan"))) for key in spec.experiment.info_keys}
            session.end_episode(episode_return, {"episode_steps": episode_steps, **ends, "grad_steps": grad_steps,
                                                 **means})
            if session.book.episodes % cfg.checkpoint_every == 0:
                checkpoint()
    env.close()
    return session.conclude(checkpoint, agent.save, agent.set_weights)

