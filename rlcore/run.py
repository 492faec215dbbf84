"""One training run as one function: what ``main.py train``, a Ray trial and the tests all call.

    spec = build_spec("lunar_lander", "dqn", seed=0, overrides={"lr": 5e-4}, run_dir=Path("runs/x"))
    model_dir = run_training(spec, on_progress=lambda row, table: ...)

``build_spec`` turns names, a preset and overrides into a checked :class:`RunSpec` (an invalid
value is a :class:`UserError` before any folder exists); with ``resume`` it takes the
hyperparameters from the run folder's checkpoint, overrides on top. TensorFlow is imported only by
``run_training`` (through the trainer).
"""
from __future__ import annotations

import importlib
from pathlib import Path
from typing import Callable

from rlcore.experiment import get_experiment
from rlcore.errors import UserError
from rlcore.hparams import apply_overrides, check_no_inert, check_same_run, from_dict
from rlcore.trainers.spec import RunSpec, check_resumable


def build_spec(experiment: str, algo: str, *, preset: str | None = None, seed: int | None = None,
               overrides: dict | None = None, run_dir: Path, resume: bool = False,
               wandb_mode: str = "auto", progress: bool = True, command: str | None = None) -> RunSpec:
    """The :class:`RunSpec` of a new run (``resume=False``; ``seed`` None = 0) or of the run in
    ``run_dir``, whose seed, preset and defining fields a resume may not change."""
    exp = get_experiment(experiment)
    overrides = dict(overrides or {})
    extra = {} if command is None else {"command": command}
    if resume:
        spec = RunSpec(exp, algo, preset or "", None, seed, wandb_mode, Path(run_dir), True,
                       progress=progress, **extra)
        state = check_resumable(spec)
        config_class = type(exp.preset(algo, None))
        # the checkpoint's own hyperparameters; budgets, rates and coefficients may be given again,
        # what defines the env or the networks may not
        recorded = from_dict(config_class, state["config"])
        check_same_run(recorded, overrides, exp.env_fields, run_dir)
        spec.config = apply_overrides(recorded, overrides)
        check_no_inert(spec.config, overrides)
        if preset is not None and preset != state["preset"]:
            raise UserError(f"--preset {preset} cannot change on --resume: the run in {run_dir} was started "
                            f"from the {state['preset']} preset")
        if seed is not None and seed != state["seed"]:
            raise UserError(f"--seed {seed} cannot change on --resume: the run in {run_dir} has seed "
                            f"{state['seed']}")
        spec.preset, spec.seed = state["preset"], state["seed"]
        return spec
    config = apply_overrides(exp.preset(algo, preset), overrides)
    check_no_inert(config, overrides)
    seed = 0 if seed is None else seed
    return RunSpec(exp, algo, preset or exp.algo(algo).default_preset, config, seed, wandb_mode,
                   Path(run_dir), progress=progress, **extra)


def run_training(spec: RunSpec, on_progress: Callable[[dict, str], None] | None = None) -> Path:
    """Train ``spec`` to its end; return the model folder. ``on_progress(row, table)`` sees every row
    the run logs as it is logged. Ctrl-C (or ``spec.stop_file``) raises ``Interrupted`` after the
    checkpoint is written. A run folder that another process writes is refused (``RunFolderBusy``)."""
    from rlcore.run_lock import hold_run_folder

    if on_progress is not None:
        spec.on_progress = on_progress
    trainer = importlib.import_module(f"rlcore.trainers.{spec.kind}")
    with hold_run_folder(spec.run_dir):  # one writer per run folder (a second one is refused here)
        return trainer.train(spec)
