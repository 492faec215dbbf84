"""The docs regions about kept sweeps' seeds, read from the run folders in ``results/sweeps/``:
``sweep-stability`` (what each seed's periodic evaluations saw: collapses during training, and whether
keep-best kept better weights than the last), ``seed-runs`` (each seed's scores, further evaluations,
env steps, wall time and speed) and ``seed-summary`` (one paragraph per sweep for the README: the IQM,
each seed's score and the shipped model's beside them). Part of :mod:`tools.docgen`;
TensorFlow-free."""
from __future__ import annotations

from rlcore.environments.registry import get_experiment
from rlcore.runs.commands import cpus_text
from rlcore.runs.critic_trace import WINDOW, critic_cell, critic_trace
from rlcore.runs.eval_history import stability_summary, steps_text, story
from tools.docgen import (
    data as docgen_data,  # its REPO and shipped_models read at each call (tests point them elsewhere)
)
from tools.docgen.words import hours, link, over_seeds_bold, score_text, sweep_score, table

#: what the sweep-stability region says before its tables (the rule is rlcore.runs.eval_history's)
STABILITY_INTRO = ("What the periodic evaluations (on selection seeds) saw through training: a *collapse* is an "
                   "evaluation that falls below a quarter of the way up from the run's first evaluation to its best "
                   "before it, once the run has made half of its best gain; it is *back* at the first evaluation three "
                   "quarters of the way up again. A run whose evaluations never got a quarter of the way from its "
                   "first to the task's solved score had little to lose, and none of its dips counts "
                   "(`rlcore/runs/eval_history.py`).")
SEED_RUNS_INTRO = ("Each seed's run: its score on unseen seeds (and further evaluations on other unseen seeds), env "
                   "steps, wall time and speed on the CPU that trained it (each CPU a resume moved it to, from "
                   "where it took over), and what ended it.")


def _runs(folder: str, solved: float | None) -> list[tuple[dict, object]]:
    """(meta, story) of each finished run of a kept sweep, by seed; ``solved``: the task's solved score."""
    runs = []
    for meta_path in (docgen_data.REPO / folder).glob("*/model/meta.json"):
        meta = docgen_data.read_json(meta_path)
        runs.append((meta, story(meta_path.parent.parent, meta, solved)))
    return sorted(runs, key=lambda run: run[0]["seed"])


def _critic_traces(folder: str) -> dict:
    """seed -> each finished run's critic over training (None for a run that logs no Q)."""
    return {docgen_data.read_json(p)["seed"]: critic_trace(p.parent.parent)
            for p in (docgen_data.REPO / folder).glob("*/model/meta.json")}


def _kept_sweeps(experiment: str):
    """(shipped model, its kept sweep's runs) for each shipped model of ``experiment`` with a kept sweep."""
    for m in docgen_data.shipped_models():
        if m.experiment == experiment and m.sweep is not None:
            yield m, _runs(m.sweep.folder, get_experiment(experiment).solved_score)


def collapses_cell(collapses: list) -> str:
    """``2: 40k → 58k, 124k → 138k`` (``never`` for one not recovered); ``none``."""
    if not collapses:
        return "none"
    return f"{len(collapses)}: " + ", ".join(
        f"{steps_text(c.env_steps)} → {steps_text(c.recovered_at) if c.recovered_at is not None else 'never'}"
        for c in collapses)


def sweep_stability(page: str, experiment: str) -> str:

    parts = []
    for m, runs in _kept_sweeps(experiment):
        if not any(st.evaluations for _, st in runs):
            parts.append(f"**[{m.name}]({link(page, m.sweep.folder + '/report.md')})**: its runs made no periodic "
                         f"evaluations; each model holds its run's last weights.")
            continue
        traces = _critic_traces(m.sweep.folder)
        critic = any(t is not None for t in traces.values())  # a Q-learner: each seed's critic at its end
        rows = []
        for meta, st in runs:
            ev = meta.get("evaluation") or {}
            share = ev.get("time_limit_share")
            deepest = min(st.collapses, key=lambda c: c.mean, default=None)
            rows.append([str(meta["seed"]), sweep_score(ev.get("success_share", ev.get("mean")), m)
                         + ("" if share is None else f" ({share:.0%})"),
                         f"{sweep_score(st.best.mean, m)} at {steps_text(st.best.env_steps)}" if st.best else "–",
                         sweep_score(st.last.mean, m) if st.last else "–",
                         collapses_cell(st.collapses),
                         f"{sweep_score(deepest.mean, m)} after {sweep_score(deepest.best_before, m)}" if deepest else "–"]
                        + ([critic_cell(traces.get(meta["seed"]))] if critic else []))
        kept = [str(meta["seed"]) for meta, st in runs if st.kept_best]
        weights = ("" if len(kept) == len(runs) else
                   f" The models of seeds {', '.join(kept)} hold their best evaluation's weights (keep-best), the "
                   f"others their last." if kept else " Every model holds its run's last weights.")
        parts.append(f"**[{m.name}]({link(page, m.sweep.folder + '/report.md')})**: "
                     f"{stability_summary([st for _, st in runs])}{weights} Beside each unseen-seed score, the share "
                     f"of its episodes that lasted to the time limit."
                     + (f" Last, the critic at the run's end: the mean Q of its training batches (median of its last "
                        f"{WINDOW} episodes) beside the largest return of any of its training episodes; at a run's "
                        f"end a critic that diverged estimates returns far beyond any it was paid." if critic else "")
                     + "\n\n" + table(["seed", "unseen seeds", "best evaluation (at)", "last", "collapses: at → back by",
                                       "deepest"] + (["critic at the end: mean Q"] if critic else []), rows,
                                      "rrrrll" + ("r" if critic else "")))
    return "\n\n".join([STABILITY_INTRO, *parts]) if parts else ""  # nothing until a sweep is kept


def seed_summary(page: str, experiment: str) -> str:

    parts = []
    for m, runs in _kept_sweeps(experiment):
        per_seed = "; ".join(f"{meta['seed']}: {evaluation_cell(meta['evaluation'], m)} after "
                             f"{meta['env_steps']:,} env steps, {hours(meta['wall_seconds'])}" for meta, _ in runs)
        parts.append(f"{m.title}, the same recipe over {len(m.sweep.seeds)} seeds "
                     f"([report]({link(page, m.sweep.folder + '/report.md')})): {over_seeds_bold(m, '[95% CI] ')}; "
                     f"per seed {per_seed}; the shipped model (seed {m.meta.get('seed')}, a run of its own) "
                     f"{score_text(m)}." + seeds_bar_text(m)
                     + (f" During training {stability_summary([st for _, st in runs])}"
                        if any(st.evaluations for _, st in runs) else ""))
    if not parts:
        return "*Not kept in `results/sweeps/` yet: the figures appear here when the runs are.*"
    return "\n\n".join(parts)


def seeds_bar_text(m) -> str:
    """`` Bar over seeds: IQM >= 11.3 (why): **met**.``, from the registry's bar for the recipe over seeds
    (:class:`rlcore.environments.experiment.SeedsBar`) and the kept sweep's report; empty where none is set."""
    bar = m.bar.over_seeds if m.bar else None
    if bar is None or bar.statistic not in m.sweep.aggregates:
        return ""
    scores = [score for _, score in m.sweep.seeds]
    met = bar.met_by(m.sweep.aggregates[bar.statistic][0], scores)
    verdict = ({True: "**met**", False: "**not met**"}[met] if met is not None
               else f"not judged yet ({len(scores)} of {bar.seeds} seeds kept)")
    return f" Bar over seeds: {bar.describe('success_share' in m.evaluation)} ({bar.reason}): {verdict}."


def evaluation_cell(evaluation: dict, m) -> str:
    """``flag in 9 of 10`` (Mario), ``257.4 over 100``, and where the bar asks for episodes that last to the
    time limit, ``18.56 over 30 (93% full length)``: one recorded evaluation, with the digits of the
    shipped score (:mod:`rlcore.runs.score_words`)."""
    from rlcore.runs.score_words import score_words

    if "success_share" in evaluation:
        return score_words(evaluation, m.experiment, m.name)
    text = f"{sweep_score(evaluation['mean'], m)} over {evaluation['episodes']}"
    share = evaluation.get("time_limit_share")
    if share is not None and m.bar is not None and m.bar.full_length_share is not None:
        text += f" ({share:.0%} full length)"
    return text


def stop_text(meta: dict, m) -> str:
    """What ended the run of ``meta``, a run of model ``m``, in words (:func:`rlcore.runs.score_words.stop_words`)."""
    from rlcore.runs.score_words import stop_words

    return stop_words(meta.get("stopped_by") or "", m.experiment, m.name, (meta.get("config") or {}).get("window", 100))


def seed_runs(page: str, experiment: str) -> str:

    parts = []
    for m, runs in _kept_sweeps(experiment):
        rows = []
        for meta, _ in runs:
            ev = meta.get("evaluation") or {}
            further = "; ".join(f"{evaluation_cell(f, m)} ({f.get('seeds')})"
                                for f in meta.get("further_evaluations", [])) or "–"
            rows.append([str(meta["seed"]), evaluation_cell(ev, m), further, f"{meta['env_steps']:,}",
                         hours(meta["wall_seconds"]), f"{meta['env_steps'] / max(meta['wall_seconds'], 1e-9):,.0f}",
                         cpus_text(meta) or "not recorded", stop_text(meta, m)])
        header = ["seed", "unseen seeds", "further unseen seeds", "env steps", "wall", "env steps/s", "CPU",
                  "stopped by"]
        stops = {row[-1] for row in rows}
        ended = ""
        if len(stops) == 1 and stops != {"–"}:  # one rule ended every run: said once, not in every row
            rows, header, ended = [row[:-1] for row in rows], header[:-1], f"\n\nEvery run was stopped by {stops.pop()}."
        parts.append(f"**[{m.name}]({link(page, m.sweep.folder + '/report.md')})**, beside the shipped model's "
                     f"{score_text(m)}:\n\n"
                     + table(header, rows, "rrrrrrll"[:len(header)]) + ended
                     + f"\n\nOver the {len(runs)} seeds: {over_seeds_bold(m, '[95% CI] ')}." + seeds_bar_text(m))
    if not parts:
        return "*Not kept in `results/sweeps/` yet: the runs' table appears here when they are.*"
    return "\n\n".join([SEED_RUNS_INTRO, *parts])
