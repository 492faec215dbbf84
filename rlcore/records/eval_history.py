"""A run's periodic evaluations (``evals.csv``) read back: collapses, recoveries, and which weights the
model kept. ``main.py report`` and the docs generator tell each seed's story from it. TensorFlow-free.

A *collapse* is measured against the run's own scale, so the same rule serves returns that start
negative (LunarLander) and returns that start near zero (Minitaur). With ``b`` the first evaluation's
mean and ``g`` the best gain over ``b`` before evaluation ``i``:

- a run whose best gain never reaches ``least`` (a quarter) of the way from ``b`` to the task's solved
  score (``Experiment.solved_score``, where the task has one and ``b`` is below it) had little to
  lose: its ups and downs are noise on a policy that has not learnt much, not collapses;
- otherwise the run has *learnt* once ``g`` is at least ``learnt`` (half) of the best gain it ever makes;
- evaluation ``i`` of a run that has learnt starts a collapse when its mean is below ``b + drop * g``
  (a quarter of the way up from the start);
- the collapse ends at the first later evaluation back above ``b + recover * g`` (three quarters);
  one that never comes back is unrecovered.

Seed 0 of the Minitaur sweep, for instance: its first evaluation -0.08, then 14.76 at 350k and 0.19 at
400k (a collapse), back at 12.06 by 500k. Seed 2 of the same sweep went from -0.34 to 0.86 at 200k and
-0.07 at 250k, and was still below 1 at 650k: against the solved score 15 it had not learnt to walk, so
its dips are not collapses.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from rlcore.errors import UserError
from rlcore.records.score_words import count

DROP, RECOVER, LEARNT, LEAST = 0.25, 0.75, 0.5, 0.25


@dataclass(frozen=True)
class Evaluation:
    env_steps: int
    mean: float
    time_limit_share: float | None  # share of its episodes that lasted to the time limit


@dataclass(frozen=True)
class Collapse:
    env_steps: int  # the evaluation that fell
    mean: float
    best_before: float  # the best evaluation before it
    recovered_at: int | None  # the first evaluation back up, if any


def read_evals(run_dir: Path) -> list[Evaluation]:
    """The periodic evaluations of a run folder, in order; none if it has no ``evals.csv``."""
    path = Path(run_dir) / "evals.csv"
    if not path.is_file():
        return []
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        evals = [Evaluation(int(float(r["env_steps"])), float(r["eval_mean"]),
                            float(r["eval_time_limit_share"]) if r.get("eval_time_limit_share") not in (None, "")
                            else None) for r in rows]
    except (KeyError, ValueError, TypeError, UnicodeDecodeError) as exc:
        raise UserError(f"{path} is damaged or not one of ours ({type(exc).__name__})") from None
    if not all(math.isfinite(e.mean) for e in evals):
        raise UserError(f"{path} is damaged or not one of ours (an evaluation's mean is not a number)")
    return evals


def far_from_solved(evals: list[Evaluation], solved: float | None, least: float = LEAST) -> bool:
    """Whether the task has a solved score above the run's first evaluation and no evaluation got
    ``least`` of the way there from the first. False with no solved score, a first evaluation already
    at it, or no evaluations: then nothing is claimed."""
    if not evals or solved is None or evals[0].mean >= solved:
        return False
    return max(e.mean for e in evals) - evals[0].mean < least * (solved - evals[0].mean)


def collapses(evals: list[Evaluation], solved: float | None = None, drop: float = DROP, recover: float = RECOVER,
              learnt: float = LEARNT) -> list[Collapse]:
    """The collapses of a run's evaluations, by the rule of this module's docstring; ``solved``: the
    task's solved score, if it has one."""
    if len(evals) < 2 or far_from_solved(evals, solved):
        return []  # nothing learnt to lose
    means = [e.mean for e in evals]
    base, total_gain = means[0], max(means) - means[0]
    if total_gain <= 0:
        return []  # it never rose above its first evaluation
    found: list[Collapse] = []
    open_at: tuple[int, float, float] | None = None  # (index, mean, gain) of the collapse not yet recovered
    for i in range(1, len(means)):
        if open_at is not None:
            start, _, gain = open_at
            if means[i] >= base + recover * gain:
                found.append(Collapse(evals[start].env_steps, means[start], base + gain, evals[i].env_steps))
                open_at = None
            continue
        gain = max(means[:i]) - base
        if gain >= learnt * total_gain and means[i] < base + drop * gain:
            open_at = (i, means[i], gain)
    if open_at is not None:
        start, _, gain = open_at
        found.append(Collapse(evals[start].env_steps, means[start], base + gain, None))
    return found


@dataclass(frozen=True)
class Story:
    """What a run's periodic evaluations say about it."""
    evaluations: int
    best: Evaluation | None
    last: Evaluation | None
    collapses: list[Collapse]
    kept_best: bool  # the model holds the best evaluation's weights (keep_best), not the last ones
    far_from_solved: bool = False  # no evaluation got a quarter of the way to the solved score (far_from_solved)

    @property
    def keep_best_mattered(self) -> bool:
        """keep-best kept weights that evaluated better than the last ones."""
        return self.kept_best and self.best is not None and self.last is not None and self.best.mean > self.last.mean


def story(run_dir: Path, meta: dict, solved: float | None = None) -> Story:
    """A run folder's :class:`Story`, from its ``evals.csv`` and its model's ``meta.json``; ``solved``:
    the task's solved score, if it has one. The best evaluation is the one training remembered
    (``best_eval``), else the highest (a tie: the later)."""
    evals = read_evals(run_dir)
    best = max(reversed(evals), key=lambda e: e.mean) if evals else None  # a tie goes to the later one
    remembered = (meta.get("best_eval") or {}).get("env_steps")
    best = next((e for e in evals if e.env_steps == remembered), best)
    return Story(len(evals), best, evals[-1] if evals else None, collapses(evals, solved),
                 meta.get("weights") == "best periodic evaluation", far_from_solved(evals, solved))


def steps_text(env_steps: int) -> str:
    """1,000,062 -> "1M"; 1,950,000 -> "1.95M"; 650,000 -> "650k"; 1,234 -> "1,234"."""
    if env_steps >= 999_500:
        return f"{round(env_steps / 1e6, 2):g}M"
    if env_steps >= 10_000:
        return f"{round(env_steps / 1000):,}k"
    return f"{env_steps:,}"


def collapse_text(c: Collapse, digits: int = 2) -> str:
    back = f"back by {steps_text(c.recovered_at)}" if c.recovered_at is not None else "not recovered"
    return f"{steps_text(c.env_steps)}: {c.mean:.{digits}f} after {c.best_before:.{digits}f}, {back}"


def story_text(s: Story, digits: int = 2) -> str:
    """One line: the collapses, then which weights the model holds."""
    if not s.evaluations:
        return "no periodic evaluations"
    if s.far_from_solved:
        parts = ["no evaluation a quarter of the way to the solved score"
                 + (f" (best {s.best.mean:.{digits}f})" if s.best is not None else "") + ": no dip counts as a collapse"]
    else:
        parts = [count(len(s.collapses), 'collapse')
                 + (f" ({'; '.join(collapse_text(c, digits) for c in s.collapses)})" if s.collapses else "")]
    if s.kept_best and s.best is not None:
        parts.append(f"model: weights of the best evaluation ({s.best.mean:.{digits}f} at {steps_text(s.best.env_steps)})"
                     + (f", the last scored {s.last.mean:.{digits}f}" if s.keep_best_mattered else ", also the last"))
    else:
        parts.append("model: the last weights")
    return "; ".join(parts)


def stability_summary(stories: list[Story]) -> str:
    """One sentence over a sweep's runs: how many collapsed, how many collapses came back, and how often
    keep-best kept weights that evaluated above the last ones."""
    collapsed = sum(bool(st.collapses) for st in stories)
    count = sum(len(st.collapses) for st in stories)
    unrecovered = sum(c.recovered_at is None for st in stories for c in st.collapses)
    mattered = sum(st.keep_best_mattered for st in stories)
    weights = ("keep-best changed no model (each model's weights scored as high as its run's last evaluation)"
               if not mattered else
               f"in {mattered} run{'' if mattered == 1 else 's'} keep-best mattered: the model holds an earlier "
               f"evaluation's weights, which scored above the run's last evaluation")
    far = sum(st.far_from_solved for st in stories if st.evaluations)
    never = (f"; in {far} run{'' if far == 1 else 's'} no evaluation got a quarter of the way from the first to "
             f"the solved score, so none of {'its' if far == 1 else 'their'} dips counts" if far else "")
    return (f"{collapsed} of {len(stories)} runs collapsed at least once ({count} collapse{'' if count == 1 else 's'}, "
            f"{unrecovered} not recovered){never}; {weights}.")
