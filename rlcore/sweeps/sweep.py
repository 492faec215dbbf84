"""What a sweep is: one trial per (seed, grid value ...) combination, each an ordinary run folder.

    sweeps/<name>/sweep.json            what the sweep is (experiment, algo, preset, seeds, grid, budgets)
    sweeps/<name>/<trial>/              metrics.csv, checkpoint.npz, model/ (meta.json) ...: a run folder
    sweeps/<name>/trials.log            a line per start and end of each trial's attempt
    sweeps/<name>/_tune/                Ray Tune's own records

This module reads and checks a sweep (its seeds, its grid, every trial's config); one trial runs in
:mod:`rlcore.sweeps.trial`, the whole sweep on Ray Tune in :mod:`rlcore.sweeps.on_ray`, and
:mod:`rlcore.sweeps.status` tells where it stands. TensorFlow-free and Ray-free (trials import it).
"""
from __future__ import annotations

import argparse
import dataclasses
import itertools
from dataclasses import asdict, dataclass, field
from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.atomic import write_json
from rlcore.files.model_meta import read_json

SWEEP_FILE = "sweep.json"
STOP_FILE = "STOP"
TRIALS_LOG = "trials.log"


@dataclass
class Sweep:
    """What a sweep runs: every combination of ``seeds`` and the ``grid`` values, on top of a preset."""
    experiment: str
    algo: str
    name: str
    folder: str  # absolute path of sweeps/<name>, where it is now: not written to sweep.json
    seeds: list[int]
    grid: dict[str, list] = field(default_factory=dict)  # hyperparameter -> values
    preset: str | None = None
    overrides: dict = field(default_factory=dict)  # budgets (max_env_steps, max_episodes)
    cpus_per_run: float = 1.0
    max_concurrent: int = 0  # 0 = as many as the CPUs allow
    final_eval_episodes: int | None = None  # None = the experiment's default
    env_kwargs: dict | None = None  # a Gymnasium id's constructor arguments (--env-kwargs), every trial's

    def trials(self) -> list[dict]:
        """One dict per trial: the seed and one value of every grid field."""
        names = sorted(self.grid)
        combos = itertools.product(*(self.grid[n] for n in names)) if names else [()]
        return [{**dict(zip(names, values)), "seed": seed} for values in combos for seed in self.seeds]

    def save(self) -> None:
        # the folder is where sweep.json lies; an absolute path would name this machine's checkout
        write_json(Path(self.folder) / SWEEP_FILE, {k: v for k, v in asdict(self).items() if k != "folder"})

    @classmethod
    def load(cls, folder: Path) -> "Sweep":
        path = Path(folder) / SWEEP_FILE
        if not path.is_file():
            raise UserError(f"no sweep to resume in {folder} (no {SWEEP_FILE}); start it without --resume")
        data = read_json(path, "put back a good copy of the sweep's folder")
        data["folder"] = str(Path(folder).resolve())  # where it is now (a clone elsewhere), not where it began
        return cls(**data)


def trial_name(trial: dict) -> str:
    """``lr=0.0001__seed=3``: the grid values in name order, the seed last."""
    parts = [f"{k}={trial[k]}" for k in sorted(trial) if k != "seed"] + [f"seed={trial['seed']}"]
    return "__".join(parts)


def parse_seeds(text: str) -> list[int]:
    """``0-4`` or ``0,3,7`` (or both: ``0-2,9``)."""
    from rlcore.environments.seeding import MAX_RUN_SEED

    seeds = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                low, high = (int(x) for x in part.split("-", 1))
                if high < low:
                    raise UserError(f"--seeds {text!r} is invalid: the range {part} runs downward; "
                                    f"write {high}-{low}")
                seeds.extend(range(low, high + 1))
            elif part:
                seeds.append(int(part))
        except ValueError:
            raise UserError(f"--seeds {text!r} is invalid: give a range (0-4) or a list (0,3,7)") from None
    if not seeds or min(seeds) < 0 or max(seeds) > MAX_RUN_SEED or len(set(seeds)) != len(seeds):
        raise UserError(f"--seeds {text!r} is invalid: allowed are distinct whole numbers from 0 to "
                        f"{MAX_RUN_SEED}")
    return seeds


# settings a grid may not vary, and why
UNSWEPT = {"init_from": "each trial's folder is named by its values, and a path cannot be part of a folder's "
                        "name; fine-tune one run with `main.py train ... --init-from`"}


def parse_grid(items: list[str], config) -> dict[str, list]:
    """``["lr=1e-4,3e-4", "world=1,2"]`` -> ``{"lr": [0.0001, 0.0003], "world": [1, 2]}``, each value
    parsed by its field's type; an unknown name is a :class:`UserError`."""
    from rlcore.hyperparams.flags import field_types

    types = field_types(type(config))
    grid = {}
    for item in items:
        name, sep, values = item.partition("=")
        name = name.strip().lstrip("-").replace("-", "_")
        if not sep or not values.strip():
            raise UserError(f"--grid {item!r} is invalid: write NAME=V1,V2 (e.g. --grid lr=1e-4,3e-4)")
        if name not in types:
            raise UserError(f"--grid {item!r}: {name!r} is not a hyperparameter of {type(config).__name__}; "
                            f"`main.py train EXPERIMENT ALGO --help` lists them")
        if name in UNSWEPT:
            raise UserError(f"--grid {item!r}: a sweep cannot set {name} ({UNSWEPT[name]})")
        try:
            # tuple fields (hidden sizes) take ';' between values: --grid hidden=64,64;128,128
            sep_values = values.split(";") if isinstance(getattr(config, name), tuple) else values.split(",")
            grid[name] = [types[name](v.strip()) for v in sep_values if v.strip()]
        except argparse.ArgumentTypeError as exc:  # a bad true/false says what it allows
            raise UserError(f"--grid {item!r} is invalid: {exc}") from None
        except ValueError:  # float('abc') says "could not convert string to float"
            raise UserError(f"--grid {item!r} is invalid: {name} takes {_takes(config, name)}") from None
    return grid


def _takes(config, name: str) -> str:
    """What field ``name`` of ``config`` takes, in words, for a --grid value that is no such thing."""
    from rlcore.hyperparams.allowed import field_words

    f = next(f for f in dataclasses.fields(config) if f.name == name)
    kind = {"int": "whole numbers", "float": "numbers", "tuple[int, ...]": "lists of whole numbers"}
    words = field_words(f) or kind.get(str(f.type), str(f.type))
    return words + (" (values apart with ';')" if str(f.type).startswith("tuple") else "")


def check(sweep: Sweep) -> None:
    """Build every trial's config once, so a bad value stops the sweep before Ray starts."""
    from rlcore.environments.registry import get_experiment
    from rlcore.hyperparams.flags import apply_overrides, check_no_inert

    exp = get_experiment(sweep.experiment, env_kwargs=sweep.env_kwargs)
    base = exp.preset(sweep.algo, sweep.preset)
    for trial in sweep.trials():
        values = {k: v for k, v in trial.items() if k != "seed"}
        check_no_inert(apply_overrides(base, {**sweep.overrides, **values}), values)
