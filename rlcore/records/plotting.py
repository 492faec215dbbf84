"""Training plots as PNG (matplotlib, no display needed)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from rlcore.errors import UserError  # noqa: E402
from rlcore.files.atomic import atomic_path  # noqa: E402

ABOUT_KEYS = ("experiment", "algo", "preset", "seed", "config")  # what a plot's title and window need


def plot_run(run_dir: str | Path, out_dir: str | Path, experiment, about: dict) -> list[Path]:
    """Every plot a run's CSV tables allow, written to ``out_dir``; the first is the score plot.

    ``about`` says what the run trained (``algo``, ``preset``, ``seed``, ``config``), as a checkpoint's
    state or a ``meta.json`` does. Reads ``metrics.csv`` (one row per episode) once and, when present,
    ``evals.csv``; experiments with a goal that measures progress (``Goal.progress_key``) also get the
    progress and endings plots, and with a cause of failure (``Goal.cause_key``) the Deaths plot.
    """
    missing = [key for key in ABOUT_KEYS if key not in about]
    if missing:
        raise UserError(f"{run_dir}: its checkpoint or meta.json lacks {', '.join(missing)}; "
                        "not a run of this package")
    run_dir, out_dir, algo = Path(run_dir), Path(out_dir), about["algo"]
    title = plot_title(experiment, about)
    window = about["config"].get("window", 100)
    prefix = experiment.plot_prefix or experiment.name
    label = experiment.score_label
    metrics, evals = run_dir / "metrics.csv", run_dir / "evals.csv"
    goal = experiment.goal
    df = read_table(metrics, "episode", "total_points", "av_latest_points")
    full = full_episodes(df, experiment.curriculum.partial_key if experiment.curriculum else None)
    out = [plot_episode_scores(df, full, out_dir / f"{prefix}_Train_{algo}.png", title, experiment.solved_score, label)]
    if goal and goal.progress_key:
        if goal.progress_key not in df:  # checked after the score plot, as its own read of the table did
            raise UserError(f"{metrics} is damaged or not one of ours (no column {goal.progress_key})")
        out.append(plot_progress(full, out_dir / f"{prefix}_Progress_{algo}.png", title, goal.progress_key, window))
        out.append(plot_endings(full, out_dir / f"{prefix}_Endings_{algo}.png", title, goal.progress_key))
    if goal and goal.cause_key and goal.cause_key in df and df[goal.cause_key].notna().any():
        out.append(plot_causes(df, out_dir / f"{prefix}_Deaths_{algo}.png", title, goal.cause_key, goal.cause_name))
    if evals.exists():
        out.append(plot_evaluations(evals, out_dir / f"{prefix}_Eval_{algo}.png", title,
                                    experiment.solved_score, label))
    return out


def plot_title(experiment, about: dict) -> str:
    """What trained: experiment, algorithm, the level for one-model-per-level experiments, preset, seed."""
    fields = experiment.shipped_by.fields if experiment.shipped_by else ()
    level = "-".join(str(about["config"].get(f)) for f in fields)  # Mario: "2-1"
    return (f"{experiment.name} {about['algo']}{' ' + level if level else ''} "
            f"({about['preset']} preset, seed {about['seed']})")


def plot_episode_scores(df: pd.DataFrame, full: pd.DataFrame, png_path: str | Path, title: str,
                        solved_score: float | None = None, score_label: str = "return") -> Path:
    """Score per episode (metrics.csv's ``df``), its moving average and the solved line, as in article 000's
    figure. Only the episodes from the start (``full``, :func:`full_episodes`: Mario's restarts left out) are
    drawn, and the average is taken over them."""
    if len(full) < len(df):  # the logged average counted every episode: take it over these only
        df = full.assign(av_latest_points=full["total_points"].rolling(100, min_periods=1).mean())
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(df["episode"], df["total_points"], color="tab:blue", linewidth=1, alpha=0.6, label="Score")
    ax.plot(df["episode"], df["av_latest_points"], color="tab:orange", linewidth=2, linestyle="--",
            label="Average score (last 100)")
    if solved_score is not None:
        ax.axhline(solved_score, color="tab:red", linewidth=2, linestyle="--", label="Solved requirement")
    ax.set_xlabel("episode")
    ax.set_ylabel(score_label)
    return _save(fig, ax, title, png_path)


def plot_evaluations(csv_path: str | Path, png_path: str | Path, title: str,
                     solved_score: float | None = None, score_label: str = "return") -> Path:
    """Periodic greedy evaluation: mean +- std against env steps (article 002's test-reward curve)."""
    df = read_table(csv_path, "env_steps", "eval_mean", "eval_std")
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(df["env_steps"], df["eval_mean"], color="tab:blue", linewidth=2, label="Evaluation mean")
    ax.fill_between(df["env_steps"], df["eval_mean"] - df["eval_std"], df["eval_mean"] + df["eval_std"],
                    color="tab:blue", alpha=0.2, label="+- std")
    if solved_score is not None:
        ax.axhline(solved_score, color="tab:red", linewidth=2, linestyle="--", label="Solved requirement")
    ax.set_xlabel("env steps")
    ax.set_ylabel(f"greedy {score_label}")
    return _save(fig, ax, title, png_path)


def plot_progress(df: pd.DataFrame, png_path: str | Path, title: str, progress_key: str, window: int = 100) -> Path:
    """Episodes with a goal (Mario's flag): how far each got (``progress_key``, with its moving
    average) and, on the right axis, the share of the last ``window`` episodes that succeeded.
    ``df``: metrics.csv's episodes from the start (:func:`full_episodes`; Mario's restarts start further in)."""
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(df["episode"], df[progress_key], color="tab:blue", linewidth=1, alpha=0.5, label=progress_key)
    ax.plot(df["episode"], df[progress_key].rolling(window, min_periods=1).mean(), color="tab:orange",
            linewidth=2, linestyle="--", label=f"average (last {window})")
    ax.set_xlabel("episode")
    ax.set_ylabel(progress_key)
    if "success_share" in df:
        share = ax.twinx()
        share.plot(df["episode"], 100 * df["success_share"], color="tab:green", linewidth=2,
                   label=f"success share (last {window}), %")
        share.set_ylim(0, 100)
        share.set_ylabel("success share, %")
        share.legend(loc="upper left")
    return _save(fig, ax, title, png_path)


def ending_shares(progress: np.ndarray, block: int, bins: int = 40) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where episodes ended, over training: episodes in blocks of ``block``, ``progress`` (one value
    per episode, e.g. Mario's x at the end) cut into ``bins`` equal bins from 0 to its maximum.

    Returns (first episode of each block, bin edges, [bins, blocks] share of the block's episodes
    that ended in each bin; each column sums to 1).
    """
    progress = np.asarray(progress, dtype=float)
    edges = np.linspace(0.0, max(float(np.nanmax(progress)), 1.0), bins + 1)
    starts = np.arange(0, len(progress), block)
    shares = np.zeros((bins, len(starts)))
    for j, start in enumerate(starts):
        counts, _ = np.histogram(progress[start:start + block], bins=edges)
        shares[:, j] = counts / max(counts.sum(), 1)
    return starts + 1, edges, shares


def plot_endings(df: pd.DataFrame, png_path: str | Path, title: str, progress_key: str, blocks: int = 60) -> Path:
    """A map of where episodes ended (``progress_key``, e.g. Mario's x) over training: the dark rows
    are where the agent keeps dying or stalling. Episodes with a ``stalled`` mark add its share.
    ``df``: metrics.csv's episodes from the start (:func:`full_episodes`; Mario's restarts start further in)."""
    block = max(1, int(np.ceil(len(df) / blocks)))
    starts, edges, shares = ending_shares(df[progress_key].to_numpy(), block)
    fig, ax = plt.subplots(figsize=(9, 5))
    image = ax.imshow(shares, origin="lower", aspect="auto", cmap="magma_r", interpolation="nearest",
                      extent=(starts[0], starts[-1] + block, edges[0], edges[-1]))
    fig.colorbar(image, ax=ax, pad=0.09, label=f"share of the {block} episodes of a column")
    ax.set_xlabel("episode")
    ax.set_ylabel(f"{progress_key} at the episode's end")
    if "stalled" in df and df["stalled"].notna().any():
        stalled = df["stalled"].groupby(np.arange(len(df)) // block).mean()
        share = ax.twinx()
        share.plot(starts + block / 2, 100 * stalled.to_numpy(), color="tab:cyan", linewidth=1.5,
                   label="ended by the stall limit, %")
        share.set_ylim(0, 100)
        share.set_ylabel("stalled, %")
        share.legend(loc="upper left")
    ax.set_title(title)
    return write_png(fig, png_path)


def cause_shares(causes: pd.Series, block: int, most: int = 6) -> pd.DataFrame:
    """What ended the failures, over training: the share of each cause (words) among the failures of
    each block of ``block`` episodes (a row per block, the ``most`` commonest causes, then "other";
    each row sums to 1, a block without failures is NaN). ``causes`` is NaN where an episode did
    not fail (or before the cause was logged)."""
    blocks = pd.Series(np.arange(len(causes)) // block, index=causes.index)
    named = causes.dropna()
    common = list(named.value_counts().index[:most])
    named = named.where(named.isin(common), "other")
    shares = pd.crosstab(blocks[named.index], named, normalize="index")
    columns = common + (["other"] if "other" in shares.columns else [])
    shares = shares.reindex(index=range(int(blocks.max()) + 1 if len(blocks) else 0), columns=columns)
    return shares.rename_axis(index=None, columns=None)


def plot_causes(df: pd.DataFrame, png_path: str | Path, title: str, cause_key: str, cause_name,
                blocks: int = 60) -> Path:
    """What ends the failed episodes (``cause_key``, e.g. Mario's killed_by) over training, as
    shares of the failures of each block of episodes, from the first episode that logged a cause;
    ``df``: metrics.csv's rows, restarted episodes included."""
    df = df.loc[df[cause_key].first_valid_index():]  # a run resumed by newer code logs it from there on
    causes = df[cause_key].map(cause_name, na_action="ignore")
    block = max(20, int(np.ceil(len(df) / blocks)))  # fewer blocks while a few hundred are logged
    shares = cause_shares(causes, block)
    starts = df["episode"].to_numpy()[::block][:len(shares)]
    values = 100 * shares.fillna(0).to_numpy()
    edges = np.append(starts, starts[-1] + block)  # each block's shares drawn over its whole width
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.stackplot(edges, np.vstack([values, values[-1:]]).T, labels=list(shares.columns), step="post",
                 colors=plt.get_cmap("tab10").colors[:shares.shape[1]])
    ax.set_xlabel("episode")
    ax.set_ylabel(f"share of the failures in each {block} episodes, %")
    ax.set_ylim(0, 100)
    ax.set_xlim(edges[0], edges[-1])
    ax.legend(loc="upper left", fontsize="small", title=cause_key)
    ax.set_title(title)
    return write_png(fig, png_path)


def full_episodes(df: pd.DataFrame, partial_key: str | None) -> pd.DataFrame:
    """The rows of episodes that started where evaluations start (not marked by ``partial_key``)."""
    return df[df[partial_key] != 1] if partial_key and partial_key in df else df


def read_table(csv_path: str | Path, *columns: str) -> pd.DataFrame:
    """The CSV table at ``csv_path``, checked to hold ``columns``; a damaged one is a clear error."""
    try:
        df = pd.read_csv(csv_path)
    except (pd.errors.EmptyDataError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise UserError(f"{csv_path} is damaged or not one of ours ({type(exc).__name__})") from None
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise UserError(f"{csv_path} is damaged or not one of ours (no column {', '.join(missing)})")
    return df


def _save(fig, ax, title, png_path) -> Path:
    """A line plot's title, grid and legend, then the file."""
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right")
    return write_png(fig, png_path)


def write_png(fig, png_path: str | Path, dpi: int = 100, then: str = "resume the run") -> Path:
    """The figure as a PNG, written whole or not at all, then closed; ``then``: what to do after a failed write."""
    fig.tight_layout()
    with atomic_path(png_path, then) as tmp:
        fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    return Path(png_path)
