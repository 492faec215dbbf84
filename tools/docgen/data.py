"""What the docs generator reads: the shipped models (``saved_networks/*/*/meta.json``), the sweeps kept in
``results/sweeps/`` and their runs, the CSV headers and the registry's presets. TensorFlow-free."""
import argparse
import dataclasses
import functools
import json
import re
from pathlib import Path

from rlcore.algorithms.registry import FAMILIES
from rlcore.cli.parser import build_parser
from rlcore.environments.experiment import Bar
from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.files.model_meta import cost_from_scratch, lineage
from rlcore.hyperparams.allowed import field_words
from rlcore.hyperparams.flags import to_dict
from rlcore.records.eval_history import story

REPO = Path(__file__).resolve().parents[2]
#: the Gymnasium id each experiment's models play (Mario's depends on the level)
ENV_IDS = {"lunar_lander": "LunarLander-v3", "cartpole": "CartPole-v1", "cartpole_v0": "CartPole-v0",
           "mario_ppo": "SuperMarioBros-{model}-v0", "minitaur": "deeprl/Minitaur-v0"}
# in a sweep's report.md, an aggregate's row (| iqm | 14.84 | [4.33, 20.02] |) and a run's (| trial | seed | score |
# ..., where a goal's share gives the episodes behind it: 0.800 (8 of 10))
AGGREGATE_ROW = re.compile(r"^\| (mean|median|iqm) \| (-?[\d.]+) \| \[(-?[\d.]+), (-?[\d.]+)\] \|$")
RUN_ROW = re.compile(r"^\| [^|]+ \| \d+ \| (-?[\d.]+)(?: \(\d+ of \d+\))? \|", re.M)
#: where one registry entry covers two articles, which algorithm comes from which
ARTICLE_OF_ALGO = {(exp, algo): article for exp in ("cartpole", "cartpole_v0")
                   for algo, article in (("dqn", "003"), ("a2c", "002"))}


@dataclasses.dataclass
class Sweep:
    """A kept sweep (results/sweeps/NAME) of one shipped model's recipe over seeds."""
    folder: str  # repo-relative
    seeds: list[tuple[int, float]]  # (seed, final score on unseen seeds), from each run's meta.json
    aggregates: dict[str, tuple[float, float, float]]  # mean/median/iqm -> (point, low, high), from report.md

    def __post_init__(self):
        self.report = f"{self.folder}/report.md"


@dataclasses.dataclass
class Model:
    """One shipped model folder, with the names and places the docs give it."""
    experiment: str
    name: str  # the algorithm, or Mario's level
    folder: str  # repo-relative, e.g. saved_networks/lunar_lander/dqn
    meta: dict
    bar: Bar | None
    sweep: Sweep | None = None

    def __post_init__(self):
        self.algo, self.evaluation = self.meta.get("algo"), self.meta.get("evaluation") or {}
        self.slug, self.card = f"{self.experiment}_{self.name}", f"{self.folder}/README.md"
        self.page = f"docs/models/{self.slug}.md"  # the card on the docs site
        self.env_id = ENV_IDS.get(self.experiment, self.experiment).format(model=self.name)
        gif = f"docs/assets/gifs/{self.slug}.gif"  # written by `make gifs`
        self.gif = gif if (REPO / gif).is_file() else None
        self.family = FAMILIES.get(self.meta.get("kind"))  # how its algorithm acts: discrete, stochastic
        self.algo_name = get_experiment(self.experiment).algos[self.algo].description.split(",")[0]  # Dueling DDQN
        self.lineage = lineage(self.meta)  # the runs whose weights its run started from (--init-from), nearest first
        page = "cartpole" if self.experiment == "cartpole_v0" else self.experiment  # v0 shares CartPole's page
        self.experiment_page = f"docs/experiments/{page}.md"
        found = re.search(r"articles? ([\d/]+)$", get_experiment(self.experiment).description)  # the source article
        self.article = ARTICLE_OF_ALGO.get((self.experiment, self.algo), found[1] if found else "")

    def from_scratch(self) -> tuple[int, float]:
        """Env steps and wall seconds of this run and every run it started from: what the model cost."""
        return cost_from_scratch(self.meta)

    def preset(self) -> tuple[str, dict]:
        """The name of the model's preset and that preset's values today (none where it was renamed since)."""
        exp = get_experiment(self.experiment)
        name = self.meta.get("preset") or exp.algo(self.algo).default_preset
        try:
            return name, to_dict(exp.preset(self.algo, name))
        except Exception:  # a preset renamed since: compare with nothing
            return name, {}


def read_json(path: Path) -> dict:
    return json.loads(path.read_text())


def score_of(evaluation: dict) -> float | None:
    """An evaluation's score: the share of episodes reaching the goal, or the mean return."""
    return evaluation.get("success_share", evaluation.get("mean"))


def shipped_models() -> list[Model]:
    """Every shipped model, in registry order (algorithms as registered, Mario's levels sorted)."""
    sweeps, models = kept_sweeps(), []
    for name in experiment_names():
        exp = get_experiment(name)
        folders = sorted(p.parent for p in (REPO / "saved_networks" / name).glob("*/meta.json"))
        if exp.shipped_by is None:
            order = list(exp.algos)
            folders.sort(key=lambda p: order.index(p.name) if p.name in order else len(order))
        models += [Model(name, f.name, f.relative_to(REPO).as_posix(), read_json(f / "meta.json"),
                         exp.bar(f.name), sweeps.get((name, f.name))) for f in folders]
    return models


def kept_sweeps() -> dict[tuple[str, str], Sweep]:
    """(experiment, model) -> the sweep over seeds (without a grid) of that model's recipe kept in results/sweeps:
    scores from each run's meta.json, aggregates from report.md, which must list the same scores (else it is stale)."""
    found = {}
    for sweep_json in sorted((REPO / "results" / "sweeps").glob("*/sweep.json")):
        sweep, folder = read_json(sweep_json), sweep_json.parent.relative_to(REPO)
        if sweep.get("grid"):
            continue
        scores = [(meta["seed"], score_of(meta.get("evaluation") or {}))
                  for meta in map(read_json, (REPO / folder).glob("*/model/meta.json"))]
        seeds = sorted((seed, float(score)) for seed, score in scores if score is not None)
        report = (REPO / folder / "report.md").read_text() if (REPO / folder / "report.md").is_file() else ""
        if sorted(map(float, RUN_ROW.findall(report))) != sorted(round(s, 3) for _, s in seeds):
            raise SystemExit(f"error: {folder}/report.md does not list the scores of its runs' meta.json; "
                             f"rerun `python main.py report {folder}`")
        aggregates = {}
        for row in filter(None, map(AGGREGATE_ROW.match, map(str.strip, report.splitlines()))):
            aggregates.setdefault(row[1], (float(row[2]), float(row[3]), float(row[4])))
        found[(sweep["experiment"], model_of(sweep))] = Sweep(folder.as_posix(), seeds, aggregates)
    return found


def model_of(sweep: dict) -> str:
    """The shipped model a sweep's recipe trains: its algorithm, or (Mario) the level its overrides or preset set."""
    exp = get_experiment(sweep["experiment"])
    if not exp.shipped_by:
        return sweep["algo"]
    preset, overrides = exp.preset(sweep["algo"], sweep.get("preset")), sweep.get("overrides") or {}
    return "-".join(str(overrides.get(f, getattr(preset, f))) for f in exp.shipped_by.fields)


def kept_runs(experiment: str) -> list[tuple[Model, list[dict]]]:
    """Each shipped model of ``experiment`` with a kept sweep, and its runs by seed: meta.json, folder, story."""
    found = []
    for m in (m for m in shipped_models() if m.experiment == experiment and m.sweep is not None):
        solved = get_experiment(experiment).solved_score
        runs = [(read_json(path), path.parent.parent) for path in (REPO / m.sweep.folder).glob("*/model/meta.json")]
        found.append((m, sorted([dict(meta=meta, folder=run, story=story(run, meta, solved)) for meta, run in runs],
                                key=lambda run: run["meta"]["seed"])))
    return found


def csv_columns(experiments: str) -> list[tuple[str, str, str, dict[str, bool]]]:
    """(file, experiment, trainer, {column: in every such file}) per CSV of the shipped models (of ``a/b``, or all)."""
    seen: dict[tuple[str, str, str], list[list[str]]] = {}
    for m in (m for m in shipped_models() if not experiments or m.experiment in experiments.split("/")):
        for path in sorted((REPO / m.folder).glob("*.csv")):
            with path.open() as f:
                seen.setdefault((m.experiment, m.meta.get("kind", m.algo), path.name), []).append(
                    f.readline().strip().split(","))
    return [(name, experiment, kind, {c: all(c in h for h in headers) for header in headers for c in header})
            for (experiment, kind, name), headers in seen.items()]


def flag_value(value) -> str:
    """A preset's value as its flag takes it: ``true``, ``64,64``, ``0.0003``."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, tuple):
        return ",".join(map(str, value)) or "(empty)"
    return f"{value:g}" if isinstance(value, float) else str(value)


def preset_fields(spec) -> list[tuple[dataclasses.Field, list[str], str]]:
    """(field, its value in each preset, the values it allows in words) per field of an algorithm's default preset."""
    return [(f, [flag_value(getattr(p, f.name)) if hasattr(p, f.name) else "–" for p in spec.presets.values()],
             field_words(f) or ("true or false" if f.type in (bool, "bool") else ""))
            for f in dataclasses.fields(spec.presets[spec.default_preset])]


def cli_help() -> dict[str, str]:
    """The parser's own ``--help`` (key ``""``) and each subcommand's, 100 characters wide whatever the terminal."""
    parser = build_parser(["list"])
    subcommands = next((a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), {})
    for sub in (parser, *subcommands.values()):
        sub.formatter_class = functools.partial(sub.formatter_class, width=100)
    return {name: sub.format_help().rstrip() for name, sub in {"": parser, **subcommands}.items()}
