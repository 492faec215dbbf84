"""The docs generator: every number in the README, the docs site and the model cards that comes from an artefact.

``python -m tools.docgen`` fills the templates in ``templates/`` with what :mod:`tools.docgen.data` reads and the rules
below (Jinja filters): whole files (the model cards, ``docs/models/``, ``docs/results.md``, ``docs/reference/``) and
the regions ``<!-- generated:NAME ARG -->`` of the README and the docs pages (``regions/NAME.md``). ``--check`` writes
nothing and exits 1 listing every file that differs. TensorFlow-free."""
import argparse
import json
import os
import re
from collections import Counter

import jinja2

from rlcore.environments import seeding
from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.records.commands import cpus_text
from rlcore.records.critic_trace import WINDOW, critic_cell, critic_trace
from rlcore.records.eval_history import stability_summary, steps_text
from rlcore.records.score_words import hours, return_digits, score_words, stop_words, success_word
from rlcore.training.evaluation import miss_cause
from tools.docgen import data  # its REPO and shipped_models read at each call (tests point them elsewhere)

ENV = jinja2.Environment(loader=jinja2.PackageLoader("tools.docgen"), undefined=jinja2.StrictUndefined,
                         trim_blocks=True, lstrip_blocks=True, extensions=["jinja2.ext.do"])  # templates/
REGION = re.compile(r"(<!-- generated:([\w-]+)(?: ([\w./-]+))? -->\n)(.*?)(<!-- /generated -->)", re.S)


def generate() -> dict[str, str]:
    """Every file the generator owns or fills: repo-relative path -> its text."""
    models = data.shipped_models()
    out = {m.card: render("model.md", m=m, page=m.card, docs=False) for m in models}
    out |= {m.page: render("model.md", m=m, page=m.page, docs=True) for m in models}
    out |= {"docs/models/index.md": render("models_index.md", models=models),
            "docs/results.md": render("results.md", page="docs/results.md", models=models),
            "docs/reference/cli.md": render("cli.md", helps=data.cli_help()),
            "docs/reference/hyperparameters.md": render("hyperparameters.md")}
    out = {path: text + "\n" for path, text in out.items()}
    pages = ["README.md"] + sorted(p.relative_to(data.REPO).as_posix() for p in (data.REPO / "docs").rglob("*.md"))
    texts = {page: (data.REPO / page).read_text() for page in pages if page not in out}
    return out | {page: fill_regions(page, text) for page, text in texts.items() if "<!-- generated:" in text}


def render(template: str, **values) -> str:
    """``templates/TEMPLATE`` filled with ``values``, less its last newlines (a region: ``regions/NAME.md``)."""
    return ENV.get_template(template).render(values).rstrip("\n")


def fill_regions(page: str, text: str) -> str:
    """``text`` of ``page`` with each generated region written anew."""
    def fill(m: re.Match) -> str:
        try:
            return f"{m[1]}{render(f'regions/{m[2]}.md', page=page, arg=m[3] or '')}\n{m[5]}"
        except jinja2.TemplateNotFound:
            known = ", ".join(name[8:-3] for name in ENV.list_templates() if name.startswith("regions/"))
            raise SystemExit(f"error: {page}: unknown generated region {m[2]!r}; known: {known}") from None
    return REGION.sub(fill, text)


@jinja2.pass_context
def link(context, target: str) -> str:
    """A relative link from the file being written (``page``) to ``target``; hooks.py mounts those for the site."""
    return os.path.relpath(target, os.path.dirname(context["page"]) or ".").replace(os.sep, "/")


def ret(value: float, near: float | None = None) -> str:
    """A return with the README's digits for a score near ``near`` (itself when not given): 257.4, 18.56."""
    return f"{value:,.{return_digits(value if near is None else near)}f}"


def sweep_score(value: float, model) -> str:
    """A score (a seed's, an IQM...) with the model's shipped score's digits: ``257.4``, ``18.56``, or ``80%``."""
    if "success_share" in model.evaluation:
        return f"{value:.0%}"
    return f"{value:,.{return_digits(model.evaluation['mean']) if 'mean' in model.evaluation else 1}f}"


def score_text(model) -> str:
    """``270.7 ± 21.4`` or ``flag in 8 of 10``: the shipped score on unseen seeds."""
    return score_words(model.evaluation, model.experiment, model.name) if model.evaluation else "not evaluated"


def bar_text(model, met: str = "") -> str:
    """``flag in >= 80% of episodes``, or ``none set``; given ``met`` (``": "``), whether the model met it after it."""
    if model.bar is None:
        return "none set"
    return model.bar.describe(success_word(model.experiment, model.name)) + (met + bar_met(model) if met else "")


def bar_met(model) -> str:
    if model.bar is None or not model.evaluation:
        return ""
    return "met" if model.bar.met_by(model.evaluation) else "**not met**"


def interval(model, statistic: str) -> str:
    """``14.84 [4.33, 20.02]``: a statistic of the model's kept sweep with its 95% interval (``–`` where none is)."""
    found = model.sweep.aggregates.get(statistic) if model.sweep else None
    return "{} [{}, {}]".format(*(sweep_score(value, model) for value in found)) if found else "–"


def over_seeds(model, bold: str | None = None) -> str:
    """The recipe over seeds in the statistic its bar over seeds is set on (else the IQM) with its 95% interval: a cell
    ``IQM over 5: 14.84 [4.33, 20.02]`` (``–`` without a kept sweep), or ``IQM {bold}**14.84 [4.33, 20.02]**``."""
    statistic = model.bar.over_seeds.statistic if model.bar and model.bar.over_seeds else "iqm"
    value = interval(model, statistic)
    name = "IQM" if statistic == "iqm" or value == "–" else statistic
    if bold is not None:
        return f"{name} {bold}**{value}**"
    return f"{name} over {len(model.sweep.seeds)}: {value}" if value != "–" else "–"


def replaced_text(old: dict | None, m) -> str | None:
    """The shipped model this one replaced (``main.py train --publish``): its score, and what training it cost."""
    if not old:
        return None
    ev, commands = old.get("evaluation") or {}, old.get("commands") or 0
    score = score_words(ev, m.experiment, m.name) if ev else "not evaluated"
    seeds = f" (seeds {ev['seeds']})" if ev.get("seeds") else ""
    return (f"{score}{seeds}; trained by {commands or 'unrecorded'} command{'s' * (commands != 1)} "
            f"(`{old.get('preset')}` preset), {old.get('env_steps', 0):,} env steps, "
            f"{hours(old.get('wall_seconds', 0))}")


def collapses_cell(collapses: list) -> str:
    """``2: 40k → 58k, 124k → 138k`` (``never`` for one not recovered); ``none``."""
    if not collapses:
        return "none"
    return f"{len(collapses)}: " + ", ".join(
        f"{steps_text(c.env_steps)} → {steps_text(c.recovered_at) if c.recovered_at is not None else 'never'}"
        for c in collapses)


def seeds_bar_text(m) -> str:
    """`` Bar over seeds: IQM >= 11.3 (why): **met**.``, the registry's bar for the recipe over seeds and the kept
    sweep's verdict; empty where none is set."""
    bar = m.bar.over_seeds if m.bar else None
    if bar is None or bar.statistic not in m.sweep.aggregates:
        return ""
    scores = [score for _, score in m.sweep.seeds]
    met = bar.met_by(m.sweep.aggregates[bar.statistic][0], scores)
    verdict = ({True: "**met**", False: "**not met**"}[met] if met is not None
               else f"not judged yet ({len(scores)} of {bar.seeds} seeds kept)")
    return f" Bar over seeds: {bar.describe('success_share' in m.evaluation)} ({bar.reason}): {verdict}."


def evaluation_cell(evaluation: dict, m) -> str:
    """``flag in 9 of 10``, ``257.4 over 100``, or where the bar asks for full-length episodes ``18.56 over 30 (93%
    full length)``: one recorded evaluation, with the shipped score's digits."""
    if "success_share" in evaluation:
        return score_words(evaluation, m.experiment, m.name)
    share = evaluation.get("time_limit_share")
    full = share is not None and m.bar is not None and m.bar.full_length_share is not None
    return f"{sweep_score(evaluation['mean'], m)} over {evaluation['episodes']}" + (
        f" ({share:.0%} full length)" if full else "")


def misses(m) -> list[tuple[float, str]]:
    """Each miss of the evaluation: (its progress, Mario's x; what ended it: its cause, the stall limit, or
    neither), from its per-episode records."""
    goal, found = get_experiment(m.experiment).goal, []
    for r in m.evaluation.get("per_episode") or [] if goal and goal.progress_key else []:
        if not r.get("success") and goal.progress_key in r:
            cause = miss_cause(r, goal.cause_key, goal.cause_name) or "no cause recorded"
            found.append((r[goal.progress_key], cause))
    return found


def miss_causes(m) -> str:
    """``stalled 15, fell 1``: what ended the evaluation's misses, most first (the recorded causes where the
    evaluation kept no per-episode records)."""
    counts = Counter(cause for _, cause in misses(m)) or Counter(m.evaluation.get("causes") or {})
    return ", ".join(f"{cause} {n}" for cause, n in counts.most_common())


def miss_places(m, most: int = 5) -> str:
    """Where the evaluation's misses ended, most first: ``2,600-2,699: stalled 12; 1,700-1,799: Goomba 3`` (the
    progress in blocks of 100, and what ended each miss)."""
    places = Counter((int(x) // 100 * 100, cause) for x, cause in misses(m))
    return "; ".join(f"{x:,}-{x + 99:,}: {cause} {n}" for (x, cause), n in places.most_common(most))


def stop_text(meta: dict, m) -> str:
    """What ended the run of ``meta``, a run of model ``m``, in words (``rlcore.records.score_words.stop_words``)."""
    return stop_words(meta.get("stopped_by") or "", m.experiment, m.name, (meta.get("config") or {}).get("window", 100))


ENV.filters.update({f.__name__: f for f in (
    link, ret, sweep_score, score_text, bar_text, bar_met, interval, over_seeds, replaced_text,
    collapses_cell, seeds_bar_text, evaluation_cell, stop_text, miss_causes, miss_places,
    hours, steps_text, success_word, cpus_text,
    critic_cell, critic_trace, stability_summary)}, json=json.dumps, fmt=format,  # fmt: x|fmt(",.1f"), a format spec
    brief_cpu=lambda text: re.sub(r" \([^)]*\)|\(R\)| Processor", "", text))  # a CPU in a table cell: AMD EPYC
ENV.globals.update(data=data, experiment=get_experiment, experiment_names=experiment_names, render=render,
                   seeding=seeding, zip=zip, critic_window=WINDOW)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.docgen", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 listing every file that differs from what would be written")
    check, out = parser.parse_args(argv).check, generate()
    stale = [p for p, text in out.items() if not (data.REPO / p).is_file() or (data.REPO / p).read_text() != text]
    gone = (p.relative_to(data.REPO).as_posix() for p in (data.REPO / "docs/models").glob("*.md"))
    stale += sorted(path for path in gone if path not in out)  # the generated model pages whose model is gone
    if check:
        print("docs out of date (run `python -m tools.docgen`):\n  " + "\n  ".join(stale) if stale
              else f"docs up to date ({len(out)} files)")
        return 1 if stale else 0
    for path in stale:
        target = data.REPO / path
        if path in out:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.with_name(target.name + ".tmp").write_text(out[path])
            os.replace(target.with_name(target.name + ".tmp"), target)
        else:
            target.unlink()
        print(f"{'wrote' if path in out else 'removed'} {path}")
    print(f"{len(stale)} of {len(out)} files changed")
    return 0
