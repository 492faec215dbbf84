"""Episode book-keeping as article 000 does it: returns, the moving average, its console lines; and,
for experiments with a goal (Mario's flag), which episodes reached it."""
from __future__ import annotations

import numpy as np
from tqdm.auto import tqdm  # a widget in a notebook, text in a terminal


def episode_means(reports: list[dict], names: tuple[str, ...]) -> dict[str, float]:
    """The mean of each named number over an episode's update reports (NaN before the first update)."""
    return {n: float(np.mean([r[n] for r in reports])) if reports else float("nan") for n in names}


class EpisodeBook:
    """Episode returns, the moving average, successes, and the article's console line and wandb keys."""

    def __init__(self, window: int, solved_score: float | None, returns: list[float] | None = None,
                 successes: list[bool] | None = None, counted_returns: list[float] | None = None):
        self.window, self.solved_score = window, solved_score
        self.returns: list[float] = list(returns or [])  # every episode's, in order
        # the returns of the episodes that count (all but those that started elsewhere than
        # evaluations do, e.g. Mario's restarts): the moving average is theirs
        self.counted_returns: list[float] = list(self.returns if counted_returns is None else counted_returns)
        self.successes: list[bool] = list(successes or [])  # only counted episodes that report success
        self.solved_episode: int | None = None

    @property
    def episodes(self) -> int:
        return len(self.returns)

    @property
    def average(self) -> float:
        """The mean return of the last ``window`` counted episodes."""
        recent = self.counted_returns[-self.window:]
        return float(np.mean(recent)) if recent else float("nan")

    @property
    def success_share(self) -> float:
        """Share of the last ``window`` episodes that succeeded (0 before any)."""
        recent = self.successes[-self.window:]
        return float(np.mean(recent)) if recent else 0.0

    def full_window(self) -> bool:
        return len(self.counted_returns) >= self.window

    @property
    def settled_success_share(self) -> float | None:
        """The success share once ``window`` counted episodes have reported success, else None (what
        the stop rule and ``--lr-halve-at`` read, so a lucky first few episodes do not count)."""
        return self.success_share if len(self.successes) >= self.window else None

    def add(self, episode_return: float, success: bool | None = None, counted: bool = True) -> dict:
        """Record one episode; return the article's per-episode metrics (and success, when given).
        An episode not ``counted`` (it started elsewhere than evaluations do) logs its return and
        success but leaves the moving average and the success share as they were."""
        self.returns.append(float(episode_return))
        if counted:
            self.counted_returns.append(float(episode_return))
        if (self.solved_score is not None and self.solved_episode is None and self.full_window()
                and self.average >= self.solved_score):
            self.solved_episode = self.episodes
            # the article's line; the run goes on, since its own stop rules and budget end it
            tqdm.write(f"\nEnvironment solved in {self.episodes} episodes! (the last {self.window} average "
                       f"{self.average:.1f} >= {self.solved_score:g}; training goes on until a stop rule or its budget ends it)")
        if self.episodes % self.window == 0:
            which = "episodes" if len(self.counted_returns) == self.episodes else "full episodes"
            tqdm.write(f"Episode {self.episodes} | Total point average of the last {self.window} "
                       f"{which}: {self.average:.2f}")
        row = {"episode": self.episodes, "total_points": float(episode_return),
               "av_latest_points": self.average, "target_ave_scores": self.solved_score}
        if success is not None:
            if counted:
                self.successes.append(bool(success))
            row.update(success=int(success), success_share=self.success_share)
        return row
