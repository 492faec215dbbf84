"""The words and numbers the docs generator writes, one rule each: a return with the README's digits,
a shipped score, its bar, the recipe over seeds, a relative link, a Markdown table. Shared by
:mod:`tools.docgen` and its parts (cards, sweeps, reference pages); TensorFlow-free."""
from __future__ import annotations

import os
import re

from rlcore.algorithms.registry import FAMILIES
from rlcore.environments.registry import get_experiment
from rlcore.runs.score_words import hours, return_digits, score_words, success_word  # noqa: F401 (hours: the docs' parts import it here)
from tools.docgen.data import Model


def num(value: float, digits: int = 1) -> str:
    return f"{value:,.{digits}f}"


def ret(value: float, near: float | None = None) -> str:
    """A return with the README's digits for a score near ``near`` (itself when not given): 257.4, 18.56."""
    return num(value, return_digits(value if near is None else near))


def score_value(model: Model) -> float | None:
    ev = model.evaluation
    return ev.get("success_share", ev.get("mean"))


def score_text(model: Model) -> str:
    """``270.7 ± 21.4`` or ``flag in 8 of 10``: the shipped score on unseen seeds."""
    if not model.evaluation:
        return "not evaluated"
    return score_words(model.evaluation, model.experiment, model.name)


def policy_text(model: Model) -> str:
    ev = model.evaluation
    acts = FAMILIES.get(model.meta.get("kind"))
    if acts and not acts.discrete and ev.get("policy") == "greedy":
        return "the mean action (deterministic)"
    if ev.get("policy") == "greedy":
        return "greedy (argmax)"
    return ev.get("policy", "?")


def eval_text(model: Model) -> str:
    """``100 episodes on seeds 1000000..1000099, greedy (argmax)``."""
    ev = model.evaluation
    return f"{ev.get('episodes')} episodes on seeds {ev.get('seeds')}, {policy_text(model)}"


def bar_text(model: Model) -> str:
    if model.bar is None:
        return "none set"
    return model.bar.describe(success_word(model.experiment, model.name))


def bar_met(model: Model) -> str:
    if model.bar is None or not model.evaluation:
        return ""
    return "met" if model.bar.met_by(model.evaluation) else "**not met**"


def sweep_score(value: float, model: Model) -> str:
    """A score of the model's experiment (a seed's, an IQM, an evaluation's) with the shipped score's
    digits: ``257.4``, Minitaur's ``18.56``, or a share ``80%``."""
    if "success_share" in model.evaluation:
        return f"{value:.0%}"
    return num(value, return_digits(model.evaluation["mean"]) if "mean" in model.evaluation else 1)


def over_seeds(model: Model) -> tuple[str, str] | None:
    """The recipe over seeds in one statistic and its 95% interval, from the kept sweep's report:
    ``("IQM", "14.84 [4.33, 20.02]")``; the statistic is the one its bar over seeds is set on (Mario
    1-1: the median of 3), else the IQM. None where no sweep is kept."""
    bar = model.bar.over_seeds if model.bar else None
    statistic = bar.statistic if bar else "iqm"
    if model.sweep is None or statistic not in model.sweep.aggregates:
        return None
    point, low, high = model.sweep.aggregates[statistic]
    return ("IQM" if statistic == "iqm" else statistic,
            f"{sweep_score(point, model)} [{sweep_score(low, model)}, {sweep_score(high, model)}]")


def over_seeds_cell(model: Model) -> str:
    """A table cell: ``IQM over 5: 14.84 [4.33, 20.02]``, or ``–``."""
    if (found := over_seeds(model)) is None:
        return "–"
    return f"{found[0]} over {len(model.sweep.seeds)}: {found[1]}"


def over_seeds_bold(model: Model, between: str = "") -> str:
    """In a sentence: ``IQM **14.84 [4.33, 20.02]**`` (``between`` goes after the statistic's name)."""
    name, value = over_seeds(model) or ("IQM", "–")
    return f"{name} {between}**{value}**"


#: the header of the column :func:`over_seeds_cell` fills
OVER_SEEDS_HEADER = "same recipe over seeds [95% CI]"


#: where one registry entry covers two articles, which algorithm comes from which
ARTICLE_OF_ALGO = {("cartpole", "dqn"): "003", ("cartpole", "a2c"): "002", ("cartpole_v0", "dqn"): "003",
                   ("cartpole_v0", "a2c"): "002"}


def article_of(experiment: str, algo: str | None = None) -> str:
    if (experiment, algo) in ARTICLE_OF_ALGO:
        return ARTICLE_OF_ALGO[(experiment, algo)]
    m = re.search(r"articles? ([\d/]+)$", get_experiment(experiment).description)
    return m[1] if m else ""


def link(page: str, target: str) -> str:
    """A relative link from the file ``page`` to ``target`` (both repo-relative), true in the repository
    (GitHub reads it as written); the docs site serves saved_networks/ and results/ as if under docs/,
    and its hook points such links there (tools/docgen/hooks.py)."""
    return os.path.relpath(target, os.path.dirname(page) or ".").replace(os.sep, "/")


def model_page(model: Model) -> str:
    return f"docs/models/{model.slug}.md"


def table(header: list[str], rows: list[list[str]], align: str | None = None) -> str:
    align = align or "l" * len(header)
    marks = ["---:" if a == "r" else ":---:" if a == "c" else "---" for a in align]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(marks) + " |"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)
