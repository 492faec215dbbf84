"""Greedy evaluation on seeds that training never uses."""
from __future__ import annotations

import numpy as np
from tqdm import tqdm


def evaluate(experiment, policy, episodes: int = 100, seed_base: int | None = None,
             max_episode_steps: int | None = None, progress: bool = True) -> np.ndarray:
    """Play ``episodes`` greedy episodes, episode i seeded ``seed_base + i``; return the returns.

    ``max_episode_steps=None`` keeps the env's registered time limit.

    All episodes run side by side in an in-process vector env so the policy sees one batch per step.
    """
    import gymnasium as gym

    seed_base = experiment.eval_seed_base if seed_base is None else seed_base
    width = min(episodes, 20)
    envs = gym.vector.SyncVectorEnv(
        [lambda: experiment.make_env(max_episode_steps=max_episode_steps) for _ in range(width)],
        autoreset_mode=gym.vector.AutoresetMode.SAME_STEP)
    returns, next_seed = [], 0
    obs, _ = envs.reset(seed=[seed_base + i for i in range(width)])
    next_seed = width
    running = np.zeros(width)
    active = np.ones(width, bool)  # envs still owed an episode
    bar = tqdm(total=episodes, unit="ep", desc="evaluate", disable=None if progress else True,
               leave=False)
    while active.any():
        obs, reward, terminated, truncated, _ = envs.step(policy(obs))
        running += reward
        for i in np.flatnonzero((terminated | truncated) & active):
            returns.append(running[i])
            running[i] = 0.0
            bar.update(1)
            if next_seed < episodes:  # the auto-reset episode gets a fresh evaluation seed
                obs[i], _ = envs.envs[i].reset(seed=seed_base + next_seed)
                next_seed += 1
            else:
                active[i] = False
    bar.close()
    envs.close()
    return np.asarray(returns[:episodes])
