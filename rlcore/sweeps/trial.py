"""One trial of a sweep: its run folder trained, resumed or evaluated, and what it reports to Tune.

A trial calls :func:`rlcore.training.run.run_training`, the function ``main.py train`` calls, and reports
every logged row to Tune as it comes. Fault tolerance lives in the run folder, not in Tune: a trial
that starts where a checkpoint exists resumes it (so a trial whose worker was killed and that Tune
restarts continues its counters; one killed before its first checkpoint starts over, its tables
cleared), and a trial whose ``model/meta.json`` exists has trained and is not trained again
(``--resume``): it is finished once that file holds its evaluation on unseen seeds, and evaluated first
where the process ended before it. A trial that fails with a user error (a bad value, a diverged loss, a
run folder another process writes) is reported once, not retried: a retry would fail the same way.
TensorFlow-free until a trial trains.
"""
from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.model_meta import read_json
from rlcore.sweeps.sweep import STOP_FILE, TRIALS_LOG, Sweep, trial_name


def run_trial(trial: dict, sweep: dict, modules: dict, report) -> dict:
    """Run (or resume, or skip if finished) one trial's run folder; ``report(metrics)`` is Tune's.

    Returns the final metrics: the evaluation on unseen seeds from ``meta.json``.
    """
    from rlcore.environments import registry

    registry.EXPERIMENT_MODULES.update(modules)  # experiments registered by the caller (tests' toys)
    sweep = Sweep(**sweep)
    run_dir = Path(sweep.folder) / trial_name(trial)
    meta_path = run_dir / "model" / "meta.json"
    meta = read_json(meta_path, "move the trial's folder aside to train it again") if meta_path.is_file() else None
    if meta is not None and not _wants_evaluation(sweep, meta):  # finished before: not run again
        return final_metrics(meta, skipped=True)
    if (Path(sweep.folder) / STOP_FILE).exists():  # the sweep is stopping: a trial not begun stays so
        return {"interrupted": 1, "not_started": 1}
    from rlcore.files.run_lock import hold_run_folder

    log_trial(sweep, trial, "started" if meta is None else "trained but not evaluated: evaluating")
    try:
        with hold_run_folder(run_dir):  # one writer: a trial restarted while its old worker lives is refused
            (run_dir / "worker.pid").write_text(f"{os.getpid()}\n")
            result = (_train_trial(trial, sweep, run_dir, report) if meta is None
                      else final_metrics(_evaluate_trial(sweep, run_dir)))
        log_trial(sweep, trial, "stopped at a checkpoint" if result.get("interrupted") else "finished")
        return result
    except UserError as exc:  # a bad value, a diverged loss, a busy folder: a retry would fail the same way
        log_trial(sweep, trial, f"failed: {exc}")
        return {"error": str(exc), "failed": 1}
    except BaseException as exc:  # the worker's own end (Ray restarts it from the checkpoint)
        log_trial(sweep, trial, f"stopped: {type(exc).__name__}")
        raise


def _wants_evaluation(sweep: Sweep, meta: dict) -> bool:
    """A trained trial whose evaluation on unseen seeds never ran (the process ended between the two)
    and whose sweep asks for one: it is evaluated before it counts as finished, so no trained seed drops
    out of the report."""
    return not meta.get("evaluation") and sweep.final_eval_episodes != 0


def _evaluate_trial(sweep: Sweep, run_dir: Path) -> dict:
    """Evaluate a trained trial's model on unseen seeds into its meta.json; return the meta."""
    from rlcore.environments.registry import get_experiment
    from rlcore.models import shipping

    episodes = shipping.eval_episodes(get_experiment(sweep.experiment), sweep.final_eval_episodes)
    return shipping.record_evaluation(run_dir / "model", episodes, replace=True)  # the trial's own model


def log_trial(sweep: Sweep, trial: dict, event: str) -> None:
    """One line in the sweep's trials.log per start and per end of a trial's attempt (with the worker's
    pid), so restarts and failures can be counted afterwards."""
    line = f"{time.strftime('%Y-%m-%dT%H:%M:%S')} {trial_name(trial)} pid {os.getpid()} {event}\n"
    with open(Path(sweep.folder) / TRIALS_LOG, "a") as log:
        log.write(line)


def _train_trial(trial: dict, sweep: Sweep, run_dir: Path, report) -> dict:
    """The trial's run in ``run_dir``, resumed where a checkpoint exists; its final metrics."""
    from rlcore.models import shipping
    from rlcore.training.run import build_spec, run_training
    from rlcore.training.stopping import Interrupted

    resume = (run_dir / "checkpoint.npz").is_file()
    if not resume:  # a start killed before its first checkpoint: its rows go, the run begins again
        for table in run_dir.glob("*.csv"):
            table.unlink()
    values = {k: v for k, v in trial.items() if k != "seed"}
    command = (f"python main.py sweep {sweep.experiment} {sweep.algo} --name {sweep.name} "
               f"(trial {trial_name(trial)}{', resumed' if resume else ''})")
    spec = build_spec(sweep.experiment, sweep.algo, preset=sweep.preset, seed=int(trial["seed"]),
                      overrides={**sweep.overrides, **values}, run_dir=run_dir, resume=resume,
                      wandb_mode="off", progress=False, command=command,
                      env_kwargs=None if resume else sweep.env_kwargs)
    spec.stop_file = Path(sweep.folder) / STOP_FILE
    last = [0.0]

    def on_progress(row: dict, table: str) -> None:
        now = time.monotonic()
        if table != "metrics" or now - last[0] >= 1.0:  # episodes at most once a second
            last[0] = now
            # finite numbers only: a loss logged as NaN before the first update made Tune's TensorBoard
            # logger print "NaN or Inf found in input tensor." in the sweep's console
            report({f"{table}/{k}" if table != "metrics" else k: v for k, v in row.items()
                    if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)})
    try:
        model_dir = run_training(spec, on_progress)
    except Interrupted:
        return {"interrupted": 1}
    episodes = shipping.eval_episodes(spec.experiment, sweep.final_eval_episodes)
    meta = (shipping.record_evaluation(model_dir, episodes, replace=True) if episodes > 0
            else json.loads((model_dir / "meta.json").read_text()))
    return final_metrics(meta)


def final_metrics(meta: dict, skipped: bool = False) -> dict:
    ev = meta.get("evaluation") or {}
    score = ev.get("success_share", ev.get("mean"))
    return {"final_score": float("nan") if score is None else float(score), "env_steps": meta["env_steps"],
            "wall_seconds": meta["wall_seconds"], "finished": 1, "skipped": int(skipped)}
