"""What a run's ``metrics.csv`` says of its critic: the mean Q of its training batches (``q_mean``, logged
per episode by the DQN family and SAC) over training, beside the returns its episodes paid.

A critic estimates discounted returns, so its mean Q stays within the scale of the returns the run has
seen; a critic that diverges does not (seed 2 of the Minitaur sweep: its mean Q rose from 0.2 at 160k env
steps to about 3,000 at 1M, while no training episode returned more than 5.6). Nothing here draws a
line between the two: the report and the docs print both numbers side by side and
:func:`rlcore.records.report_plots.plot_critic` draws the curve. The comparison holds at a run's end, not at its
start: SAC's Q is soft (it holds the entropy bonus), so its first ~20k steps read high (about 54 against
returns of about 3 on Minitaur) while the temperature is still near its initial 1. TensorFlow-free.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: the metrics.csv column of a critic's mean Q on its training batches
Q_COLUMN = "q_mean"
#: episodes in the running median that smooths the per-episode means (a batch's Q is noisy)
WINDOW = 20


@dataclass(frozen=True)
class CriticTrace:
    env_steps: np.ndarray  # at the end of each episode that made gradient steps
    q: np.ndarray  # running median of the mean Q over the last WINDOW such episodes
    largest_return: float  # the largest return of any training episode

    @property
    def q_end(self) -> float:
        return float(self.q[-1])


def running_median(values: np.ndarray, window: int = WINDOW) -> np.ndarray:
    """Element i: the median of ``values[max(0, i - window + 1) : i + 1]``."""
    return np.array([np.median(values[max(0, i - window + 1):i + 1]) for i in range(len(values))])


def critic_trace(run_dir: Path) -> CriticTrace | None:
    """The run's critic over training; None when its metrics.csv logs no Q (A2C, PPO) or has no episode that
    made a gradient step yet."""
    path = Path(run_dir) / "metrics.csv"
    if not path.is_file():
        return None
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or Q_COLUMN not in rows[0]:
        return None
    steps, q = [], []
    for row in rows:
        value, step = _number(row[Q_COLUMN]), _number(row.get("env_steps"))
        if value is not None and step is not None:  # episodes before learning starts log an empty or nan Q
            steps.append(step)
            q.append(value)
    if not q:
        return None
    returns = [r for r in (_number(row.get("total_points")) for row in rows) if r is not None]
    return CriticTrace(np.array(steps), running_median(np.array(q)), max(returns, default=float("nan")))


def _number(text: str | None) -> float | None:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def critic_cell(trace: CriticTrace | None) -> str:
    """``1,234 (largest return 5.67)``: mean Q at the end beside the largest training return (``–`` where
    no return was logged); ``–`` without a trace."""
    if trace is None:
        return "–"
    paid = "–" if math.isnan(trace.largest_return) else q_text(trace.largest_return)
    return f"{q_text(trace.q_end)} (largest return {paid})"


def q_text(value: float) -> str:
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.1f}" if abs(value) >= 10 else f"{value:.2f}"
