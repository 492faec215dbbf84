"""``main.py status SWEEP``: a line per trial of a sweep (finished with its score, at a checkpoint with
its pace and last evaluation, or not started), and the hours of training the sweep has left at the paces
seen. TensorFlow-free."""
from __future__ import annotations

import json
import math
from pathlib import Path

from rlcore.status import NO_BUDGET, evaluation_lines, pace, pace_text


def sweep_status(folder: str | Path) -> list[str]:
    """What ``main.py status SWEEP`` prints: the sweep, then a line per trial (finished with its final
    score, stopped or running at a checkpoint with its last periodic evaluation, or not started)."""
    from rlcore.checkpoint import read_checkpoint_state
    from rlcore.sweep import Sweep, final_metrics, trial_name
    from rlcore.trainers.spec import CHECKPOINT_FILE

    sweep = Sweep.load(Path(folder))
    trials = [trial_name(t) for t in sweep.trials()]
    lines = [f"sweep {sweep.name}: {sweep.experiment} {sweep.algo}, {len(trials)} trials"]
    budgets: set = set()  # the env-step budgets the trials' records hold (one, unless a grid sets it)
    left: list = []  # per trial not finished: seconds left, "not started", or None (cannot be told)
    rates: list[float] = []  # env steps/s of the finished trials over their whole runs
    for name in trials:
        trial = Path(sweep.folder) / name
        meta = trial / "model" / "meta.json"
        if meta.is_file():
            record = json.loads(meta.read_text())
            budgets.add((record.get("config") or {}).get("max_env_steps"))
            if record.get("wall_seconds"):
                rates.append(record["env_steps"] / record["wall_seconds"])
            final = final_metrics(record)  # as the sweep reports it (Mario: flag share)
            lines.append(f"  {name}: finished at {final['env_steps']:,} env steps"
                         + (f", final score {final['final_score']:.2f} on unseen seeds"
                            if not math.isnan(final["final_score"]) else ""))  # NaN: not evaluated
        elif (trial / CHECKPOINT_FILE).is_file():
            state = read_checkpoint_state(trial / CHECKPOINT_FILE)
            budgets.add((state.get("config") or {}).get("max_env_steps"))
            last = evaluation_lines(trial / "evals.csv", last=1)
            text = pace_text(trial / "metrics.csv", state)
            lines.append(f"  {name}: checkpoint at {state['env_steps']:,} env steps, "
                         f"{state.get('wall_seconds', 0) / 3600:.1f} h" + (f", {text}" if text else "")
                         + (f"; last {last[0]}" if last else ""))
            measured = pace(trial / "metrics.csv", state)
            left.append(measured[1] if measured else None)
        else:
            lines.append(f"  {name}: not started")
            left.append("not started")
    budgets.discard(None)  # a record without its config says nothing of the budget
    budget = budgets.pop() if len(budgets) == 1 else None
    return lines + _sweep_time_left(left, rates, budget if budget and budget < NO_BUDGET else None,
                                    sweep.max_concurrent)


def _sweep_time_left(left: list, rates: list[float], budget: int | None, at_once: int) -> list[str]:
    """The sweep's hours of training left: each running trial's at its pace lately, each trial not started
    at the finished trials' mean pace over its whole env-step budget, shared by ``at_once`` trials at a time
    (0: as many as the CPUs allow, unknown here, so the sum is given). ``budget``: the trials' env-step budget
    as their records hold it. No line when a part cannot be told."""
    waiting = left.count("not started")
    if not left or any(part is None for part in left) or (waiting and not (rates and budget)):
        return []
    seconds = sum(part for part in left if part != "not started")
    if waiting:
        seconds += waiting * budget / (sum(rates) / len(rates))
    if seconds <= 0:
        return []
    shared = f", {at_once} trial{'s' * (at_once > 1)} at a time" if at_once else " in all (trials at once not fixed)"
    waiting_text = (f" ({waiting} trial{'s' * (waiting > 1)} not started, at the finished trials' mean pace)"
                    if waiting else "")
    return [f"about {seconds / 3600 / max(1, at_once):.1f} h of training left{shared}, at the paces seen{waiting_text}"]
