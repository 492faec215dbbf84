"""How fast a run in progress goes: its env steps per second lately, from metrics.csv's training clock,
and the hours left at that pace to its budget, of env steps or of episodes, whichever it meets first
(``main.py status``, for a run and for each trial of a sweep). TensorFlow-free."""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from rlcore.records.plotting import read_table

#: a budget this large is no budget (the presets' "until the stop rule" values)
NO_BUDGET = 10**9


class Pace(NamedTuple):
    rate: float  # env steps per second lately
    left: float | None  # seconds to the budget it meets first, at that pace; None without one
    budget: str | None = None  # that budget in words: "1,000,000 env steps", "2,000 episodes"


def pace(metrics_csv: Path, about: dict, span_seconds: float = 1800.0) -> Pace | None:
    """A run in progress: its env steps per second over the last ``span_seconds`` of its training clock
    (``metrics.csv``'s ``wall_seconds``, which a resume carries on), and the seconds left at that pace to
    the budget it meets first, of env steps or episodes (None without one, or while it takes no gradient step yet: an off-policy run's
    first, random steps run about twice as fast as its learning ones, so they tell nothing of the hours
    left). A stop rule may end it sooner, a slower pace later. None for a table without that clock."""
    if not Path(metrics_csv).is_file():
        return None
    df = read_table(metrics_csv, "env_steps")
    if "wall_seconds" not in df:
        return None
    grads = df["grad_steps"].fillna(0) if "grad_steps" in df else None  # a running count (DQN, SAC)
    df = df[["env_steps", "wall_seconds"]].dropna()
    # only the rows since either counter last went back (a table pieced together from two runs)
    back = ((df["wall_seconds"].diff() < 0) | (df["env_steps"].diff() < 0)).to_numpy().nonzero()[0]
    df = df.iloc[back[-1]:] if len(back) else df
    if grads is not None and len(df):
        # an episode learnt when the count grew over it; the pace is read from the row before the
        # latest stretch of such episodes (its first steps, or a resume refilling an empty memory, take none)
        grads = grads.reindex(df.index).to_numpy()
        learnt = grads > np.concatenate(([0.0], grads[:-1]))
        if not learnt[-1]:
            measured = _rate(df, span_seconds)
            return None if measured is None else Pace(measured, None)
        idle = (~learnt).nonzero()[0]
        df = df.iloc[idle[-1]:] if len(idle) else df
    rate = _rate(df, span_seconds)
    if rate is None:
        return None
    return Pace(rate, *_time_left(df, about, rate, span_seconds))


def _time_left(df: pd.DataFrame, about: dict, rate: float, span_seconds: float) -> tuple[float | None, str | None]:
    """Seconds to the budget the run meets first at the recent pace, and that budget in words."""
    config = about.get("config") or {}
    found = []
    steps, done = config.get("max_env_steps"), about.get("env_steps", int(df["env_steps"].iloc[-1]))
    if steps and steps < NO_BUDGET:
        found.append((max(0, steps - done) / rate, f"{steps:,} env steps"))
    episodes, ended = config.get("max_episodes"), about.get("episodes", len(about.get("returns") or []) or len(df))
    per_second = _rate(df.assign(env_steps=np.arange(len(df), dtype=float)), span_seconds)  # rows are episodes
    if episodes and episodes < NO_BUDGET and per_second:
        found.append((max(0, episodes - ended) / per_second, f"{episodes:,} episodes"))
    return min(found) if found else (None, None)


def _rate(df: pd.DataFrame, span_seconds: float) -> float | None:
    """Env steps per second over the last ``span_seconds`` of the ``wall_seconds`` clock (the last two rows
    when fewer fall in it); None for fewer than two rows or no time or step between them."""
    if len(df) < 2:
        return None
    recent = df[df["wall_seconds"] >= df["wall_seconds"].iloc[-1] - span_seconds]
    recent = recent if len(recent) >= 2 else df.tail(2)
    seconds = float(recent["wall_seconds"].iloc[-1] - recent["wall_seconds"].iloc[0])
    steps = float(recent["env_steps"].iloc[-1] - recent["env_steps"].iloc[0])
    return steps / seconds if seconds > 0 and steps > 0 else None


def pace_text(metrics_csv: Path, about: dict, measured: Pace | None = None) -> str | None:
    """:func:`pace` in words: ``86 env steps/s lately, about 3.1 h to its budget of 1,000,000 env steps``
    (``measured``: what :func:`pace` gave already, so the table is not read again)."""
    measured = measured or pace(metrics_csv, about)
    if measured is None:
        return None
    rate, left, budget = measured
    text = (f"{rate:,.0f}" if rate >= 10 else f"{rate:.2g}") + " env steps/s lately"
    if left:
        config = about["config"]
        text += f", about {left / 3600:.1f} h to its budget of {budget}"
        if config.get("stop_success_share") or (config.get("stop_eval_score") and config.get("eval_every_steps")):
            text += " (its stop rule may end it sooner)"
    return text
