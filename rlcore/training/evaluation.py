"""Greedy evaluation on seeds that training never uses."""
from __future__ import annotations

from collections import Counter

import numpy as np
from tqdm.auto import tqdm  # a widget in a notebook, text in a terminal

from rlcore.environments.vector import final_info


def evaluate(experiment, policy, episodes: int = 100, seed_base: int | None = None,
             max_episode_steps: int | None = None, progress: bool = True, make_env=None) -> np.ndarray:
    """Play ``episodes`` greedy episodes, episode i seeded ``seed_base + i``; return the returns in
    seed order. The arguments are those of :func:`play_greedy`."""
    records = play_greedy(experiment, policy, episodes, seed_base, max_episode_steps, progress, make_env)
    return np.asarray([r["return"] for r in records])


def play_greedy(experiment, policy, episodes: int = 100, seed_base: int | None = None,
                max_episode_steps: int | None = None, progress: bool = True, make_env=None,
                info_keys: tuple[str, ...] = ()) -> list[dict]:
    """Play ``episodes`` greedy episodes, episode i seeded ``seed_base + i``; one record per
    episode in seed order: seed, return, length, ``time_limit`` (it lasted until the time limit
    rather than ending in the env, a fall say) and the final value of each of ``info_keys`` that the
    env reported (a training-only key, such as Mario's ``start_x``, is left out).

    ``max_episode_steps=None`` keeps the env's registered time limit; ``make_env()``, when given,
    builds the env instead (a saved model's own level, say).

    All episodes run side by side in an in-process vector env so the policy sees one batch per step.
    """
    import gymnasium as gym

    seed_base = experiment.eval_seed_base if seed_base is None else seed_base
    width = min(episodes, 20)
    make_env = make_env or (lambda: experiment.make_env(max_episode_steps=max_episode_steps))
    envs = gym.vector.SyncVectorEnv(
        [make_env for _ in range(width)],
        autoreset_mode=gym.vector.AutoresetMode.SAME_STEP)
    records = []
    obs, _ = envs.reset(seed=[seed_base + i for i in range(width)])
    slot_seed = list(range(seed_base, seed_base + width))  # the seed of each env's current episode
    next_seed = seed_base + width
    running, length = np.zeros(width), np.zeros(width, int)
    active = np.ones(width, bool)  # envs still owed an episode
    bar = tqdm(total=episodes, unit="ep", desc="evaluate", disable=None if progress else True,
               leave=False)
    while active.any():
        obs, reward, terminated, truncated, info = envs.step(policy(obs))
        running += reward
        length += 1
        for i in np.flatnonzero((terminated | truncated) & active):
            record = {"seed": slot_seed[i], "return": float(running[i]), "length": int(length[i]),
                      "time_limit": bool(truncated[i] and not terminated[i])}
            reported = {k: final_info(info, k, i, None) for k in info_keys}
            record.update({k: float(v) for k, v in reported.items() if v is not None})
            records.append(record)
            running[i], length[i] = 0.0, 0
            bar.update(1)
            if next_seed < seed_base + episodes:  # the auto-reset episode gets a fresh evaluation seed
                obs[i], _ = envs.envs[i].reset(seed=next_seed)
                slot_seed[i], next_seed = next_seed, next_seed + 1
            else:
                active[i] = False
    bar.close()
    envs.close()
    return sorted(records, key=lambda r: r["seed"])


def evaluate_success(make_env, act, episodes: int, seed_base: int, success_key: str,
                     progress_key: str | None = None, progress: bool = True,
                     stop_at_success: bool = False, info_keys: tuple[str, ...] = ()) -> list[dict]:
    """Play episodes one by one; episode i resets with seed ``seed_base + i`` and draws its actions
    from ``act(obs_batch, rng)`` with ``rng = default_rng(seed_base + i)``.

    For envs where success is an event (Mario's flag), not a return. Each record holds the
    return, the length, whether ``info[success_key]`` was true at the end, ``info[progress_key]``
    there, and each of ``info_keys`` the env reported.
    """
    env = make_env()
    records = []
    bar = tqdm(total=episodes, unit="ep", desc="evaluate", disable=None if progress else True, leave=False)
    try:
        for i in range(episodes):
            rng = np.random.default_rng(seed_base + i)
            obs, info = env.reset(seed=seed_base + i)
            total, length, done = 0.0, 0, False
            while not done:
                obs, reward, terminated, truncated, info = env.step(int(act(obs[None], rng)[0]))
                total, length, done = total + reward, length + 1, terminated or truncated
            record = {"seed": seed_base + i, "return": float(total), "length": length,
                      "success": bool(info.get(success_key, False))}
            if progress_key:
                record[progress_key] = float(info.get(progress_key, float("nan")))
            record.update({k: float(info[k]) for k in info_keys if k in info})
            records.append(record)
            bar.update(1)
            if stop_at_success and record["success"]:
                break
    finally:
        bar.close()
        env.close()
    return records


def summarize_success(records: list[dict], progress_key: str | None = None) -> dict:
    """Share of successes, mean return (and mean progress) over evaluation records."""
    out = {"episodes": len(records),
           "success_share": round(float(np.mean([r["success"] for r in records])), 3),
           "mean_return": round(float(np.mean([r["return"] for r in records])), 2)}
    if progress_key:
        values = [r[progress_key] for r in records]
        out[f"mean_{progress_key}"] = round(float(np.mean(values)), 1)
        out[f"max_{progress_key}"] = round(float(np.max(values)), 1)
    return out


def miss_cause(record: dict, cause_key: str | None, cause_name) -> str | None:
    """What ended a failed episode, in words: its cause (``cause_key``, named by ``cause_name``), or ``stalled``
    where the stall limit ended it (the episode's ``stalled`` mark, as the plots read it); None for neither."""
    code = record.get(cause_key, np.nan) if cause_key else np.nan
    if code is not None and not np.isnan(code):
        return cause_name(code)
    return "stalled" if record.get("stalled") else None


def count_causes(records: list[dict], cause_key: str, cause_name) -> list[tuple[str, int]]:
    """(what ended the episode in words, episodes) over the records :func:`miss_cause` names, most first (ties
    in the order met); numbers that ``cause_name`` puts in the same words (Mario: the five Firebar ids) count
    together, and the stall limit counts as ``stalled``."""
    names = Counter(name for r in records if (name := miss_cause(r, cause_key, cause_name)) is not None)
    return names.most_common()
