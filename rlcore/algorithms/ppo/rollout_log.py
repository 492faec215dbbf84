"""What the episodes of one PPO rollout did: each episode's row of metrics.csv, the rollout's row of
rollouts.csv and its console line (the article's: max and min progress, flags reached).

An experiment may name info keys for success and progress (its ``Goal``, Mario: ``flag_get``,
``x_pos``), episodes that started elsewhere than evaluations do (its ``Curriculum``: ``restarted``) and
more to keep per episode (``stalled``); the values are read where each episode ended
(:func:`rlcore.environments.vector.final_info`).
"""
from __future__ import annotations

import numpy as np

from rlcore.environments.vector import final_info


class RolloutLog:
    def __init__(self, experiment):
        self.exp = experiment
        goal, curriculum = experiment.goal, experiment.curriculum
        self.success_key = goal.success_key if goal else None
        self.progress_key = goal.progress_key if goal else None
        self.partial_key = curriculum.partial_key if curriculum else None
        self.max_x, self.min_x = -np.inf, np.inf
        self.ended = self.flags = 0
        self.partial_ended = self.partial_flags = 0  # episodes that did not start at the start

    def step(self, infos: dict) -> None:
        """After each pool step: the farthest progress of any env."""
        if self.progress_key:
            self.max_x = max(self.max_x, float(np.max(infos[self.progress_key])))

    def episode(self, infos: dict, i: int, extra: dict) -> tuple[dict, bool | None, bool]:
        """Env ``i``'s episode ended this step: (its metrics row, ``extra`` first; whether it
        succeeded, None without a success key; whether it counts toward the success share)."""
        row, won = dict(extra), None
        partial = bool(self.partial_key and final_info(infos, self.partial_key, i, False))
        if self.partial_key:
            row[self.partial_key] = float(partial)
            self.partial_ended += partial
        if self.progress_key:
            x = float(final_info(infos, self.progress_key, i))
            self.max_x, self.min_x = max(self.max_x, x), min(self.min_x, x)
            row[self.progress_key] = x
        if self.success_key:
            won = bool(final_info(infos, self.success_key, i, False))
            self.flags += won and not partial
            self.partial_flags += won and partial
        for key in self.exp.info_keys:  # NaN where the env did not report it
            row[key] = float(final_info(infos, key, i, float("nan")))
        self.ended += 1
        return row, won, not partial

    def row(self) -> dict:
        """The rollout's counts for rollouts.csv (before the losses)."""
        row = {"episodes_ended": self.ended, "successes": self.flags}
        if self.partial_key:
            row.update({f"{self.partial_key}_episodes": self.partial_ended,
                        f"{self.partial_key}_successes": self.partial_flags})
        return {**row, f"max_{self.progress_key or 'x'}": self.max_x}

    def line(self, rollout: int, env_steps: int, book, window: int) -> str:
        """The console line, without the losses."""
        line = f"rollout {rollout} | env steps {env_steps:,} | episodes {book.episodes:,}"
        if self.progress_key:
            min_x = self.min_x if np.isfinite(self.min_x) else float("nan")
            line += f" | max {self.progress_key} {self.max_x:.0f} | min {self.progress_key} {min_x:.0f}"
        if self.success_key:
            line += (f" | {self.success_key} {self.flags}/{self.ended - self.partial_ended} "
                     f"(last {window}: {book.success_share:.0%})")
            if self.partial_ended:
                line += f" | {self.partial_key} {self.partial_flags}/{self.partial_ended}"
        return line
