"""The reference pages: the CLI (from the real argparse parser) and every hyperparameter of every
experiment x algorithm x preset (from the registry's dataclasses). Part of :mod:`rlcore.docgen`."""
from __future__ import annotations

import argparse
import dataclasses

from rlcore.allowed import field_words
from rlcore.docgen_data import GENERATED_NOTE
from rlcore.docgen_words import table
from rlcore.experiment import experiment_names, get_experiment

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
    from rlcore.command_line import build_parser

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
