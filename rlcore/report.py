"""``main.py report``: per-run results of one or more sweeps, aggregated with confidence intervals.

Statistics follow rliable (Agarwal et al. 2021): mean, median and interquartile mean (IQM) of the
runs' final scores, each with a 95 % stratified percentile bootstrap interval, and the probability
that one sweep's runs beat another's. The aggregates and the probability of improvement are
rliable's own (``rliable.metrics``); the bootstrap is written here because ``rliable.library``
calls ``arch``, and neither arch 7 (it fails to import with pandas 3) nor arch 8 (it no longer
takes rliable's ``random_state`` argument) works with it on Python 3.13 today.

A run's final score is the evaluation on unseen seeds in its ``model/meta.json``: the greedy mean
return, or for Mario the share of episodes that reached the flag. TensorFlow-free.
"""
from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np

from rlcore.atomic import write_atomic
from rlcore.errors import UserError
from rlcore.eval_history import stability_summary, story, story_text
from rlcore.extras import require

AGGREGATES = ("mean", "median", "iqm")


def aggregates(scores: np.ndarray) -> np.ndarray:
    """[mean, median, IQM] of a (runs, tasks) score matrix.

    The mean and IQM are rliable's. The median is the median over runs of each run's mean over
    tasks: rliable's ``aggregate_median`` is the median over *tasks* of the per-task means, which
    for the single task of a sweep group is just the mean again.
    """
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return np.array([metrics.aggregate_mean(scores), float(np.median(scores.mean(axis=1))),
                     metrics.aggregate_iqm(scores)])


def stratified_bootstrap_ci(statistic, *matrices: np.ndarray, reps: int = 5000, level: float = 0.95,
                            seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval of ``statistic(*matrices)`` under rliable's stratified bootstrap.

    Each matrix is (runs, tasks); a resample draws, for every task separately, as many runs with
    replacement as there are (the strata are the tasks). Returns ``(point, [low, high])``.
    """
    rng = np.random.default_rng(seed)
    point = np.asarray(statistic(*matrices))
    draws = []
    for _ in range(reps):
        resampled = []
        for m in matrices:
            runs, tasks = m.shape
            rows = rng.integers(0, runs, (runs, tasks))
            resampled.append(np.take_along_axis(m, rows, axis=0))
        draws.append(statistic(*resampled))
    tail = (1 - level) / 2 * 100
    return point, np.percentile(np.asarray(draws), [tail, 100 - tail], axis=0)


def probability_of_improvement(x: np.ndarray, y: np.ndarray) -> float:
    """P(a run of X scores above a run of Y), ties counting half (rliable's definition)."""
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return float(metrics.probability_of_improvement(x, y))


# --------------------------------------------------------------------------------- run folders
def load_runs(sweep_dir: Path) -> list[dict]:
    """One row per run folder of a sweep: trial, final score, env steps, wall time and the CPU it ran
    on (finished runs only)."""
    sweep_dir = Path(sweep_dir)
    if not sweep_dir.is_dir():
        raise UserError(f"no sweep folder {sweep_dir}")
    rows = []
    for meta_path in sorted(sweep_dir.glob("*/model/meta.json")):
        meta = json.loads(meta_path.read_text())
        ev = meta.get("evaluation") or {}
        score = ev.get("success_share", ev.get("mean"))
        if score is None:
            continue  # trained but not evaluated: nothing to aggregate
        rows.append({"trial": meta_path.parent.parent.name, "seed": meta["seed"], "score": float(score),
                     "eval_episodes": ev.get("episodes"), "env_steps": meta["env_steps"],
                     "wall_seconds": meta["wall_seconds"], "run_dir": meta_path.parent.parent,
                     "cpu": meta.get("cpu"), "time_limit_share": ev.get("time_limit_share"),
                     "story": story(meta_path.parent.parent, meta),
                     "what": f"{meta.get('experiment')} {meta.get('algo')}"})
    if not rows:
        raise UserError(f"{sweep_dir} holds no finished, evaluated run (model/meta.json with an evaluation)")
    kinds = sorted({row["what"] for row in rows})
    if len(kinds) > 1:  # one aggregate over unlike scores would mean nothing
        raise UserError(f"{sweep_dir} holds runs of {' and '.join(kinds)}: a report aggregates one experiment "
                        f"and algorithm per folder; give each its own SWEEP_DIR")
    return rows


#: what ``keep`` copies of a run folder: what the report reads (meta.json, metrics.csv) and the periodic
#: evaluations (evals.csv); a sweep's checkpoints stay behind
KEPT_FILES = ("model/meta.json", "metrics.csv", "evals.csv")


def keep(sweep_dir: Path, dest: Path) -> Path:
    """Copy ``sweep.json`` and, per run, :data:`KEPT_FILES` of ``sweep_dir``
    into ``dest``, a folder git keeps (``results/sweeps/NAME``); a report of ``dest`` then gives the
    same numbers. Returns ``dest``."""
    sweep_dir, dest = Path(sweep_dir), Path(dest)
    runs = load_runs(sweep_dir)  # refuses a folder with no finished run before anything is copied
    copies = [(sweep_dir / "sweep.json", dest / "sweep.json")] if (sweep_dir / "sweep.json").is_file() else []
    for run in runs:
        copies += [(run["run_dir"] / name, dest / run["trial"] / name) for name in KEPT_FILES
                   if (run["run_dir"] / name).is_file()]
    for source, target in copies:
        target.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(target, lambda tmp, source=source: shutil.copyfile(source, tmp))
    return dest


def run_curve(run_dir: Path) -> tuple[np.ndarray, np.ndarray]:
    """One run's (env steps, 100-episode average return) at each episode's end, from metrics.csv."""
    with open(Path(run_dir) / "metrics.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return (np.array([float(r["env_steps"]) for r in rows]),
            np.array([float(r["av_latest_points"]) for r in rows]))


def learning_curve(run_dirs: list[Path], points: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """(env steps grid, [runs, points] 100-episode average return), each run interpolated.

    The grid ends where the shortest run ends, so every point aggregates every run.
    """
    curves = [run_curve(d) for d in run_dirs]
    end = min(s[-1] for s, _ in curves)
    grid = np.linspace(0, end, points)
    return grid, np.stack([np.interp(grid, s, v) for s, v in curves])


# --------------------------------------------------------------------------------------- report
def setting_of(trial: str) -> str:
    """``lr=0.0001__seed=3`` -> ``lr=0.0001``: the grid values, which group runs across seeds."""
    return "__".join(part for part in trial.split("__") if not part.startswith("seed="))


def summarize(sweep_dirs: list[Path], reps: int = 5000) -> dict:
    """Everything ``main.py report`` prints, as numbers: one group per sweep and grid setting."""
    groups = []
    for folder in sweep_dirs:
        runs = load_runs(folder)
        settings = sorted({setting_of(r["trial"]) for r in runs})
        for setting in settings:
            members = [r for r in runs if setting_of(r["trial"]) == setting]
            scores = np.array([[r["score"]] for r in members])
            point, ci = stratified_bootstrap_ci(aggregates, scores, reps=reps)
            label = Path(folder).name + (f" [{setting}]" if setting else "")
            groups.append({"folder": Path(folder), "label": label, "runs": members,
                           "aggregates": {name: (float(point[i]), float(ci[0][i]), float(ci[1][i]))
                                          for i, name in enumerate(AGGREGATES)}})
    result = {"sweeps": groups}
    if len(groups) == 2:
        x, y = (np.array([[r["score"]] for r in g["runs"]]) for g in groups)
        point, ci = stratified_bootstrap_ci(lambda a, b: probability_of_improvement(a, b), x, y, reps=reps)
        result["probability_of_improvement"] = (float(point), float(ci[0]), float(ci[1]))
    return result


def share_text(share: float | None) -> str:
    return "–" if share is None else f"{share:.0%}"


def markdown(result: dict) -> str:
    lines = []
    for s in result["sweeps"]:
        lines += [f"## {s['label']} ({s['folder']})", "",
                  "| run | seed | final score (unseen seeds) | to time limit | env steps | wall | env steps/s | CPU |",
                  "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
        lines += [f"| {r['trial']} | {r['seed']} | {r['score']:.3f} | {share_text(r.get('time_limit_share'))} "
                  f"| {r['env_steps']:,} | {r['wall_seconds']:.0f} s | {r['env_steps'] / max(r['wall_seconds'], 1e-9):,.0f} "
                  f"| {r.get('cpu') or 'not recorded'} |" for r in s["runs"]]
        lines += ["", f"| over {len(s['runs'])} runs | point | 95% CI (stratified bootstrap) |",
                  "| --- | ---: | --- |"]
        lines += [f"| {name} | {p:.3f} | [{lo:.3f}, {hi:.3f}] |" for name, (p, lo, hi) in s["aggregates"].items()]
        lines += ["", *stability_lines(s["runs"]), ""]
    if "probability_of_improvement" in result:
        p, lo, hi = result["probability_of_improvement"]
        first, second = (s["label"] for s in result["sweeps"])
        lines += [f"P({first} > {second}) = {p:.3f} [{lo:.3f}, {hi:.3f}]", ""]
    return "\n".join(lines)


def stability_lines(runs: list[dict]) -> list[str]:
    """What the runs' periodic evaluations (on selection seeds) say: collapses and the weights kept
    (:mod:`rlcore.eval_history` defines a collapse)."""
    stories = [r["story"] for r in runs]
    if not any(st.evaluations for st in stories):
        return ["No periodic evaluations: each model holds its run's last weights."]
    lines = [f"Periodic evaluations (selection seeds): {stability_summary(stories)}", ""]
    lines += [f"- {r['trial']}: {story_text(r['story'])}" for r in runs]
    return lines


def _iqm_band(curves: np.ndarray, reps: int) -> tuple[list, list, list]:
    """IQM over runs at each column of a [runs, points] matrix, with its 95 % bootstrap interval."""
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra
    iqm, low, high = [], [], []
    for j in range(curves.shape[1]):
        point, ci = stratified_bootstrap_ci(metrics.aggregate_iqm, curves[:, j:j + 1], reps=reps)
        iqm.append(float(point))
        low.append(float(ci[0]))
        high.append(float(ci[1]))
    return iqm, low, high


def _save_figure(fig, ax, ylabel: str, out: Path) -> Path:
    import matplotlib.pyplot as plt

    from rlcore.atomic import atomic_path

    ax.set_xlabel("env steps")
    ax.set_ylabel(ylabel)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out = Path(out)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
    return out


def _figure():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(8, 4.5))


def plot_curves(result: dict, out: Path, reps: int = 1000) -> Path:
    """IQM of the 100-episode average return over env steps, with its 95 % CI band, per sweep.

    The band covers the env steps every run reached; each run is also drawn in full, thin.
    """
    fig, ax = _figure()
    for s in result["sweeps"]:
        grid, curves = learning_curve([r["run_dir"] for r in s["runs"]])
        iqm, low, high = _iqm_band(curves, reps)
        line, = ax.plot(grid, iqm, lw=2, label=f"{s['label']}: IQM of {len(s['runs'])} runs, 95% CI")
        ax.fill_between(grid, low, high, color=line.get_color(), alpha=0.25)
        for r in s["runs"]:  # each run in full, since runs with an episode budget end at different steps
            ax.plot(*run_curve(r["run_dir"]), color=line.get_color(), lw=0.7, alpha=0.35)
    return _save_figure(fig, ax, "100-episode average return", out)


def plot_evals(result: dict, out: Path, reps: int = 1000) -> Path | None:
    """IQM of the periodic evaluations' mean return (selection seeds) over env steps, 95 % CI band, per
    sweep; each run drawn thin. ``None`` (no file) when no run has periodic evaluations.

    The band covers the evaluation steps every run reached; a collapse shows as one run's dip.
    """
    sweeps = [s for s in result["sweeps"] if all(r["story"].evaluations for r in s["runs"])]
    if not sweeps:
        return None
    from rlcore.eval_history import read_evals

    fig, ax = _figure()
    for s in sweeps:
        runs = [read_evals(r["run_dir"]) for r in s["runs"]]
        steps = sorted(set.intersection(*({e.env_steps for e in evals} for evals in runs)))
        line = None
        if steps:
            curves = np.array([[next(e.mean for e in evals if e.env_steps == x) for x in steps] for evals in runs])
            iqm, low, high = _iqm_band(curves, reps)
            line, = ax.plot(steps, iqm, lw=2, label=f"{s['label']}: IQM of {len(runs)} runs, 95% CI")
            ax.fill_between(steps, low, high, color=line.get_color(), alpha=0.25)
        for evals in runs:
            ax.plot([e.env_steps for e in evals], [e.mean for e in evals], lw=0.7, alpha=0.45,
                            color=line.get_color() if line else None)
    return _save_figure(fig, ax, "periodic evaluation, mean return", out)
