"""The reference pages: the CLI (from the real argparse parser) and every hyperparameter of every
experiment x algorithm x preset (from the registry's dataclasses); and the regions of hand-written pages
that state reference facts: the CSV columns and meta.json keys of the shipped models, the bars, the
presets' differences, the seed ranges."""
import argparse
import dataclasses
from collections import Counter

from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.hyperparams.allowed import field_words
from rlcore.records.score_words import success_word
from tools.docgen.data import REPO, shipped_models
from tools.docgen.words import fill, link, table

HELP_WIDTH = 100  # fixed, so the page does not depend on the terminal that generated it


def cli_page() -> str:
    """The parser's own ``--help`` and each subcommand's."""
    from rlcore.cli.parser import build_parser

    parser = build_parser(["list"])
    subcommands = next((a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), {})
    return fill("cli.md", help=_help(parser), subcommands="\n\n".join(
        f"## {name}\n\n```text\n{_help(sub)}\n```" for name, sub in subcommands.items())) + "\n"


def _help(parser: argparse.ArgumentParser) -> str:
    """``--help`` at a fixed width, in the parser's own formatter (the top one keeps its examples' lines)."""
    kind = parser.formatter_class
    parser.formatter_class = lambda prog: kind(prog, width=HELP_WIDTH)
    return parser.format_help().rstrip()


def _value(value) -> str:
    """A preset's value as its flag takes it: ``true``, ``64,64``, ``0.0003``."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, tuple):
        return ",".join(map(str, value)) or "(empty)"
    return f"{value:g}" if isinstance(value, float) else str(value)


def preset_fields(spec) -> list[tuple[str, dataclasses.Field, list[str]]]:
    """(flag, field, its value in each preset) for every field of an algorithm's default preset."""
    return [(f"`--{f.name.replace('_', '-')}`", f,
             [_value(getattr(p, f.name)) if hasattr(p, f.name) else "–" for p in spec.presets.values()])
            for f in dataclasses.fields(spec.presets[spec.default_preset])]


def hyperparameters_page() -> str:
    """Every field of every preset, per experiment and algorithm."""
    blocks = []
    for name in experiment_names():
        blocks += [f"## {name}", get_experiment(name).description + "."]
        for algo, spec in get_experiment(name).algos.items():
            presets, default = list(spec.presets), spec.presets[spec.default_preset]
            blocks += [f"### {name} {algo}",
                       f"{spec.description}. Presets: {', '.join(f'`{p}`' for p in presets)} (default "
                       f"`{spec.default_preset}`); config class `{type(default).__name__}`.",
                       table(["flag", *[f"`{p}`" for p in presets], "allowed", "what it does"], field_rows(spec))]
    return fill("hyperparameters.md", experiments="\n\n".join(blocks)) + "\n"


def field_rows(spec) -> list[list[str]]:
    """A row per field: its flag, its value in each preset (in bold where unlike the default preset's), what it
    allows and what it does."""
    default = list(spec.presets).index(spec.default_preset)
    return [[flag, *[f"**{v}**" if v != values[default] else v for v in values],
             field_words(f) or ("true or false" if f.type in (bool, "bool") else ""),
             f.metadata.get("help", "").replace("%%", "%").replace("|", "\\|")]
            for flag, f, values in preset_fields(spec)]


def region_presets(page: str, experiment: str) -> str:
    """Per algorithm of ``experiment``, the fields whose value differs between its presets (algorithms
    whose differences are the same share one table), linking the hyperparameters page."""
    groups: dict[tuple, list[str]] = {}
    for algo, spec in get_experiment(experiment).algos.items():
        if rows := tuple((flag, *values) for flag, _, values in preset_fields(spec) if len(set(values)) > 1):
            groups.setdefault((tuple(spec.presets), rows), []).append(algo)
    tables = [", ".join(f"**{a}**" for a in algos) + "\n\n" + table(["flag", *[f"`{p}`" for p in names]], rows)
              for (names, rows), algos in groups.items()]
    return "\n\n".join([*tables, "Every other field is the same in all presets: see [hyperparameters]"
                        f"({link(page, 'docs/reference/hyperparameters.md')}#{experiment})."])


def region_csv_columns(page: str, arg: str) -> str:
    """The columns of each CSV a shipped model folder holds (of experiment ARG, or all), read from the
    files themselves: every column any of them holds (a model trained before a column was added lacks
    it; one marked * is in some of the files only)."""
    seen: dict[tuple[str, str, str], list[list[str]]] = {}
    for m in (m for m in shipped_models() if not arg or m.experiment in arg.split("/")):
        for path in sorted((REPO / m.folder).glob("*.csv")):
            with path.open() as f:
                seen.setdefault((m.experiment, m.meta.get("kind", m.algo), path.name), []).append(
                    f.readline().strip().split(","))
    rows = []
    for (experiment, kind, name), headers in seen.items():
        columns = dict.fromkeys(column for header in headers for column in header)
        marked = [f"`{c}`" + ("" if all(c in header for header in headers) else "*") for c in columns]
        rows.append([f"`{name}`", experiment, kind, ", ".join(marked)])
    partial = "\n\n\\* in some of the shipped models' files only: those trained before it was added lack it."
    return table(["file", "experiment", "trainer", "columns"], rows) + (partial if any("*" in r[3] for r in rows) else "")


def region_meta_keys(page: str, arg: str) -> str:
    """Which keys the shipped meta.json files hold, and in how many of them."""
    models = shipped_models()
    counts = Counter(key for m in models for key in [*m.meta, *(f"evaluation.{k}" for k in m.evaluation)])
    rows = [[f"`{key}`", f"{n} of {len(models)}"] for key, n in counts.items()]
    return table(["key", "in shipped meta.json files"], rows, "lr")


def region_bars(page: str, arg: str) -> str:
    """Every bar in the registry with its reason, and where one is set, the recipe's bar over seeds (its
    kept sweep's statistic) with its own."""
    rows = []
    for name in experiment_names():
        for model, bar in get_experiment(name).bars.items():
            rows.append([name, model, bar.describe(success_word(name, model)), bar.reason])
            if seeds := bar.over_seeds:
                rows.append([name, f"{model}, its recipe over seeds", seeds.describe(bar.metric == "success_share"),
                             seeds.reason])
    return table(["experiment", "model", "bar", "why this number"], rows)


def region_seed_ranges(page: str, arg: str) -> str:
    """Which seeds evaluate, select and train, per experiment, from the registry and rlcore.environments.seeding."""
    from rlcore.environments import seeding

    rows = []
    for name in experiment_names():
        exp = get_experiment(name)
        rows.append([name, f"{exp.eval_episodes}", f"from {exp.eval_seed_base:,}", f"from {exp.selection_seed_base:,}"])
    zero, one = seeding.seed_block(0), seeding.seed_block(1)
    header = ["experiment", "final evaluation episodes", "final evaluation seeds", "selection seeds"]
    return (table(header, rows, "lrrr") + f"\n\nTraining env seeds stay below {seeding.TRAINING_SEED_SPAN:,}: run seed 0 uses "
            f"{zero.start:,}-{zero.stop - 1:,}, and each run seed from 1 to {seeding.MAX_RUN_SEED} owns "
            f"its own block of {len(one):,} (seed 1: {one.start:,}-{one.stop - 1:,}).")
