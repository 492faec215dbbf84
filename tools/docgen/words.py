"""The words and numbers the docs generator writes, one rule each: a return with the README's digits, a
shipped score and its bar, the recipe over seeds, a relative link, a Markdown table, a template filled."""
import os
import re
from pathlib import Path
from string import Template

from rlcore.environments.registry import get_experiment
from rlcore.records.score_words import return_digits, score_words, success_word

TEMPLATES = Path(__file__).parent / "templates"
#: where one registry entry covers two articles, which algorithm comes from which
ARTICLE_OF_ALGO = {(exp, algo): article for exp in ("cartpole", "cartpole_v0")
                   for algo, article in (("dqn", "003"), ("a2c", "002"))}


def fill(template: str, **values) -> str:
    """``templates/TEMPLATE`` with ``values`` in its ``$fields``, less each line with a field whose value is
    None (an optional row); the file's last newline is not part of the text."""
    lines = (TEMPLATES / template).read_text().removesuffix("\n").split("\n")
    kept = [line for line in lines if all(values.get(field, "") is not None for field in re.findall(r"\$(\w+)", line))]
    return Template("\n".join(kept)).substitute(values)


def table(header: list[str], rows: list[list[str]], align: str | None = None) -> str:
    """A Markdown table; ``align`` has a letter per column: l(eft), r(ight) or c(entre)."""
    marks = {"l": "---", "r": "---:", "c": ":---:"}
    lines = [header, [marks[a] for a in align or "l" * len(header)], *rows]
    return "\n".join("| " + " | ".join(str(cell) for cell in line) + " |" for line in lines)


def link(page: str, target: str) -> str:
    """A relative link from the file ``page`` to ``target`` (both repo-relative), true in the repository; on the
    docs site, tools/docgen/hooks.py points those into saved_networks/ and results/ at their mounted copies."""
    return os.path.relpath(target, os.path.dirname(page) or ".").replace(os.sep, "/")


def ret(value: float, near: float | None = None) -> str:
    """A return with the README's digits for a score near ``near`` (itself when not given): 257.4, 18.56."""
    return f"{value:,.{return_digits(value if near is None else near)}f}"


def sweep_score(value: float, model) -> str:
    """A score of the model's experiment (a seed's, an IQM, an evaluation's) with the shipped score's
    digits: ``257.4``, Minitaur's ``18.56``, or a share ``80%``."""
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


def interval(point_low_high: tuple[float, float, float], model) -> str:
    """``14.84 [4.33, 20.02]``: a sweep's statistic with its 95% interval."""
    point, low, high = (sweep_score(value, model) for value in point_low_high)
    return f"{point} [{low}, {high}]"


def over_seeds(model, bold: str | None = None) -> str:
    """The recipe over seeds in one statistic and its 95% interval, from the kept sweep's report: the one its
    bar over seeds is set on (Mario 1-1: the median of 3), else the IQM. A cell ``IQM over 5: 14.84 [4.33,
    20.02]`` (``–`` where no sweep is kept), or with ``bold`` (what follows its name) ``IQM **14.84 [...]**``."""
    statistic = model.bar.over_seeds.statistic if model.bar and model.bar.over_seeds else "iqm"
    found = model.sweep.aggregates.get(statistic) if model.sweep else None
    name = "IQM" if statistic == "iqm" or not found else statistic
    value = interval(found, model) if found else "–"
    if bold is not None:
        return f"{name} {bold}**{value}**"
    return f"{name} over {len(model.sweep.seeds)}: {value}" if found else "–"


def article_of(experiment: str, algo: str | None = None) -> str:
    """The source article a model reproduces (the registry's description names it)."""
    if (experiment, algo) in ARTICLE_OF_ALGO:
        return ARTICLE_OF_ALGO[(experiment, algo)]
    found = re.search(r"articles? ([\d/]+)$", get_experiment(experiment).description)
    return found[1] if found else ""
