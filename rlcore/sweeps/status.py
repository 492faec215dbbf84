"""``main.py status SWEEP``: a line per trial of a sweep (finished with its score, at a checkpoint with
its pace and last evaluation, or not started), and the hours of training the sweep has left at the paces
seen. TensorFlow-free."""
from __future__ import annotations

import math
from pathlib import Path

from rlcore.errors import UserError
from rlcore.records.critic_trace import critic_cell, critic_trace
from rlcore.records.pace import NO_BUDGET, pace, pace_text
from rlcore.records.status import evaluation_lines, run_record

NOT_STARTED = "not started"


def sweep_status(folder: str | Path) -> list[str]:
    """What ``main.py status SWEEP`` prints: the sweep, then a line per trial (finished with its final
    score, stopped or running at a checkpoint with its pace and last periodic evaluation, or not
    started), then the hours of training left (:func:`time_left`). A trial whose tables are damaged
    gets its line without a pace, and the sweep no hours left."""
    from rlcore.sweeps.sweep import Sweep, trial_name

    sweep = Sweep.load(Path(folder))
    trials = [trial_name(t) for t in sweep.trials()]
    lines = [f"sweep {sweep.name}: {sweep.experiment} {sweep.algo}, {len(trials)} trials"]
    budgets: set = set()  # the env-step budgets the trials' records hold (one, unless a grid sets it)
    left: list = []  # per trial not finished: seconds left, NOT_STARTED, or None (cannot be told)
    rates: list[float] = []  # env steps/s of the finished trials over their whole runs
    for name in trials:
        trial = Path(sweep.folder) / name
        record = run_record(trial)
        if record is None:
            lines.append(f"  {name}: {NOT_STARTED}")
            left.append(NOT_STARTED)
            continue
        budgets.add((record.get("config") or {}).get("max_env_steps"))
        if "returns" not in record:  # a model's meta.json: finished
            if record.get("wall_seconds") and math.isfinite(record["env_steps"] / record["wall_seconds"]):
                rates.append(record["env_steps"] / record["wall_seconds"])
            lines.append(f"  {name}: " + finished_text(record, sweep.final_eval_episodes) + critic_text(trial))
            continue
        text, seconds_left = checkpoint_text(trial, record)
        lines.append(f"  {name}: {text}{critic_text(trial)}")
        left.append(seconds_left)
    budgets.discard(None)  # a record without its config says nothing of the budget
    budget = budgets.pop() if len(budgets) == 1 else None
    return lines + time_left(left, rates, budget if budget and budget < NO_BUDGET else None, sweep.max_concurrent)


def critic_text(trial: Path) -> str:
    """``; critic: mean Q ...``: a Q-learner's critic now, beside the returns it was paid; nothing for a
    damaged table or another learner."""
    try:
        critic = critic_trace(trial)
    except (OSError, ValueError, KeyError):
        return ""
    return f"; critic: mean Q {critic_cell(critic)}" if critic else ""


def finished_text(record: dict, final_eval_episodes: int) -> str:
    """A finished trial's env steps and final score as the sweep reports it (Mario: flag share)."""
    from rlcore.sweeps.trial import final_metrics

    final = final_metrics(record)
    if not math.isnan(final["final_score"]):
        return f"finished at {final['env_steps']:,} env steps, final score {final['final_score']:.2f} on unseen seeds"
    return (f"finished at {final['env_steps']:,} env steps; not evaluated on unseen seeds"  # NaN: not evaluated
            + ("" if final_eval_episodes == 0 else " yet (the sweep's --resume evaluates it)"))


def checkpoint_text(trial: Path, record: dict) -> tuple[str, object]:
    """A stopped or running trial's line (checkpoint, hours, pace, last periodic evaluation) and its
    seconds left for :func:`time_left` (None when a damaged table cannot tell)."""
    try:
        measured = pace(trial / "metrics.csv", record)
        text = pace_text(trial / "metrics.csv", record, measured)
        last = evaluation_lines(trial / "evals.csv", last=1)
    except UserError:  # a damaged table: the trial's line without what it would have said
        measured, text, last = None, None, []
    line = (f"checkpoint at {record['env_steps']:,} env steps, {record.get('wall_seconds', 0) / 3600:.1f} h"
            + (f", {text}" if text else "") + (f"; last {last[0]}" if last else ""))
    budget = (record.get("config") or {}).get("max_env_steps")
    if measured and measured[1] is None and budget and budget < NO_BUDGET:
        return line, NotLearning(max(0, budget - record["env_steps"]))  # no gradient step yet
    return line, measured[1] if measured else None


class NotLearning(float):
    """A running trial that has taken no gradient step yet: the env steps it has left, which
    :func:`time_left` prices at the finished trials' pace (its own first, random steps run faster)."""


def time_left(left: list, rates: list[float], budget: int | None, at_once: int) -> list[str]:
    """The sweep's hours of training left, about: each running trial's to its env-step budget at its
    pace lately, each trial not started (over its whole budget) or not learning yet (over its steps
    left, :class:`NotLearning`) at the finished trials' mean pace (a stop rule may end any sooner, a
    slower pace later), ``at_once`` trials at a time (0: as many as the CPUs allow, unknown here, so the
    sum is given), and never less than the longest trial's own. ``budget``: the trials' env-step budget
    as their records hold it. No line when a part cannot be told."""
    waiting = left.count(NOT_STARTED)
    early = [part for part in left if isinstance(part, NotLearning)]
    if (not left or any(part is None for part in left) or (waiting and not budget)
            or ((waiting or early) and not rates)):
        return []
    mean_rate = sum(rates) / len(rates) if rates else math.nan
    each = [float(part) for part in left if part != NOT_STARTED and not isinstance(part, NotLearning)]
    each += [budget / mean_rate for _ in range(waiting)] + [steps / mean_rate for steps in early]
    seconds = max(sum(each) / max(1, at_once), max(each))
    if not (seconds > 0 and math.isfinite(seconds)):
        return []
    shared = f", {at_once} trial{'s' * (at_once > 1)} at a time" if at_once else " in all (trials at once not fixed)"
    priced = [f"{waiting} trial{'s' * (waiting > 1)} not started"] * bool(waiting) + [
        f"{len(early)} not learning yet"] * bool(early)
    waiting_text = f" ({', '.join(priced)}, at the finished trials' mean pace)" if priced else ""
    return [f"about {seconds / 3600:.1f} h of training left{shared}, at the paces seen{waiting_text}"]
