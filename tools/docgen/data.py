"""What the docs generator reads: the shipped models (``saved_networks/*/*/meta.json``) and the sweeps
kept in ``results/sweeps/``, as :class:`Model` and :class:`Sweep` records. TensorFlow-free."""
import json
import re
from dataclasses import dataclass
from pathlib import Path

from rlcore.environments.experiment import Bar
from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.files.model_meta import cost_from_scratch, lineage

REPO = Path(__file__).resolve().parents[2]
#: the Gymnasium id each experiment's models play (Mario's depends on the level)
ENV_IDS = {"lunar_lander": "LunarLander-v3", "cartpole": "CartPole-v1", "cartpole_v0": "CartPole-v0",
           "mario_ppo": "SuperMarioBros-{model}-v0", "minitaur": "deeprl/Minitaur-v0"}
# in a sweep's report.md, an aggregate's row (| iqm | 14.84 | [4.33, 20.02] |) and a run's (| trial | seed | score |
# ..., where a goal's share gives the episodes behind it: 0.800 (8 of 10))
AGGREGATE_ROW = re.compile(r"^\| (mean|median|iqm) \| (-?[\d.]+) \| \[(-?[\d.]+), (-?[\d.]+)\] \|$")
RUN_ROW = re.compile(r"^\| [^|]+ \| \d+ \| (-?[\d.]+)(?: \(\d+ of \d+\))? \|", re.M)


@dataclass
class Sweep:
    """A kept sweep (results/sweeps/NAME) of one shipped model's recipe over seeds."""
    folder: str  # repo-relative
    seeds: list[tuple[int, float]]  # (seed, final score on unseen seeds), from each run's meta.json
    aggregates: dict[str, tuple[float, float, float]]  # mean/median/iqm -> (point, low, high), from report.md

    def __post_init__(self):
        self.report = f"{self.folder}/report.md"


@dataclass
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

    @property
    def algo_name(self) -> str:
        """The algorithm's short name in the registry: ``Dueling DDQN``."""
        return get_experiment(self.experiment).algos[self.algo].description.split(",")[0]

    @property
    def lineage(self) -> list[dict]:
        """The runs whose weights this model's run started from (``--init-from``), nearest first."""
        return lineage(self.meta)

    def from_scratch(self) -> tuple[int, float]:
        """Env steps and wall seconds of this run and every run it started from: what the model cost."""
        return cost_from_scratch(self.meta)


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
    """(experiment, model) -> the sweep over seeds of that model's recipe kept in results/sweeps.

    Only sweeps without a grid count (one recipe, several seeds). Scores come from each run's
    meta.json; the IQM and its interval from report.md, which must list the same scores (else the
    report is stale and the generator says so)."""
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
