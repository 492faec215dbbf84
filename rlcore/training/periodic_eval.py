"""Periodic greedy evaluation during training: when to evaluate, the best result so far, its weights.

Only the episode-driven configs (``EpisodeLoop``: DQN, A2C, SAC) ask for it; for the others
(PPO) it is switched off. Every ``eval_every_steps`` env steps the greedy policy plays
``eval_episodes`` episodes on the fixed selection seeds (never the final evaluation's); the mean,
the std and the share of episodes that lasted to the time limit go to ``evals.csv``; the best
mean is remembered (a tie goes to the later evaluation: the same score with more training behind
it), with a snapshot of its weights when ``keep_best`` is set, and
``stop_eval_score`` can end the run once an evaluation reaches it.
"""
from __future__ import annotations

import numpy as np


class PeriodicEvaluation:
    def __init__(self, cfg, state: dict):
        from rlcore.hyperparams.base import EpisodeLoop

        on = isinstance(cfg, EpisodeLoop)  # other configs (PPO's) have no periodic evaluation
        self.every = cfg.eval_every_steps if on else 0
        self.episodes = cfg.eval_episodes if on else 0
        self.keep_best = cfg.keep_best if on else False
        self.stop_score = cfg.stop_eval_score if on else 0.0
        self.max_episode_steps = cfg.max_episode_steps or None
        self.best = state.get("best_eval")  # {"mean", "std", "env_steps"} of the best evaluation
        self.best_weights = None  # its weights, with keep_best
        self.next_step = int(state.get("next_eval_step", self.every))

    def due(self, env_steps: int) -> bool:
        return bool(self.every) and env_steps >= self.next_step

    def run(self, experiment, greedy_policy, snapshot, env_steps: int) -> dict:
        """Evaluate now; return its numbers for ``evals.csv``. ``snapshot() -> weights``."""
        from rlcore.training.evaluation import play_greedy

        while self.next_step <= env_steps:
            self.next_step += self.every
        records = play_greedy(experiment, greedy_policy, self.episodes, seed_base=experiment.selection_seed_base,
                              max_episode_steps=self.max_episode_steps, progress=False)
        returns = np.array([r["return"] for r in records])
        mean, std = float(returns.mean()), float(returns.std())
        if self.best is None or mean >= self.best["mean"]:
            self.best = {"mean": round(mean, 2), "std": round(std, 2), "env_steps": env_steps}
            if self.keep_best:
                self.best_weights = snapshot()
        return {"eval_mean": mean, "eval_std": std,
                "eval_time_limit_share": float(np.mean([r["time_limit"] for r in records]))}

    def reached_stop_score(self) -> bool:
        return bool(self.stop_score) and self.best is not None and self.best["mean"] >= self.stop_score

    def state(self) -> dict:
        return {"best_eval": self.best, "next_eval_step": self.next_step}

    def best_arrays(self) -> dict:
        """The kept best weights, as checkpoint arrays."""
        return {f"best/{i}": w for i, w in enumerate(self.best_weights or [])}

    def restore_best_arrays(self, arrays: dict) -> None:
        keys = sorted((k for k in arrays if k.startswith("best/")), key=lambda k: int(k.split("/")[1]))
        self.best_weights = [arrays[k] for k in keys] or None
