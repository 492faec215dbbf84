"""The generated regions of the README and the docs pages: the text between ``<!-- generated:NAME ARG -->``
and ``<!-- /generated -->`` is region NAME with ARG (:data:`REGIONS`); the rest of the page is left as written.
The regions about the shipped models are here; the others in :mod:`.reference` and :mod:`.sweeps`."""
import re

from rlcore.records.commands import cpus_text
from rlcore.records.score_words import hours, success_word
from tools.docgen import reference, sweeps
from tools.docgen.data import REPO, shipped_models
from tools.docgen.words import (
    article_of,
    bar_met,
    bar_text,
    interval,
    link,
    over_seeds,
    ret,
    score_text,
    sweep_score,
    table,
)

OVER_SEEDS_HEADER = "same recipe over seeds [95% CI]"  # the header of over_seeds' cells
#: the README's strip of GIFs: (experiment, model), shown when its GIF exists
GIF_STRIP = (("mario_ppo", "1-1"), ("mario_ppo", "1-4"), ("lunar_lander", "dqn"), ("minitaur", "sac"),
             ("cartpole", "a2c"))
#: the figures of a kept sweep's report: file -> (its caption after "NAME, N seeds", its alt text after NAME)
SWEEP_FIGURES = {
    "report_curves.png": (" (IQM of the 100-episode average, 95% CI band)", "sweep"),
    "report_success.png": (": the share of the last 100 episodes that reached the {goal}, as the stop rule reads "
                           "it (IQM, 95% CI band; each seed thin)", "sweep successes"),
    "report_evals.png": (": periodic evaluations on selection seeds (IQM, 95% CI band; each seed thin)",
                         "sweep evaluations"),
    "report_critic.png": (": each seed's mean Q of its training batches, running median of 20 episodes (log scale, "
                          "linear within ±1)", "sweep critic")}
REGION = re.compile(r"(<!-- generated:([\w-]+)(?: ([\w./-]+))? -->\n)(.*?)(<!-- /generated -->)", re.S)


def experiment_page(experiment: str) -> str:
    """The docs page of an experiment (cartpole_v0 shares CartPole's page)."""
    return f"docs/experiments/{'cartpole' if experiment == 'cartpole_v0' else experiment}.md"


def card_path(model, page: str) -> str:
    """Where ``page`` should send a reader for a model: the docs page inside docs, the card elsewhere."""
    return model.page if page.startswith("docs/") else model.card


def region_results_table(page: str, arg: str) -> str:
    """What is inside: one row per shipped model."""
    rows = [[f"[{m.env_id}]({link(page, experiment_page(m.experiment))})",
             f"[{m.algo if m.name == m.algo else f'{m.algo} {m.name}'}]({link(page, card_path(m, page))})",
             article_of(m.experiment, m.algo), f"**{score_text(m)}**",
             bar_text(m) + ("" if bar_met(m) == "met" else f" ({bar_met(m)})"), over_seeds(m)]
            for m in shipped_models()]
    return table(["env (experiment page)", "model (card)", "article", "score on unseen seeds", "bar",
                  OVER_SEEDS_HEADER], rows)


def region_gif_strip(page: str, arg: str) -> str:
    models = {(m.experiment, m.name): m for m in shipped_models()}
    shown = [models[key] for key in GIF_STRIP if key in models and models[key].gif]
    if not shown:
        return ("*No GIFs yet: `make gifs` writes them to `docs/assets/gifs/` from the shipped models, and "
                "`python -m tools.docgen` then shows them here.*")
    return table([f"![{m.slug}]({link(page, m.gif)})" for m in shown],
                 [[f"{m.env_id}, {m.algo}: {score_text(m)} ({m.evaluation.get('episodes')} unseen seeds)"
                   for m in shown]], "c" * len(shown))


def region_shipped(page: str, experiment: str) -> str:
    """The shipped models of one experiment with their training counters, commands, CPU and unseen-seed score,
    beside what others published; a model whose run started from another's weights (``--init-from``) also gives
    what the chain cost. A column no model fills is left out."""
    models = [m for m in shipped_models() if m.experiment == experiment]
    header = ["model", "preset", "commands", "env steps", "episodes", "wall",
              "env steps, wall with the runs it started from (`--init-from`)", "best selection eval", "CPU",
              "unseen seeds", "bar", "published elsewhere"]
    rows = []
    for m in models:
        meta, best, (steps, seconds) = m.meta, m.meta.get("best_eval") or {}, m.from_scratch()
        sources = ", ".join(source(parent, m.name) for parent in m.lineage)
        commands = str(len(meta["commands"])) if meta.get("commands") else "–"
        rows.append([f"[{m.name}]({link(page, card_path(m, page))})", f"`{meta.get('preset')}`", commands,
                     f"{meta['env_steps']:,}", f"{meta['episodes']:,}", hours(meta["wall_seconds"]),
                     f"{steps:,}, {hours(seconds)} (from {sources})" if m.lineage else "–",
                     ret(best["mean"]) if "mean" in best else "–", re.sub(r" \([^)]*\)|\(R\)| Processor", "", cpus_text(meta) or "–"),
                     f"**{score_text(m)}** ({m.evaluation.get('episodes', '?')} ep.)", bar_text(m, met=": "),
                     (m.bar.published if m.bar else None) or "–"])
    kept = [i for i in range(len(header)) if i < 2 or any(row[i] != "–" for row in rows)]
    return table([header[i] for i in kept], [[row[i] for i in kept] for row in rows],
                 "".join("llrrrrrrllll"[i] for i in kept))


def source(parent: dict, name: str) -> str:
    """The model folder a run started from, by its last part (Mario's level): ``2-1``, or ``an earlier
    2-2`` when it is the model's own folder as an earlier run left it."""
    folder = str(parent.get("path", "?")).rstrip("/").rsplit("/", 1)[-1]
    return f"an earlier {folder}" if folder == name else folder


def region_sweeps(page: str, experiment: str) -> str:
    """The kept sweeps of one experiment: per-seed scores and mean / median / IQM with 95 % CIs."""
    rows = [[f"[{m.name}]({link(page, m.sweep.report)})",
             ", ".join(f"{seed}: {sweep_score(score, m)}" for seed, score in m.sweep.seeds),
             *[interval(m.sweep.aggregates[k], m) if k in m.sweep.aggregates else "–"
               for k in ("iqm", "mean", "median")]]
            for m in shipped_models() if m.experiment == experiment and m.sweep is not None]
    if not rows:
        return "*No sweep over seeds is kept in `results/sweeps/` for this experiment yet.*"
    return table(["model", "score per seed (unseen seeds)", "IQM [95% CI]", "mean [95% CI]", "median [95% CI]"], rows)


def region_curves(page: str, experiment: str) -> str:
    """The training curves of the shipped models (and the figures of their sweeps' reports), as images."""
    parts = []
    for m in [m for m in shipped_models() if m.experiment == experiment]:
        if pngs := sorted((REPO / m.folder).glob("*.png")):
            images = (f"![{p.stem}]({link(page, f'{m.folder}/{p.name}')})" for p in pngs)
            parts.append(f"**{m.name}**\n\n" + "\n".join(images))
        for file, (caption, alt) in SWEEP_FIGURES.items() if m.sweep else ():
            if (REPO / m.sweep.folder / file).is_file():
                caption = caption.format(goal=success_word(experiment, m.name, "goal"))
                parts.append(f"**{m.name}, {len(m.sweep.seeds)} seeds{caption}**\n\n"
                             f"![{m.name} {alt}]({link(page, f'{m.sweep.folder}/{file}')})")
    return "\n\n".join(parts) or "*No curves shipped.*"


REGIONS = {"csv-columns": reference.region_csv_columns, "meta-keys": reference.region_meta_keys,
           "bars": reference.region_bars, "seed-ranges": reference.region_seed_ranges,
           "presets": reference.region_presets, "results-table": region_results_table,
           "gif-strip": region_gif_strip, "shipped": region_shipped, "sweeps": region_sweeps,
           "sweep-stability": sweeps.sweep_stability, "seed-summary": sweeps.seed_summary,
           "seed-runs": sweeps.seed_runs, "curves": region_curves}


def fill_regions(page: str, text: str) -> str:
    """``text`` of ``page`` with each generated region written anew."""
    def replace(m: re.Match) -> str:
        if m[2] not in REGIONS:
            raise SystemExit(f"error: {page}: unknown generated region {m[2]!r}; known: {', '.join(REGIONS)}")
        return f"{m[1]}{REGIONS[m[2]](page, m[3] or '')}\n{m[5]}"
    return REGION.sub(replace, text)


def region_pages() -> list[str]:
    """README.md and every docs page that holds a generated region."""
    pages = ["README.md"] + sorted(p.relative_to(REPO).as_posix() for p in (REPO / "docs").rglob("*.md"))
    return [p for p in pages if "<!-- generated:" in (REPO / p).read_text()]
