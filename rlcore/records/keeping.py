"""``main.py report --keep DIR``: finished runs copied into a folder git keeps (``results/sweeps/NAME``),
a sweep's trials or single runs of one recipe over seeds, so that ``report`` and the docs generator
read it as any kept sweep. A keep replaces the folder whole, in one swap. TensorFlow-free.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.model_meta import read_json
from rlcore.records.commands import command_starts
from rlcore.records.report import load_runs

#: what ``keep`` copies of a run folder: what the report reads (meta.json, metrics.csv), the periodic
#: evaluations (evals.csv), PPO's rollout table (rollouts.csv) and the model's weights (model/*.h5), so
#: that a kept run's model can be evaluated again (``main.py evaluate ... --model KEPT/seed=S``);
#: checkpoints, replay memories and plots stay behind
KEPT_FILES = ("model/meta.json", "model/*.h5", "metrics.csv", "evals.csv", "rollouts.csv")


def kept_files(run_dir: Path) -> list[str]:
    """The :data:`KEPT_FILES` a run folder holds, as paths relative to it."""
    run_dir = Path(run_dir)
    return [p.relative_to(run_dir).as_posix() for pattern in KEPT_FILES for p in sorted(run_dir.glob(pattern))
            if p.is_file()]


def is_run_folder(folder: Path) -> bool:
    """A finished run's folder (``model/meta.json``), as opposed to a sweep's folder of such runs."""
    return (Path(folder) / "model" / "meta.json").is_file()


def _keep_into(dest: Path, pairs: list[tuple[Path, str]], sweep: dict | None = None) -> Path:
    """Make ``dest`` hold exactly the ``pairs`` (source file, path in ``dest``) and, given, ``sweep`` as
    its sweep.json; an earlier kept sweep there is replaced whole (a seed it held and this keep lacks
    does not survive), in one swap (:func:`rlcore.files.atomic.replace_folder`), so a kept folder is never a
    mix of two keeps or a keep cut short."""
    from rlcore.files.atomic import replace_folder

    if dest.exists() and not dest.is_dir():
        raise UserError(f"--keep {dest}: a file is there; give a folder")
    earlier_keep = (dest / "sweep.json").is_file() or any(dest.glob("*/model/meta.json"))
    if dest.is_dir() and any(dest.iterdir()) and not earlier_keep:
        raise UserError(f"--keep {dest}: that folder holds other files and no kept sweep (sweep.json); give a new "
                        f"folder, or one an earlier keep wrote, which is replaced whole")

    def fill(fresh: Path) -> None:
        for source, name in pairs:
            (fresh / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, fresh / name)
        if sweep is not None:
            (fresh / "sweep.json").write_text(json.dumps(sweep, indent=2) + "\n")

    return replace_folder(dest, fill)


#: config fields kept runs may differ in: budgets, which a resume may give again (the stop rule ends a run)
BUDGETS = ("max_env_steps", "max_episodes")


def check_one_recipe_throughout(run_dir: Path, meta: dict) -> None:
    """Refuse a run that did not follow one recipe from random weights to its end: one started from a
    model's weights (``--init-from``), or resumed with a hyperparameter other than a :data:`BUDGETS` changed
    (read from meta.json's ``command_starts``, where each resume records what it changed), or a resume
    whose record predates that."""
    if meta.get("init_from"):
        source = meta["init_from"].get("path", "a model") if isinstance(meta["init_from"], dict) else meta["init_from"]
        raise UserError(f"{run_dir} started from the weights of {source} (--init-from): kept runs train from "
                        f"random weights")
    for number, start in enumerate(command_starts(meta)[1:], 2):
        if not isinstance(start, dict) or "changed" not in start:
            raise UserError(f"{run_dir}: its meta.json does not say what its command {number} (a resume) changed "
                            f"(a record from before 2026-11-27): kept runs must show that a resume gave budgets only")
        changed = {name: values for name, values in start["changed"].items() if name not in BUDGETS}
        if changed:
            what = ", ".join(f"{name} {before} -> {after}" for name, (before, after) in sorted(changed.items()))
            raise UserError(f"{run_dir} was resumed at env step {start['env_steps']:,} with {what}: kept runs follow "
                            f"one recipe from start to end (a resume may give budgets again, nothing else)")


def keep_runs(run_dirs: list[Path], dest: Path) -> Path:
    """Keep single runs of one recipe over seeds (``main.py train ... --seed S``, one run folder each) as
    a sweep would be kept: per run :data:`KEPT_FILES` into ``dest/seed=S/``, and a ``sweep.json`` naming
    the experiment, algorithm, preset, seeds and (for Mario) the level, so that ``report`` and the docs
    generator read ``dest`` like any kept sweep. The runs must differ in their seed (and :data:`BUDGETS`) only,
    and each must have kept its recipe throughout (:func:`check_one_recipe_throughout`)."""
    from rlcore.environments.registry import get_experiment
    from rlcore.hyperparams.flags import to_dict

    run_dirs, dest = [Path(d) for d in run_dirs], Path(dest)
    metas = [read_json(d / "model" / "meta.json", "keep only finished runs") for d in run_dirs]
    first = metas[0]
    for d, meta in zip(run_dirs, metas):
        check_one_recipe_throughout(d, meta)
        what = (meta.get("experiment"), meta.get("algo"), meta.get("preset"))
        if what != (first.get("experiment"), first.get("algo"), first.get("preset")):
            raise UserError(f"{d} is a run of {' '.join(map(str, what))}, {run_dirs[0]} of {first.get('experiment')} "
                            f"{first.get('algo')} {first.get('preset')}: kept runs are one recipe over seeds")
        differ = sorted(k for k in set(meta.get("config", {})) | set(first.get("config", {}))
                        if k not in BUDGETS and meta.get("config", {}).get(k) != first.get("config", {}).get(k))
        if differ:
            raise UserError(f"{d} and {run_dirs[0]} differ in {', '.join(differ)}: kept runs are one recipe over seeds")
    seeds = [meta["seed"] for meta in metas]
    if len(set(seeds)) != len(seeds):
        raise UserError(f"two of the runs have the same seed ({', '.join(map(str, seeds))}): keep one run per seed")
    if not all(meta.get("evaluation") for meta in metas):
        raise UserError("a run has no evaluation on unseen seeds in its model/meta.json: evaluate it first "
                        "(main.py evaluate ... --model RUN_DIR --record)")
    exp = get_experiment(first["experiment"])
    fields = exp.shipped_by.fields if exp.shipped_by else ()
    preset = json.loads(json.dumps(to_dict(exp.preset(first["algo"], first.get("preset")))))  # as meta.json has it
    sweep = {"experiment": first["experiment"], "algo": first["algo"], "name": dest.name,
             "seeds": sorted(seeds), "grid": {}, "preset": first.get("preset"),
             # what the recipe set beside its preset (Mario: the level, the stop share, the precision)
             "overrides": {k: v for k, v in first["config"].items()
                           if k in fields or (k not in BUDGETS and preset.get(k) != v)}}
    pairs = [(d / name, f"seed={meta['seed']}/{name}") for d, meta in zip(run_dirs, metas) for name in kept_files(d)]
    return _keep_into(dest, pairs, sweep)


def keep(sweep_dir: Path, dest: Path) -> Path:
    """Copy ``sweep.json`` and, per run, :data:`KEPT_FILES` of ``sweep_dir``
    into ``dest``, a folder git keeps (``results/sweeps/NAME``); a report of ``dest`` then gives the
    same numbers. Returns ``dest``."""
    sweep_dir, dest = Path(sweep_dir), Path(dest)
    runs = load_runs(sweep_dir)  # refuses a folder with no finished run before anything is copied
    copies = [(sweep_dir / "sweep.json", "sweep.json")] if (sweep_dir / "sweep.json").is_file() else []
    for run in runs:
        copies += [(run["run_dir"] / name, f"{run['trial']}/{name}") for name in kept_files(run["run_dir"])]
    return _keep_into(dest, copies)
