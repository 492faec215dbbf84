"""The figures of ``main.py report``: learning curves (the 100-episode average of each run's training
episodes) and periodic evaluations over env steps, each an IQM over runs with its 95 % stratified bootstrap
band (runs resampled as rliable resamples them for a curve), every run drawn thin beside it. TensorFlow-free."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from rlcore.host.extras import require
from rlcore.records.score_words import count

#: metrics.csv's columns a report draws over env steps: the 100-episode average return, and for a task with a
#: goal (Mario's flag) the share of the last 100 episodes from the start that reached it (the stop rule's)
AVERAGE_RETURN, SUCCESS_SHARE = "av_latest_points", "success_share"


def run_curve(run_dir: Path, column: str = AVERAGE_RETURN) -> tuple[np.ndarray, np.ndarray]:
    """One run's (env steps, ``column``) at each episode's end, from metrics.csv (rows without a value
    of it skipped)."""
    with open(Path(run_dir) / "metrics.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r.get(column) not in (None, "")]
    return (np.array([float(r["env_steps"]) for r in rows]), np.array([float(r[column]) for r in rows]))


def has_column(run_dir: Path, column: str) -> bool:
    """Whether a run's metrics.csv has ``column`` (SUCCESS_SHARE: the runs of a task with a goal)."""
    with open(Path(run_dir) / "metrics.csv", newline="") as f:
        return column in next(csv.reader(f), [])


def _iqm_band(curves: np.ndarray, reps: int, seed: int = 0) -> tuple[list, list, list]:
    """IQM over runs at each column of a [runs, points] matrix, with its 95 % bootstrap interval.

    As rliable bootstraps a curve: a resample draws runs with replacement, each drawn run bringing its
    whole curve, and every point's IQM (rliable's ``aggregate_iqm``: the mean of the middle half, a 25 %
    trimmed mean) is taken on that one resample; the band is the 2.5th and 97.5th percentiles over
    ``reps`` resamples. All resamples at once, as one [reps, runs, points] array: one trimmed mean per
    point and resample, each a scipy call, took most of a report's time (120 points x 1,000 reps)."""
    require("rliable.metrics", "A sweep report")  # the sweep extra (it brings scipy)
    from scipy.stats import trim_mean

    runs = curves.shape[0]
    rows = np.random.default_rng(seed).integers(0, runs, (reps, runs))
    draws = trim_mean(curves[rows], 0.25, axis=1)  # [reps, points]
    low, high = np.percentile(draws, [2.5, 97.5], axis=0)
    return [float(v) for v in trim_mean(curves, 0.25, axis=0)], [float(v) for v in low], [float(v) for v in high]


def _save_figure(fig, ax, ylabel: str, out: Path) -> Path:
    from rlcore.records.plotting import write_png

    ax.set_xlabel("env steps")
    ax.set_ylabel(ylabel)
    ax.legend()
    ax.grid(alpha=0.3)
    return write_png(fig, out, dpi=110, then="report again")


def _figure():
    from rlcore.records.plotting import plt  # matplotlib without a display (Agg)

    return plt.subplots(figsize=(8, 4.5))


def plot_curves(result: dict, out: Path, reps: int = 1000, column: str = AVERAGE_RETURN) -> Path | None:
    """IQM of the 100-episode average return (or another of metrics.csv's ``column``) over env steps, with
    its 95 % CI band, per sweep. ``None`` (no file) where no sweep's runs all log the column.

    The band covers the env steps every run reached (each run interpolated on 40 points up to where the
    shortest ends, so every point aggregates every run); each run is also drawn in full, thin.
    """
    sweeps = [s for s in result["sweeps"] if all(has_column(r["run_dir"], column) for r in s["runs"])]
    if not sweeps:
        return None
    fig, ax = _figure()
    for s in sweeps:
        runs = [run_curve(r["run_dir"], column) for r in s["runs"]]  # (env steps, values) each
        grid = np.linspace(0, min(steps[-1] for steps, _ in runs), 40)
        iqm, low, high = _iqm_band(np.stack([np.interp(grid, *run) for run in runs]), reps)
        line, = ax.plot(grid, iqm, lw=2, label=f"{s['label']}: IQM of {count(len(runs), 'run')}, 95% CI")
        ax.fill_between(grid, low, high, color=line.get_color(), alpha=0.25)
        for run in runs:  # each run in full, since runs with an episode budget end at different steps
            ax.plot(*run, color=line.get_color(), lw=0.7, alpha=0.35)
    if column == SUCCESS_SHARE:
        word, stop = _goal(sweeps)
        if stop:  # where the runs' stop rule ends them
            ax.axhline(stop, color="0.4", lw=0.8, ls="--", label=f"stop rule: {stop:.0%} of the last 100")
        ax.set_ylim(-0.02, 1.02)
        return _save_figure(fig, ax, f"share of the last 100 episodes\nthat reached the {word}", out)
    return _save_figure(fig, ax, "100-episode average return", out)


def _goal(sweeps: list[dict]) -> tuple[str, float | None]:
    """What the runs' successful episodes reach (Mario: flag, or axe on x-4; ``load_runs``'s ``goal``), and the
    success share their stop rule ends them at (``--stop-success-share``), where all runs have the same."""
    words = {r.get("goal") or "goal" for s in sweeps for r in s["runs"]}
    stops = {r.get("stop_share") for s in sweeps for r in s["runs"]}
    return (words.pop() if len(words) == 1 else "goal"), (stops.pop() if len(stops) == 1 else None)


def plot_evals(result: dict, out: Path, reps: int = 1000) -> Path | None:
    """IQM of the periodic evaluations' mean return (selection seeds) over env steps, 95 % CI band, per
    sweep; each run drawn thin. ``None`` (no file) when no run has periodic evaluations.

    The band covers the evaluation steps every run reached; a collapse shows as one run's dip.
    """
    sweeps = [s for s in result["sweeps"] if all(r["story"].evaluations for r in s["runs"])]
    if not sweeps:
        return None
    from rlcore.records.eval_history import read_evals

    fig, ax = _figure()
    for s in sweeps:
        runs = [read_evals(r["run_dir"]) for r in s["runs"]]
        steps = sorted(set.intersection(*({e.env_steps for e in evals} for evals in runs)))
        if len(steps) > 40:  # a band of at most 40 points, as the learning curve's (600 evaluations: CartPole A2C)
            steps = [steps[i] for i in np.linspace(0, len(steps) - 1, 40).round().astype(int)]
        line = None
        if steps:
            curves = np.array([[next(e.mean for e in evals if e.env_steps == x) for x in steps] for evals in runs])
            iqm, low, high = _iqm_band(curves, reps)
            line, = ax.plot(steps, iqm, lw=2, label=f"{s['label']}: IQM of {count(len(runs), 'run')}, 95% CI")
            ax.fill_between(steps, low, high, color=line.get_color(), alpha=0.25)
        for evals in runs:
            ax.plot([e.env_steps for e in evals], [e.mean for e in evals], lw=0.7, alpha=0.45,
                            color=line.get_color() if line else None)
    return _save_figure(fig, ax, "periodic evaluation, mean return", out)


def plot_critic(result: dict, out: Path) -> Path | None:
    """Each run's mean Q over env steps (the running median of :func:`rlcore.records.critic_trace.critic_trace`),
    one line per run that logs Q, on a log scale (linear within +-1, where Q may change sign), so a critic
    that diverges stands out by orders of magnitude. ``None`` (no file) when no run logs Q (A2C, PPO)."""
    from rlcore.records.critic_trace import WINDOW, critic_trace

    lines = [(f"{s['label']} {r['trial']}" if len(result["sweeps"]) > 1 else r["trial"], critic_trace(r["run_dir"]))
             for s in result["sweeps"] for r in s["runs"]]
    lines = [(label, t) for label, t in lines if t is not None]
    if not lines:
        return None
    fig, ax = _figure()
    for label, t in lines:
        ax.plot(t.env_steps, t.q, lw=1.0, label=label)
    ax.set_yscale("symlog", linthresh=1.0)
    return _save_figure(fig, ax, f"mean Q of the training batches\n(median of {WINDOW} episodes)", out)
