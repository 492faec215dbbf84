"""The docs regions about kept sweeps' seeds, read from the run folders in ``results/sweeps/``:
``sweep-stability`` (what each seed's periodic evaluations saw: collapses, and whether keep-best kept better
weights than the last), ``seed-runs`` (each seed's scores, env steps, wall time and speed) and
``seed-summary`` (one paragraph per sweep for the README)."""
from rlcore.environments.registry import get_experiment
from rlcore.records.commands import cpus_text
from rlcore.records.critic_trace import WINDOW, critic_cell, critic_trace
from rlcore.records.eval_history import stability_summary, steps_text, story
from rlcore.records.score_words import hours, score_words, stop_words
from tools.docgen import data  # its REPO and shipped_models read at each call (tests point them elsewhere)
from tools.docgen.words import fill, link, over_seeds, score_text, sweep_score, table

#: what the sweep-stability region says of a Q-learner's sweep, whose table ends with each seed's critic
CRITIC = (f" Last, the critic at the run's end: the mean Q of its training batches (median of its last {WINDOW} "
          f"episodes) beside the largest return of any of its training episodes; at a run's end a critic that "
          f"diverged estimates returns far beyond any it was paid.")


def kept_runs(experiment: str):
    """(shipped model, its kept sweep's runs as (meta, story, run folder) by seed), per model with a kept sweep."""
    for m in data.shipped_models():
        if m.experiment == experiment and m.sweep is not None:
            runs = [(data.read_json(path), path.parent.parent)
                    for path in (data.REPO / m.sweep.folder).glob("*/model/meta.json")]
            solved = get_experiment(experiment).solved_score
            yield m, sorted([(meta, story(run, meta, solved), run) for meta, run in runs], key=lambda r: r[0]["seed"])


def sweep_name(page: str, m) -> str:
    """``**[sac](../../results/sweeps/minitaur__sac/report.md)**``: a sweep by its model, linking its report."""
    return f"**[{m.name}]({link(page, m.sweep.report)})**"


def collapses_cell(collapses: list) -> str:
    """``2: 40k → 58k, 124k → 138k`` (``never`` for one not recovered); ``none``."""
    if not collapses:
        return "none"
    return f"{len(collapses)}: " + ", ".join(
        f"{steps_text(c.env_steps)} → {steps_text(c.recovered_at) if c.recovered_at is not None else 'never'}"
        for c in collapses)


def sweep_stability(page: str, experiment: str) -> str:
    """Each kept sweep's seeds through training: collapses of the periodic evaluations, the weights kept."""
    parts = [stability(page, m, runs) for m, runs in kept_runs(experiment)]
    return fill("sweep_stability.md", sweeps="\n\n".join(parts)) if parts else ""  # nothing until a sweep is kept


def stability(page: str, m, runs: list) -> str:
    """One sweep's paragraph and table in the sweep-stability region."""
    stories = [st for _, st, _ in runs]
    if not any(st.evaluations for st in stories):
        return f"{sweep_name(page, m)}: its runs made no periodic evaluations; each model holds its run's last weights."
    traces = [critic_trace(run) for _, _, run in runs]
    critic = any(t is not None for t in traces)  # a Q-learner: each seed's critic at its end
    rows = [stability_row(meta, st, m) + ([critic_cell(t)] if critic else []) for (meta, st, _), t in zip(runs, traces)]
    kept = [str(meta["seed"]) for meta, st, _ in runs if st.kept_best]
    weights = ("" if len(kept) == len(runs) else
               f" The models of seeds {', '.join(kept)} hold their best evaluation's weights (keep-best), the "
               f"others their last." if kept else " Every model holds its run's last weights.")
    header = ["seed", "unseen seeds", "best evaluation (at)", "last", "collapses: at → back by", "deepest"]
    header += ["critic at the end: mean Q"] if critic else []
    return (f"{sweep_name(page, m)}: {stability_summary(stories)}{weights} Beside each unseen-seed score, the share "
            f"of its episodes that lasted to the time limit.{CRITIC if critic else ''}\n\n"
            + table(header, rows, "rrrrll" + ("r" if critic else "")))


def stability_row(meta: dict, st, m) -> list[str]:
    """A seed's unseen-seed score (with its share of full-length episodes), best and last evaluation, collapses."""
    ev = meta.get("evaluation") or {}
    share = ev.get("time_limit_share")
    deepest = min(st.collapses, key=lambda c: c.mean, default=None)
    return [str(meta["seed"]), sweep_score(data.score_of(ev), m) + ("" if share is None else f" ({share:.0%})"),
            f"{sweep_score(st.best.mean, m)} at {steps_text(st.best.env_steps)}" if st.best else "–",
            sweep_score(st.last.mean, m) if st.last else "–", collapses_cell(st.collapses),
            f"{sweep_score(deepest.mean, m)} after {sweep_score(deepest.best_before, m)}" if deepest else "–"]


def seed_summary(page: str, experiment: str) -> str:
    """A paragraph per kept sweep of an experiment: IQM, per-seed scores, the shipped model, collapses."""
    parts = []
    for m, runs in kept_runs(experiment):
        stories, during = [st for _, st, _ in runs], ""
        if any(st.evaluations for st in stories):
            during = f" During training {stability_summary(stories)}"
        per_seed = "; ".join(f"{meta['seed']}: {evaluation_cell(meta['evaluation'], m)} after "
                             f"{meta['env_steps']:,} env steps, {hours(meta['wall_seconds'])}" for meta, _, _ in runs)
        parts.append(f"{m.algo_name} on {m.env_id}, the same recipe over {len(m.sweep.seeds)} seeds ([report]"
                     f"({link(page, m.sweep.report)})): {over_seeds(m, bold='[95% CI] ')}; per seed {per_seed}; the "
                     f"shipped model (seed {m.meta.get('seed')}, a run of its own) {score_text(m)}."
                     + seeds_bar_text(m) + during)
    return "\n\n".join(parts) or "*Not kept in `results/sweeps/` yet: the figures appear here when the runs are.*"


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
    time limit, ``18.56 over 30 (93% full length)``: one recorded evaluation, with the shipped score's digits."""
    if "success_share" in evaluation:
        return score_words(evaluation, m.experiment, m.name)
    share = evaluation.get("time_limit_share")
    full = share is not None and m.bar is not None and m.bar.full_length_share is not None
    return f"{sweep_score(evaluation['mean'], m)} over {evaluation['episodes']}" + (
        f" ({share:.0%} full length)" if full else "")


def stop_text(meta: dict, m) -> str:
    """What ended the run of ``meta``, a run of model ``m``, in words (:func:`rlcore.records.score_words.stop_words`)."""
    return stop_words(meta.get("stopped_by") or "", m.experiment, m.name, (meta.get("config") or {}).get("window", 100))


def seed_runs(page: str, experiment: str) -> str:
    """Each kept sweep's seeds: scores (and further evaluations), env steps, wall time, speed, what stopped them."""
    parts = []
    for m, runs in kept_runs(experiment):
        rows = [seed_run_row(meta, m) for meta, _, _ in runs]
        header = ["seed", "unseen seeds", "further unseen seeds", "env steps", "wall", "env steps/s", "CPU",
                  "stopped by"]
        stops, ended = {row[-1] for row in rows}, ""
        if len(stops) == 1 and stops != {"–"}:  # one rule ended every run: said once, not in every row
            rows, header = [row[:-1] for row in rows], header[:-1]
            ended = f"\n\nEvery run was stopped by {stops.pop()}."
        parts.append(f"{sweep_name(page, m)}, beside the shipped model's {score_text(m)}:\n\n"
                     + table(header, rows, "rrrrrrll"[:len(header)]) + ended
                     + f"\n\nOver the {len(runs)} seeds: {over_seeds(m, bold='[95% CI] ')}." + seeds_bar_text(m))
    if not parts:
        return "*Not kept in `results/sweeps/` yet: the runs' table appears here when they are.*"
    return fill("seed_runs.md", sweeps="\n\n".join(parts))


def seed_run_row(meta: dict, m) -> list[str]:
    """A seed's scores, env steps, wall time, speed, CPU and what stopped it."""
    further = "; ".join(f"{evaluation_cell(f, m)} ({f.get('seeds')})" for f in meta.get("further_evaluations", []))
    return [str(meta["seed"]), evaluation_cell(meta.get("evaluation") or {}, m), further or "–",
            f"{meta['env_steps']:,}", hours(meta["wall_seconds"]),
            f"{meta['env_steps'] / max(meta['wall_seconds'], 1e-9):,.0f}", cpus_text(meta) or "not recorded",
            stop_text(meta, m)]
