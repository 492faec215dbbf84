"""Running mean and variance of a stream of vectors (Chan et al.'s parallel update), for observation
standardization. Plain numpy; its state is three JSON-able lists for a checkpoint."""
from __future__ import annotations

import numpy as np


class RunningMeanStd:
    def __init__(self, dim: int, state: dict | None = None):
        self.count = 0.0
        self.mean = np.zeros(dim)
        self.var = np.ones(dim)  # the variance before any data: standardizing leaves x - 0 as it is
        if state:
            self.count = float(state["count"])
            self.mean, self.var = np.asarray(state["mean"], float), np.asarray(state["var"], float)

    def update(self, batch: np.ndarray) -> None:
        """Fold a batch of rows ``[B, dim]`` into the statistics (population variance)."""
        batch = np.asarray(batch, float).reshape(-1, self.mean.size)
        n = len(batch)
        if n == 0:
            return
        b_mean, b_var = batch.mean(axis=0), batch.var(axis=0)
        if self.count == 0:
            self.count, self.mean, self.var = float(n), b_mean, b_var
            return
        total = self.count + n
        delta = b_mean - self.mean
        m2 = self.var * self.count + b_var * n + delta ** 2 * self.count * n / total
        self.mean, self.var, self.count = self.mean + delta * n / total, m2 / total, total

    def state(self) -> dict:
        return {"count": self.count, "mean": self.mean.tolist(), "var": self.var.tolist()}
