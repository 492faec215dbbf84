"""What defines a training run, and where its folder is: :class:`RunSpec`, new and latest run folders,
and the check that a checkpoint belongs to the run that wants to resume it."""
from __future__ import annotations

import glob
import re
import shlex
import sys
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Callable

from rlcore.errors import UserError
from rlcore.files.checkpoint import read_checkpoint_state

RUNS_DIR = Path("runs")
CHECKPOINT_FILE = "checkpoint.npz"


def recorded_env(run_dir: str | Path) -> dict:
    """The env a run's checkpoint records (a Gymnasium id's registration and ``--env-kwargs``), read quietly:
    {} for a run without one, and for a missing or damaged checkpoint, whose resume reports it in its words."""
    try:
        return read_checkpoint_state(Path(run_dir) / CHECKPOINT_FILE).get("env") or {}
    except (UserError, OSError, ValueError):
        return {}


@dataclass
class RunSpec:
    """Everything that defines a training run (what ``main.py train`` parsed)."""
    experiment: object  # rlcore.environments.experiment.Experiment
    algo: str
    preset: str
    config: object
    seed: int
    wandb_mode: str = "auto"  # as asked: auto, online, offline or off (a resume keeps the run's)
    run_dir: Path | None = None
    resume: bool = False
    command: str = field(default_factory=lambda: " ".join(shlex.quote(a) for a in ["python", *sys.argv]))
    progress: bool = True
    # on_progress(row, table): every row the run logs (episodes, evaluations, rollouts), as it comes
    on_progress: Callable[[dict, str], None] | None = None
    # a file whose appearance stops the run at its next safe point, with a checkpoint (sweeps' Ctrl-C)
    stop_file: Path | None = None
    # a resume's hyperparameters that differ from its checkpoint's, name -> [before, after] (JSON values):
    # meta.json keeps them beside the command, so a run's settings can be followed from start to end
    changes: dict = field(default_factory=dict)
    # episodes of the final evaluation on unseen seeds (None: the experiment's default; a resume keeps the run's)
    final_eval_episodes: int | None = None

    @property
    def kind(self) -> str:
        return self.experiment.algo(self.algo).kind

    def describe(self) -> dict:
        """What the run is, as CSV headers, checkpoints and meta.json record it."""
        from rlcore.hyperparams.flags import to_dict

        env = getattr(self.experiment, "env_record", None)  # a Gymnasium id's registration
        return {"experiment": self.experiment.name, "algo": self.algo, "kind": self.kind,
                "preset": self.preset, "seed": self.seed, "config": to_dict(self.config),
                **({"env": env} if env else {})}


def folder_safe(name: str) -> str:
    """``name`` as one folder or file name: ``ALE/Pong-v5`` -> ``ALE_Pong-v5``, ``my_envs:Maze-v0`` ->
    ``my_envs_Maze-v0`` (a Gymnasium id can hold a namespace and a module)."""
    return re.sub(r"[^\w.-]", "_", name)


def new_run_dir(experiment: str, algo: str, seed: int) -> Path:
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    return RUNS_DIR / f"{folder_safe(experiment)}__{algo}__{seed}__{stamp}"


def latest_run_dir(experiment: str, algo: str) -> Path:
    runs = sorted(RUNS_DIR.glob(f"{glob.escape(folder_safe(experiment))}__{algo}__*/{CHECKPOINT_FILE}"),
                  key=lambda p: p.stat().st_mtime)
    if not runs:
        raise UserError(f"no run of {experiment} {algo} with a checkpoint under {RUNS_DIR}/ to resume; a run "
                        f"started with --run-dir DIR resumes with --resume DIR")
    return runs[-1].parent


def check_resumable(spec: RunSpec) -> dict:
    """The checkpoint's state, after checking it belongs to this experiment and algorithm."""
    state = read_checkpoint_state(spec.run_dir / CHECKPOINT_FILE)
    found = (state.get("experiment"), state.get("algo"))
    if found != (spec.experiment.name, spec.algo):
        raise UserError(f"checkpoint in {spec.run_dir} is from {found[0]} {found[1]}, "
                        f"not {spec.experiment.name} {spec.algo}; pick the matching run")
    return state
