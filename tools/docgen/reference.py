"""The reference pages: the CLI (from the real argparse parser) and every hyperparameter of every
experiment x algorithm x preset (from the registry's dataclasses); and the regions of hand-written pages
that state reference facts: the CSV columns and meta.json keys of the shipped models, the bars, the
presets' differences, the seed ranges. Part of :mod:`tools.docgen`."""
from __future__ import annotations

import argparse
import dataclasses

from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.hyperparams.allowed import field_words
from rlcore.runs.score_words import success_word
from tools.docgen.data import GENERATED_NOTE, REPO, shipped_models
from tools.docgen.words import link, table

HELP_WIDTH = 100  # fixed, so the page does not depend on the terminal that generated it


def _help(parser: argparse.ArgumentParser) -> str:
    """``--help`` at a fixed width, in the parser's own formatter (the top one keeps its examples' lines)."""
    kind = parser.formatter_class
    parser.formatter_class = lambda prog: kind(prog, width=HELP_WIDTH)
    return parser.format_help().rstrip()


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def cli_page() -> str:
    from rlcore.cli.parser import build_parser

    parser = build_parser(["list"])
    parts = [GENERATED_NOTE, "", "# Command line", "",
             "`python main.py COMMAND ...` (or the `deeprl` console script, the same commands). This page is "
             "the parser's own `--help`, written by the docs generator, so it cannot fall behind the code.", "",
             "`train` adds one flag per hyperparameter once EXPERIMENT and ALGO are given "
             "(`python main.py train lunar_lander dqn --help`); they are listed, with each preset's values, on the "
             "[hyperparameters](hyperparameters.md) page.", "",
             "```text", _help(parser), "```", ""]
    for name, sub in _subcommands(parser).items():
        parts += [f"## {name}", "", "```text", _help(sub), "```", ""]
    return "\n".join(parts)


def _value(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, tuple):
        return ",".join(map(str, value)) or "(empty)"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def hyperparameters_page() -> str:
    parts = [GENERATED_NOTE, "", "# Hyperparameters", "",
             "Every field of every preset, read from the registry's dataclasses: the flag that overrides it "
             "(`python main.py train EXPERIMENT ALGO --preset NAME --flag VALUE`), its value in each preset, "
             "the values it allows (checked when the command line is parsed, before any run folder exists) "
             "and what it does. A preset's values are the defaults of its `--help`.", ""]
    for name in experiment_names():
        exp = get_experiment(name)
        parts += [f"## {name}", "", exp.description + ".", ""]
        for algo, spec in exp.algos.items():
            presets = spec.presets
            default = presets[spec.default_preset]
            parts += [f"### {name} {algo}", "",
                      f"{spec.description}. Presets: " + ", ".join(f"`{p}`" for p in presets)
                      + f" (default `{spec.default_preset}`); config class `{type(default).__name__}`.", ""]
            rows = []
            for f in dataclasses.fields(default):
                values = [_value(getattr(p, f.name)) if hasattr(p, f.name) else "–" for p in presets.values()]
                # a value that differs from the default preset's is shown in bold
                shown = [f"**{v}**" if v != values[list(presets).index(spec.default_preset)] else v for v in values]
                rows.append([f"`--{f.name.replace('_', '-')}`", *shown,
                             field_words(f) or ("true or false" if f.type in (bool, "bool") else ""),
                             f.metadata.get("help", "").replace("%%", "%").replace("|", "\\|")])
            parts += [table(["flag", *[f"`{p}`" for p in presets], "allowed", "what it does"], rows), ""]
    return "\n".join(parts)


def preset_differences(experiment: str, reference: str) -> str:
    """Per algorithm of ``experiment``, the fields whose value differs between its presets (algorithms
    whose differences are the same share one table)."""
    exp = get_experiment(experiment)
    groups: dict[tuple, list[str]] = {}
    for algo, spec in exp.algos.items():
        presets = spec.presets
        rows = []
        for f in dataclasses.fields(presets[spec.default_preset]):
            values = [_value(getattr(p, f.name)) if hasattr(p, f.name) else "–" for p in presets.values()]
            if len(set(values)) > 1:
                rows.append((f"`--{f.name.replace('_', '-')}`", *values))
        if rows:
            groups.setdefault((tuple(presets), tuple(rows)), []).append(algo)
    parts = []
    for (names, rows), algos in groups.items():
        parts += [", ".join(f"**{a}**" for a in algos), "",
                  table(["flag", *[f"`{p}`" for p in names]], [list(r) for r in rows]), ""]
    parts.append(f"Every other field is the same in all presets: see [hyperparameters]({reference}#{experiment}).")
    return "\n".join(parts)


# ------------------------------------------------------------------ regions of hand-written pages
def region_csv_columns(page: str, arg: str) -> str:
    """The columns of each CSV a shipped model folder holds (of experiment ARG, or all), read from the
    files themselves: every column any of them holds (a model trained before a column was added lacks
    it; one marked * is in some of the files only)."""
    seen: dict[tuple[str, str, str], list[list[str]]] = {}
    for m in shipped_models():
        if arg and m.experiment not in arg.split("/"):
            continue
        for csv_path in sorted((REPO / m.folder).glob("*.csv")):
            with csv_path.open() as f:
                seen.setdefault((m.experiment, m.meta.get("kind", m.algo), csv_path.name), []).append(
                    f.readline().strip().split(","))
    rows = []
    for (experiment, kind, name), headers in seen.items():
        columns = list(dict.fromkeys(c for header in headers for c in header))
        rows.append([f"`{name}`", experiment, kind, ", ".join(
            f"`{c}`" + ("" if all(c in header for header in headers) else "*") for c in columns)])
    partial = any(row[3].count("*") for row in rows)
    return table(["file", "experiment", "trainer", "columns"], rows) + (
        "\n\n\\* in some of the shipped models' files only: those trained before it was added lack it." if partial else "")


def region_meta_keys(page: str, arg: str) -> str:
    """Which keys the shipped meta.json files hold, and in how many of them."""
    counts: dict[str, int] = {}
    models = shipped_models()
    for m in models:
        for key in m.meta:
            counts[key] = counts.get(key, 0) + 1
        for key in m.evaluation:
            counts[f"evaluation.{key}"] = counts.get(f"evaluation.{key}", 0) + 1
    return table(["key", "in shipped meta.json files"],
                 [[f"`{k}`", f"{n} of {len(models)}"] for k, n in counts.items()], "lr")


def region_bars(page: str, arg: str) -> str:
    """Every bar in the registry with its reason, and where one is set, the recipe's bar over seeds (its
    kept sweep's statistic) with its own."""
    rows = []
    for name in experiment_names():
        for model, bar in get_experiment(name).bars.items():
            rows.append([name, model, bar.describe(success_word(name, model)), bar.reason])
            if bar.over_seeds:
                seeds = bar.over_seeds
                rows.append([name, f"{model}, its recipe over seeds",
                             seeds.describe(bar.metric == "success_share"), seeds.reason])
    return table(["experiment", "model", "bar", "why this number"], rows)


def region_presets(page: str, arg: str) -> str:
    """How the presets of experiment ARG differ, field by field, linking the hyperparameters page."""
    return preset_differences(arg, link(page, "docs/reference/hyperparameters.md"))


def region_seed_ranges(page: str, arg: str) -> str:
    """Which seeds evaluate, select and train, per experiment, from the registry and rlcore.environments.seeding."""
    from rlcore.environments import seeding

    rows = []
    for name in experiment_names():
        exp = get_experiment(name)
        rows.append([name, f"{exp.eval_episodes}", f"from {exp.eval_seed_base:,}", f"from {exp.selection_seed_base:,}"])
    text = table(["experiment", "final evaluation episodes", "final evaluation seeds", "selection seeds"], rows, "lrrr")
    zero = seeding.seed_block(0)
    one = seeding.seed_block(1)
    return text + (f"\n\nTraining env seeds stay below {seeding.TRAINING_SEED_SPAN:,}: run seed 0 uses "
                   f"{zero.start:,}-{zero.stop - 1:,}, and each run seed from 1 to {seeding.MAX_RUN_SEED} owns "
                   f"its own block of {len(one):,} (seed 1: {one.start:,}-{one.stop - 1:,}).")
