"""``main.py status RUN_DIR``: where a run stands, in a few lines, from its CSV tables.

First what the run is and how far it got, with the pace of a run in progress and the hours left at that
pace to its env-step budget (:mod:`rlcore.records.pace`), and where it was resumed and what each resume changed
(:func:`resumes_lines`), and where a success-share stop rule stands (:func:`goal_line`). Then, for a run that lasts many sessions (a Mario level): per block of
episodes that started where evaluations start, the success share, the mean progress and the mean
return; the episodes that started elsewhere (Mario's restarts) beside them, with where they started;
and what ended the failures. For a run without a goal (Minitaur): per block, the mean return, episode length and info
keys (metres walked), and the last periodic evaluations. For a PPO run, per block of rollouts
(``rollouts.csv``): the same success shares beside the size of PPO's updates (entropy, approx KL,
clip fraction), the learning rate and the entropy weight, to see what a change of settings did. It
reads the same tables as ``main.py plot`` and works on a run that is training, interrupted or
finished. TensorFlow-free.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from rlcore.files.model_meta import read_json
from rlcore.models.shipping import model_name
from rlcore.records.pace import pace_text
from rlcore.records.plotting import full_episodes, read_table
from rlcore.records.score_words import hours, stop_words
from rlcore.training.evaluation import count_causes


def run_status(run_dir: str | Path, experiment, about: dict, block: int = 200,
               blocks: int = 6, rollout_block: int = 20) -> list[str]:
    """The lines ``main.py status`` prints: a headline from ``about`` (a checkpoint's state or a
    model's meta.json), then one line per block of ``block`` full episodes, the last ``blocks`` of
    them, then the commonest causes of failure over those blocks' span (all episodes), then the last
    ``blocks`` blocks of ``rollout_block`` rollouts, then the last periodic evaluations."""
    df = read_table(Path(run_dir) / "metrics.csv", "episode", "env_steps", "total_points")
    pace = pace_text(Path(run_dir) / "metrics.csv", about) if "returns" in about else None  # a checkpoint's
    goal = goal_line(about, experiment) if "returns" in about else None
    lines = [headline(about, experiment) + (f"; {pace}" if pace else "")] + resumes_lines(about) + ([goal] if goal else [])
    full = full_episodes(df, experiment.curriculum.partial_key if experiment.curriculum else None)
    recent = full.tail(block * blocks)
    if recent.empty:
        return lines + ["no episode from the start logged yet"]
    span = df[df["episode"] >= recent["episode"].iloc[0]]
    for part in _blocks(recent, block):
        lines.append(block_line(experiment, part, _partial_between(df, experiment, part)))
    causes = cause_line(experiment, span)
    return (lines + ([causes] if causes else []) + rollout_lines(Path(run_dir) / "rollouts.csv", experiment,
                                                                 rollout_block, blocks)
            + evaluation_lines(Path(run_dir) / "evals.csv"))


def headline(about: dict, experiment) -> str:
    """What the run is and how far it got."""
    episodes = about.get("episodes", len(about.get("returns", [])))
    where = "checkpoint" if "returns" in about else "model"  # a checkpoint's state keeps every return
    text = (f"{about['experiment']} {about['algo']} ({about.get('preset', '?')} preset, "
            f"seed {about.get('seed', '?')}): {where} at {about['env_steps']:,} env steps, "
            f"{episodes:,} episodes, {hours(about.get('wall_seconds', 0))} of training")
    if "stopped_by" in about:
        text += "; stopped by " + stop_words(about["stopped_by"], about["experiment"], model_name(experiment, about),
                                             (about.get("config") or {}).get("window", 100))
    return text


def goal_line(about: dict, experiment) -> str | None:
    """Where a run's success-share stop rule stands (``--stop-success-share``): ``stops once flag_get comes
    in 90% of the last 100 episodes from the start: now 57 of 100 (57%)``; None without one."""
    config = about.get("config") or {}
    share, window = config.get("stop_success_share") or 0.0, config.get("window") or 0
    if not (share and window):
        return None
    recent = list(about.get("successes") or [])[-window:]  # counted episodes only, as the rule reads them
    word = experiment.goal.success_key if experiment.goal else "success"
    now = (f"now {sum(map(bool, recent))} of {len(recent)} ({np.mean(recent):.0%})" if len(recent) >= window
           else f"{len(recent)} of those {window} episodes so far")
    return f"stops once {word} comes in {share:.0%} of the last {window} episodes from the start: {now}"


def resumes_lines(about: dict, most: int = 6) -> list[str]:
    """Where the run was resumed and what each resume changed (``command_starts``), so a run meant to
    follow one recipe shows that it did: none for a run never resumed; of many, the first and the
    ``most`` latest."""
    from rlcore.hyperparams.flags import change_text
    from rlcore.records.commands import command_starts

    resumes = command_starts(about)[1:]
    if not resumes:
        return []
    times = f"resumed {len(resumes)} time{'s' * (len(resumes) > 1)}"
    if not any(isinstance(start, dict) for start in resumes):  # a record from before 2026-11-27
        return [f"{times}; where and what {'it' if len(resumes) == 1 else 'they'} changed is not recorded "
                f"(runs recorded it from 2026-11-27 on); the commands are in meta.json"]
    at = [f"{start['env_steps']:,}" if isinstance(start, dict) else "?" for start in resumes]
    changes = [f"{change_text(name, before, after)} at {where}"
               for where, start in zip(at, resumes) if isinstance(start, dict)
               for name, (before, after) in sorted((start.get("changed") or {}).items())]
    unrecorded = sum(not isinstance(start, dict) or "changed" not in start for start in resumes)
    said = ["changed " + "; ".join(changes) if changes else "no setting changed"] if unrecorded < len(resumes) else []
    if unrecorded:
        who = "it" if len(resumes) == 1 else "they" if unrecorded == len(resumes) else f"{unrecorded} of them"
        said.append(f"what {who} changed is not recorded "
                    f"(resumes recorded it from 2026-11-27 on)")
    if len(changes) > most:  # a run steered by hand (Mario 2-2: about twenty changes): the latest
        said[0] = f"changed {len(changes) - most} settings earlier, then " + "; ".join(changes[-most:])
    shown = ", ".join(at) if len(at) <= most else f"{at[0]}, ..., {', '.join(at[-most + 1:])}"
    return [f"{times} (at env step {shown}): " + "; ".join(said)]


def run_record(run_dir: str | Path) -> dict | None:
    """What a run folder says it trained, the newest record first: its checkpoint's state when that is
    past its model (a run in progress, or a finished run resumed with a larger budget), else its model's
    meta.json (or a shipped model folder's own); None when it holds neither."""
    from rlcore.files.checkpoint import read_checkpoint_state
    from rlcore.training.spec import CHECKPOINT_FILE

    run_dir = Path(run_dir)
    meta = next((read_json(path, "put back a good copy") for path in (run_dir / "model" / "meta.json",
                                                                      run_dir / "meta.json") if path.is_file()), None)
    if (run_dir / CHECKPOINT_FILE).is_file():
        state = read_checkpoint_state(run_dir / CHECKPOINT_FILE)
        if meta is None or state.get("env_steps", 0) > meta.get("env_steps", 0):
            return state
    return meta


def block_line(experiment, part: pd.DataFrame, partial: pd.DataFrame | None) -> str:
    """One block of full episodes (and the partial ones logged over the same episodes)."""
    first, last = int(part["episode"].iloc[0]), int(part["episode"].iloc[-1])
    goal = experiment.goal
    success_key, progress_key = (goal.success_key, goal.progress_key) if goal else (None, None)
    words = [f"episodes {first:,}-{last:,} (to env step {int(part['env_steps'].iloc[-1]):,}):"]
    if "success" in part and part["success"].notna().any():
        wins = int(part["success"].sum())
        words.append(f"{success_key} {wins}/{len(part)} ({wins / len(part):.1%})")
    if progress_key and progress_key in part:
        words.append(f"mean {progress_key} {part[progress_key].mean():,.0f}")
    words.append(f"mean return {part['total_points'].mean():.1f}")
    if "episode_steps" in part:  # SAC: how long it stood (a Minitaur fall ends it early)
        words.append(f"mean length {part['episode_steps'].mean():,.0f} steps")
    if "q_mean" in part and part["q_mean"].notna().any():  # a Q-learner's critic (rlcore/records/critic_trace.py)
        from rlcore.records.critic_trace import q_text

        words.append(f"median Q {q_text(part['q_mean'].median())}")
    if not success_key:  # Minitaur: x, the metres walked
        words += [f"mean {key} {part[key].mean():,.2f}" for key in experiment.info_keys
                  if key in part and part[key].notna().any()]
    if partial is not None and len(partial):
        wins = f" ({int(partial['success'].sum())} {success_key})" if "success" in partial else ""
        words.append(f"| {experiment.curriculum.partial_key} {len(partial)}{wins}")
        words += _starts(experiment, partial)
    return " ".join(words)


def _starts(experiment, partial: pd.DataFrame) -> list[str]:
    """Where the partial episodes started (``Curriculum.partial_start_key``, Mario's ``start_x``: a
    restart x stepping back shows)."""
    column = experiment.curriculum.partial_start_key if experiment.curriculum else None
    if not column or column not in partial or partial[column].isna().all():
        return []
    low, high = partial[column].min(), partial[column].max()
    return [f"from {column} {low:,.0f}" + (f"-{high:,.0f}" if high > low else "")]


def rollout_lines(rollouts_csv: Path, experiment, block: int, blocks: int) -> list[str]:
    """Per block of ``block`` rollouts (the newest ``blocks``, whole blocks ending at the newest
    rollout): the success share of the episodes from the start, the restarted ones beside it, and PPO's
    update sizes (means per update), learning rate and entropy weight."""
    if not rollouts_csv.is_file():
        return []
    df = read_table(rollouts_csv, "rollout", "episodes_ended", "successes")
    return [_rollout_line(experiment, part) for part in _blocks(df.tail(block * blocks), block)]


def _blocks(rows: pd.DataFrame, block: int) -> list[pd.DataFrame]:
    """``rows`` cut into blocks of ``block``: whole blocks end at the newest row, a short one first."""
    first = len(rows) % block
    starts = ([0] if first else []) + list(range(first, len(rows), block))
    return [rows.iloc[begin:end] for begin, end in zip(starts, starts[1:] + [len(rows)])]


def _rollout_line(experiment, part: pd.DataFrame) -> str:
    key = experiment.curriculum.partial_key if experiment.curriculum else None
    partial, partial_wins = (part.get(f"{key}_{name}", pd.Series(0, index=part.index)).sum()
                             for name in ("episodes", "successes"))
    from_start, wins = int(part["episodes_ended"].sum() - partial), int(part["successes"].sum())
    words = [f"rollouts {int(part['rollout'].iloc[0])}-{int(part['rollout'].iloc[-1])}:"]
    if experiment.goal:  # a task without a success event (CartPole-v1 on PPO) has no share to give
        words.append(f"{experiment.goal.success_key} {wins}/{from_start}"
                     + (f" ({wins / from_start:.1%})" if from_start else ""))
    else:
        words.append(f"{from_start} episodes ended")
    if partial:
        words.append(f"| {key} {int(partial_wins)}/{int(partial)} ({partial_wins / partial:.1%})")
    sizes = [f"{shown} {part[name].mean():.{digits}f}"
             for name, shown, digits in (("entropy", "entropy", 2), ("approx_kl", "approx KL", 4),
                                         ("clip_fraction", "clip fraction", 3))
             if name in part and part[name].notna().any()]
    if sizes:
        words.append("| " + ", ".join(sizes))
    settings = [_setting(part, name, shown) for name, shown in (("lr", "lr"), ("entropy_coef", "entropy weight"))]
    if any(settings):
        words.append("| " + ", ".join(text for text in settings if text))
    return " ".join(words)


def _setting(part: pd.DataFrame, name: str, label: str) -> str | None:
    """A setting over a block of rollouts: its value, or first -> last when a resume changed it
    (rows logged before the code kept that column leave it empty)."""
    if name not in part or part[name].isna().all():
        return None
    values = part[name].dropna()
    return f"{label} {values.iloc[0]:.3g}" + (f" -> {values.iloc[-1]:.3g}" if values.nunique() > 1 else "")


def evaluation_lines(evals_csv: Path, last: int = 3) -> list[str]:
    """The last periodic evaluations (``evals.csv``), if the run has any."""
    if not evals_csv.is_file():
        return []
    evals = read_table(evals_csv, "env_steps", "eval_mean", "eval_std").tail(last)
    lines = []
    for row in evals.itertuples():
        line = f"evaluation at env step {int(row.env_steps):,}: mean {row.eval_mean:.2f} +- {row.eval_std:.2f}"
        share = getattr(row, "eval_time_limit_share", float("nan"))
        if pd.notna(share):
            line += f", {share:.0%} of its episodes to the time limit"
        lines.append(line)
    return lines


def cause_line(experiment, span: pd.DataFrame, most: int = 5) -> str | None:
    """The commonest causes of failure (``Goal.cause_key``) in ``span``, as shares. The span
    holds every episode since the first of the blocks, restarted ones included, and says so."""
    goal = experiment.goal
    key = goal.cause_key if goal else None
    if not key or key not in span or span[key].isna().all():
        return None
    causes = count_causes(span[[key]].to_dict("records"), key, goal.cause_name)
    total = sum(n for _, n in causes)
    shares = ", ".join(f"{name} {n / total:.0%}" for name, n in causes[:most])
    return f"{key} over all episodes since {int(span['episode'].iloc[0]):,} ({total:,} failures): {shares}"


def _partial_between(df: pd.DataFrame, experiment, part: pd.DataFrame) -> pd.DataFrame | None:
    key = experiment.curriculum.partial_key if experiment.curriculum else None
    if not key or key not in df:
        return None
    between = df["episode"].between(part["episode"].iloc[0], part["episode"].iloc[-1])
    return df[between & (df[key] == 1)]
