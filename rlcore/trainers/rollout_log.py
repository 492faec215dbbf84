"""What the episodes of one PPO rollout did: each episode's row of metrics.csv, the rollout's row of
rollouts.csv and its console line (the article's: max and min progress, flags reached).

An experiment may name info keys for success (Mario: ``flag_get``), progress (``x_pos``), episodes
that started elsewhere than evaluations do (``restarted``) and more to keep per episode
(``stalled``); the values are read where each episode ended (:func:`rlcore.vector.final_info`).
"""
from __future__ import annotations

import numpy as np

from rlcore.vector import final_info


class RolloutLog:
    def __init__(self, experiment):
        self.exp = experiment
        self.max_x, self.min_x = -np.inf, np.inf
        self.ended = self.flags = 0
        self.partial_ended = self.partial_flags = 0  # episodes that did not start at the start

    def step(self, infos: dict) -> None:
        """After each pool step: the farthest progress of any env."""
        if self.exp.progress_key:
            self.max_x = max(self.max_x, float(np.max(infos[self.exp.progress_key])))

    def episode(self, infos: dict, i: int, extra: dict) -> tuple[dict, bool | None, bool]:
        """Env ``i``'s episode ended this step: (its metrics row, ``extra`` first; whether it
        succeeded, None without a success key; whether it counts toward the success share)."""
        exp, row, won = self.exp, dict(extra), None
        partial = bool(exp.partial_key and final_info(infos, exp.partial_key, i, False))
        if exp.partial_key:
            row[exp.partial_key] = float(partial)
            self.partial_ended += partial
        if exp.progress_key:
            x = float(final_info(infos, exp.progress_key, i))
            self.max_x, self.min_x = max(self.max_x, x), min(self.min_x, x)
            row[exp.progress_key] = x
        if exp.success_key:
            won = bool(final_info(infos, exp.success_key, i, False))
            self.flags += won and not partial
            self.partial_flags += won and partial
        for key in exp.info_keys:  # NaN where the env did not report it
            row[key] = float(final_info(infos, key, i, float("nan")))
        self.ended += 1
        return row, won, not partial

    def row(self) -> dict:
        """The rollout's counts for rollouts.csv (before the losses)."""
        exp = self.exp
        row = {"episodes_ended": self.ended, "successes": self.flags}
        if exp.partial_key:
            row.update({f"{exp.partial_key}_episodes": self.partial_ended,
                        f"{exp.partial_key}_successes": self.partial_flags})
        return {**row, f"max_{exp.progress_key or 'x'}": self.max_x}

    def line(self, rollout: int, env_steps: int, book, window: int) -> str:
        """The console line, without the losses."""
        exp = self.exp
        line = f"rollout {rollout} | env steps {env_steps:,} | episodes {book.episodes:,}"
        if exp.progress_key:
            min_x = self.min_x if np.isfinite(self.min_x) else float("nan")
            line += f" | max {exp.progress_key} {self.max_x:.0f} | min {exp.progress_key} {min_x:.0f}"
        if exp.success_key:
            line += (f" | {exp.success_key} {self.flags}/{self.ended - self.partial_ended} "
                     f"(last {window}: {book.success_share:.0%})")
            if self.partial_ended:
                line += f" | {exp.partial_key} {self.partial_flags}/{self.partial_ended}"
        return line
