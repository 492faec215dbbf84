"""The generated regions of the README and the docs pages (``<!-- generated:NAME ARG -->``), one
function each, and filling a page's regions."""
from __future__ import annotations

import re

from rlcore.runs.score_words import success_word
from tools.docgen.data import REPO, Model, shipped_models
from tools.docgen.reference import region_bars, region_csv_columns, region_meta_keys, region_presets, region_seed_ranges
from tools.docgen.words import (
    OVER_SEEDS_HEADER,
    article_of,
    bar_met,
    bar_text,
    hours,
    link,
    model_page,
    over_seeds_cell,
    ret,
    score_text,
    sweep_score,
    table,
)

#: the docs page of each experiment (cartpole_v0 shares CartPole's page)
EXPERIMENT_PAGES = {"lunar_lander": "lunar_lander", "cartpole": "cartpole", "cartpole_v0": "cartpole",
                    "mario_ppo": "mario_ppo", "minitaur": "minitaur"}
#: the source articles (../shared/seeds), as far as their text names them
ARTICLES = {
    "000": "LunarLander series 07-11 (DQN, DDQN, Dueling DQN, Dueling DDQN, A2C; TensorFlow 2.10)",
    "001": "PPO on Super Mario Bros, a TensorFlow port of a PyTorch implementation",
    "002": "A2C (synchronous A3C) on CartPole with 8 parallel envs",
    "003": "DQN on CartPole-v1, the PyTorch DQN tutorial explained",
    "004": "SAC Minitaur (the TF-Agents colab, translated)",
}
#: the README's strip of GIFs: (experiment, model), shown when its GIF exists
GIF_STRIP = (("mario_ppo", "1-1"), ("mario_ppo", "1-4"), ("lunar_lander", "dqn"), ("minitaur", "sac"),
             ("cartpole", "a2c"))


# --------------------------------------------------------------------------------------- regions
def region_results_table(page: str, arg: str) -> str:
    """What is inside: one row per shipped model."""
    rows = []
    for m in shipped_models():
        exp_page = f"docs/experiments/{EXPERIMENT_PAGES[m.experiment]}.md"
        article = article_of(m.experiment, m.algo)
        name = m.algo if m.name == m.algo else f"{m.algo} {m.name}"
        rows.append([f"[{m.env_id}]({link(page, exp_page)})", f"[{name}]({link(page, card_path(m, page))})", article,
                     f"**{score_text(m)}**", bar_text(m) + ("" if bar_met(m) == "met" else f" ({bar_met(m)})"),
                     over_seeds_cell(m)])
    return table(["env (experiment page)", "model (card)", "article", "score on unseen seeds", "bar",
                  OVER_SEEDS_HEADER], rows)


def card_path(model: Model, page: str) -> str:
    """Where ``page`` should send a reader for a model: the docs page inside docs, the card elsewhere."""
    return model_page(model) if page.startswith("docs/") else f"{model.folder}/README.md"


def region_gif_strip(page: str, arg: str) -> str:
    models = {(m.experiment, m.name): m for m in shipped_models()}
    shown = [models[key] for key in GIF_STRIP if key in models and models[key].gif]
    if not shown:
        return ("*No GIFs yet: `make gifs` writes them to `docs/assets/gifs/` from the shipped models, and "
                "`python -m tools.docgen` then shows them here.*")
    images = [f"![{m.slug}]({link(page, m.gif)})" for m in shown]
    captions = [f"{m.env_id}, {m.algo}: {score_text(m)} ({m.evaluation.get('episodes')} unseen seeds)" for m in shown]
    return table(images, [captions], "c" * len(shown))


def region_shipped(page: str, experiment: str) -> str:
    """The shipped models of one experiment with their training counters and unseen-seed score; a model
    whose run started from another's weights (``--init-from``) also gives what the chain cost."""
    models = [m for m in shipped_models() if m.experiment == experiment]
    chained = any(m.lineage for m in models)
    rows = []
    for m in models:
        meta, best = m.meta, m.meta.get("best_eval") or {}
        row = [f"[{m.name}]({link(page, card_path(m, page))})", f"`{meta.get('preset')}`",
               f"{meta['env_steps']:,}", f"{meta['episodes']:,}", hours(meta["wall_seconds"])]
        if chained:
            steps, seconds = m.from_scratch()
            row.append(f"{steps:,}, {hours(seconds)} (from {', '.join(_source(p, m.name) for p in m.lineage)})"
                       if m.lineage else "–")
        rows.append(row + [ret(best["mean"]) if "mean" in best else "–",
                           f"**{score_text(m)}** ({m.evaluation.get('episodes', '?')} ep.)",
                           f"{bar_text(m)}: {bar_met(m)}" if m.bar else "none set"])
    head = ["model", "preset", "env steps", "episodes", "wall"]
    head += ["env steps, wall with the runs it started from (`--init-from`)"] if chained else []
    return table(head + ["best selection eval", "unseen seeds", "bar"], rows,
                 "llrrr" + ("r" if chained else "") + "rll")


def _source(parent: dict, name: str) -> str:
    """The model folder a run started from, by its last part (Mario's level): ``2-1``, or ``an earlier
    2-2`` when it is the model's own folder as an earlier run left it."""
    source = str(parent.get("path", "?")).rstrip("/").rsplit("/", 1)[-1]
    return f"an earlier {source}" if source == name else source


def region_sweeps(page: str, experiment: str) -> str:
    """The kept sweeps of one experiment: per-seed scores and mean / median / IQM with 95 % CIs."""
    rows = []
    for m in shipped_models():
        if m.experiment != experiment or m.sweep is None:
            continue
        agg = m.sweep.aggregates
        per_seed = ", ".join(f"{seed}: {sweep_score(score, m)}" for seed, score in m.sweep.seeds)
        cells = [f"{sweep_score(agg[k][0], m)} [{sweep_score(agg[k][1], m)}, {sweep_score(agg[k][2], m)}]"
                 if k in agg else "–" for k in ("iqm", "mean", "median")]
        rows.append([f"[{m.name}]({link(page, m.sweep.folder + '/report.md')})", per_seed, *cells])
    if not rows:
        return "*No sweep over seeds is kept in `results/sweeps/` for this experiment yet.*"
    return table(["model", "score per seed (unseen seeds)", "IQM [95% CI]", "mean [95% CI]",
                  "median [95% CI]"], rows)


def region_sweep_stability(page: str, experiment: str) -> str:
    """Each kept sweep's seeds through training: collapses of the periodic evaluations, the weights kept."""
    from tools.docgen.sweeps import sweep_stability
    return sweep_stability(page, experiment)


def region_seed_summary(page: str, experiment: str) -> str:
    """A paragraph per kept sweep of an experiment: IQM, per-seed scores, the shipped model, collapses."""
    from tools.docgen.sweeps import seed_summary
    return seed_summary(page, experiment)


def region_seed_runs(page: str, experiment: str) -> str:
    """Each kept sweep's seeds: scores (and further evaluations), env steps, wall time, speed, stop."""
    from tools.docgen.sweeps import seed_runs
    return seed_runs(page, experiment)


def region_curves(page: str, experiment: str) -> str:
    """The training curves of the shipped models (and the sweeps' IQM curves), as images."""
    parts = []
    for m in shipped_models():
        if m.experiment != experiment:
            continue
        pngs = sorted((REPO / m.folder).glob("*.png"))
        if pngs:
            parts.append(f"**{m.name}**\n\n" + "\n".join(
                f"![{p.stem}]({link(page, m.folder + '/' + p.name)})" for p in pngs))
        if m.sweep and (REPO / m.sweep.folder / "report_curves.png").is_file():
            parts.append(f"**{m.name}, {len(m.sweep.seeds)} seeds (IQM of the 100-episode average, 95% CI band)**"
                         f"\n\n![{m.name} sweep]({link(page, m.sweep.folder + '/report_curves.png')})")
        if m.sweep and (REPO / m.sweep.folder / "report_success.png").is_file():
            parts.append(f"**{m.name}, {len(m.sweep.seeds)} seeds: the share of the last 100 episodes that reached "
                         f"the {success_word(experiment, m.name, 'goal')}, as the stop rule reads it (IQM, 95% CI band; each seed thin)**\n\n"
                         f"![{m.name} sweep successes]({link(page, m.sweep.folder + '/report_success.png')})")
        if m.sweep and (REPO / m.sweep.folder / "report_evals.png").is_file():
            parts.append(f"**{m.name}, {len(m.sweep.seeds)} seeds: periodic evaluations on selection seeds (IQM, 95% CI "
                         f"band; each seed thin)**\n\n![{m.name} sweep evaluations]"
                         f"({link(page, m.sweep.folder + '/report_evals.png')})")
        if m.sweep and (REPO / m.sweep.folder / "report_critic.png").is_file():
            parts.append(f"**{m.name}, {len(m.sweep.seeds)} seeds: each seed's mean Q of its training batches, "
                         f"running median of 20 episodes (log scale, linear within ±1)**\n\n![{m.name} sweep critic]"
                         f"({link(page, m.sweep.folder + '/report_critic.png')})")
    return "\n\n".join(parts) or "*No curves shipped.*"


REGIONS = {"csv-columns": region_csv_columns, "meta-keys": region_meta_keys, "bars": region_bars,
           "seed-ranges": region_seed_ranges, "presets": region_presets,
           "results-table": region_results_table, "gif-strip": region_gif_strip, "shipped": region_shipped,
           "sweeps": region_sweeps, "sweep-stability": region_sweep_stability,
           "seed-summary": region_seed_summary, "seed-runs": region_seed_runs, "curves": region_curves}
_REGION = re.compile(r"(<!-- generated:([\w-]+)(?: ([\w./-]+))? -->\n)(.*?)(<!-- /generated -->)", re.S)


def fill_regions(page: str, text: str) -> str:
    def replace(m: re.Match) -> str:
        if m[2] not in REGIONS:
            raise SystemExit(f"error: {page}: unknown generated region {m[2]!r}; known: {', '.join(REGIONS)}")
        return f"{m[1]}{REGIONS[m[2]](page, m[3] or '')}\n{m[5]}"
    return _REGION.sub(replace, text)


# ------------------------------------------------------------------------------------- the files
def region_pages() -> list[str]:
    pages = ["README.md"] + sorted(p.relative_to(REPO).as_posix() for p in (REPO / "docs").rglob("*.md"))
    return [p for p in pages if "<!-- generated:" in (REPO / p).read_text()]


