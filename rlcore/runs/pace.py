"""How fast a run in progress goes: its env steps per second lately, from metrics.csv's training clock,
and the hours left at that pace to its env-step budget (``main.py status``, for a run and for each trial
of a sweep). TensorFlow-free."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from rlcore.runs.plotting import read_table


#: a budget this large is no budget (the presets' "until the stop rule" values)
NO_BUDGET = 10**9


def pace(metrics_csv: Path, about: dict, span_seconds: float = 1800.0) -> tuple[float, float | None] | None:
    """A run in progress: its env steps per second over the last ``span_seconds`` of its training clock
    (``metrics.csv``'s ``wall_seconds``, which a resume carries on), and the seconds left at that pace to
    its env-step budget (None without one, or while it takes no gradient step yet: an off-policy run's
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
            return None if measured is None else (measured, None)
        idle = (~learnt).nonzero()[0]
        df = df.iloc[idle[-1]:] if len(idle) else df
    rate = _rate(df, span_seconds)
    if rate is None:
        return None
    budget = (about.get("config") or {}).get("max_env_steps")
    done = about.get("env_steps", int(df["env_steps"].iloc[-1]))
    left = max(0, budget - done) / rate if budget and budget < NO_BUDGET else None
    return rate, left


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


def pace_text(metrics_csv: Path, about: dict, measured: tuple[float, float | None] | None = None) -> str | None:
    """:func:`pace` in words: ``86 env steps/s lately, about 3.1 h to its budget of 1,000,000 env steps``
    (``measured``: what :func:`pace` gave already, so the table is not read again)."""
    measured = measured or pace(metrics_csv, about)
    if measured is None:
        return None
    rate, left = measured
    text = (f"{rate:,.0f}" if rate >= 10 else f"{rate:.2g}") + " env steps/s lately"
    if left:
        config = about["config"]
        text += f", about {left / 3600:.1f} h to its budget of {config['max_env_steps']:,} env steps"
        if config.get("stop_success_share") or (config.get("stop_eval_score") and config.get("eval_every_steps")):
            text += " (its stop rule may end it sooner)"
    return text
