"""The console progress bar of a run: by episode (DQN, A2C, SAC) or by env step (PPO: long
episodes and a step budget). Off with ``--no-progress`` or when the console is not a terminal."""
from __future__ import annotations

import time

from tqdm.auto import tqdm  # a widget in a notebook, text in a terminal


class Progress:
    def __init__(self, unit: str, cfg, episodes: int, env_steps: int, enabled: bool):
        self.by_steps = unit == "step"
        self._started, self._steps_at_start = time.perf_counter(), env_steps
        self.bar = tqdm(total=(cfg.max_env_steps or None) if self.by_steps else cfg.max_episodes,
                        initial=env_steps if self.by_steps else episodes,
                        unit="step" if self.by_steps else "ep", unit_scale=self.by_steps,
                        disable=None if enabled else True, dynamic_ncols=True, leave=True)

    def episode(self, book, env_steps: int) -> None:
        if self.by_steps:
            self.bar.set_postfix(episodes=book.episodes, avg100=f"{book.average:.1f}", refresh=False)
            return
        rate = (env_steps - self._steps_at_start) / max(time.perf_counter() - self._started, 1e-9)
        self.bar.update(1)
        self.bar.set_postfix(avg100=f"{book.average:.1f}", steps=env_steps, sps=f"{rate:.0f}", refresh=False)

    def steps(self, n: int) -> None:
        if self.by_steps:
            self.bar.update(n)

    def close(self) -> None:
        self.bar.close()
