"""One training run as one function: what ``main.py train``, a Ray trial and the tests all call.

    spec = build_spec("lunar_lander", "dqn", seed=0, overrides={"lr": 5e-4}, run_dir=Path("runs/x"))
    model_dir = run_training(spec, on_progress=lambda row, table: ...)
    model_dir, meta = train_and_evaluate(spec)    # the same, then the final evaluation (main.py train)

The Python API (:mod:`rlcore.api`) wraps these for notebooks and scripts.

``build_spec`` turns names, a preset and overrides into a checked :class:`RunSpec` (an invalid
value is a :class:`UserError` before any folder exists); with ``resume`` it takes the
hyperparameters from the run folder's checkpoint, overrides on top. TensorFlow is imported only by
``run_training`` (through the trainer).
"""
from __future__ import annotations

import importlib
from pathlib import Path
from typing import Callable

from rlcore.algorithms.registry import family
from rlcore.environments.registry import get_experiment
from rlcore.errors import UserError
from rlcore.hyperparams.allowed import flag, resume_words, setting
from rlcore.hyperparams.flags import apply_overrides, as_recorded, check_no_inert, check_same_run, from_dict, to_dict
from rlcore.training.spec import RunSpec, check_resumable, recorded_env


def build_spec(experiment: str, algo: str, *, preset: str | None = None, seed: int | None = None,
               overrides: dict | None = None, run_dir: Path, resume: bool = False,
               wandb_mode: str | None = None, progress: bool = True, command: str | None = None,
               nothing_to_train_ok: bool = False, final_eval_episodes: int | None = None,
               env_kwargs: dict | None = None) -> RunSpec:
    """The :class:`RunSpec` of a new run (``resume=False``; ``seed`` None = 0) or of the run in
    ``run_dir``, whose seed, preset and defining fields a resume may not change, and which must have
    something left to train unless ``nothing_to_train_ok`` (``--publish``: evaluate it again, publish).
    ``wandb_mode`` and ``final_eval_episodes`` left None: ``auto`` and the experiment's default for a new
    run, the run's own for a resume (its checkpoint records them). ``env_kwargs``: a Gymnasium id's
    constructor arguments (``--env-kwargs``); a resume keeps the run's."""
    from rlcore.files.run_lock import refuse_if_busy

    refuse_if_busy(run_dir)  # before the checkpoint is read or a header printed
    exp = _experiment_of(experiment, Path(run_dir), resume, env_kwargs)
    overrides = dict(overrides or {})
    extra = {} if command is None else {"command": command}
    if resume:
        return _resumed_spec(exp, algo, preset, seed, overrides, Path(run_dir), wandb_mode, progress,
                             final_eval_episodes, nothing_to_train_ok, extra)
    config = apply_overrides(exp.preset(algo, preset), overrides)
    check_no_inert(config, overrides)
    if getattr(config, "init_from", ""):  # PPO: a wrong folder is one line before any env process starts
        from rlcore.training.init_from import init_from_meta

        init_from_meta(config.init_from, exp.name, algo, family(exp.algo(algo).kind).policy_file)
    seed = 0 if seed is None else seed
    return RunSpec(exp, algo, preset or exp.algo(algo).default_preset, config, seed, wandb_mode or "auto",
                   Path(run_dir), progress=progress, final_eval_episodes=final_eval_episodes, **extra)


def _resumed_spec(exp, algo: str, preset: str | None, seed: int | None, overrides: dict, run_dir: Path,
                  wandb_mode: str | None, progress: bool, final_eval_episodes: int | None,
                  nothing_to_train_ok: bool, extra: dict) -> RunSpec:
    """The spec of the run in ``run_dir``, resumed: its checkpoint's hyperparameters with the changes a
    resume may make (budgets, rates, coefficients); its seed, preset and what defines the env or the
    networks as they were."""
    spec = RunSpec(exp, algo, preset or "", None, seed, wandb_mode or "auto", Path(run_dir), True,
                   progress=progress, final_eval_episodes=final_eval_episodes, **extra)
    state = check_resumable(spec)
    if wandb_mode is None:
        spec.wandb_mode = str(state.get("wandb_mode") or "auto")
    if final_eval_episodes is None and state.get("final_eval_episodes") is not None:
        spec.final_eval_episodes = int(state["final_eval_episodes"])
    config_class = type(exp.preset(algo, None))
    # the checkpoint's own hyperparameters; budgets, rates and coefficients may be given again,
    # what defines the env or the networks may not
    recorded = from_dict(config_class, state["config"])
    overrides = as_recorded(recorded, overrides)
    check_same_run(recorded, overrides, exp.env_fields, run_dir)
    spec.config = apply_overrides(recorded, overrides)
    check_no_inert(spec.config, overrides)
    before, after = to_dict(recorded), to_dict(spec.config)
    spec.changes = {name: [before[name], after[name]] for name in overrides if before[name] != after[name]}
    if preset is not None and preset != state["preset"]:
        raise UserError(f"{setting('preset', preset)} cannot change on a resume: the run in {run_dir} was started "
                        f"from the {state['preset']} preset")
    if seed is not None and seed != state["seed"]:
        raise UserError(f"{setting('seed', seed)} cannot change on a resume: the run in {run_dir} has seed "
                        f"{state['seed']}")
    spec.preset, spec.seed = state["preset"], state["seed"]
    if not nothing_to_train_ok:
        refuse_nothing_to_train(spec, state)
    return spec


def _experiment_of(experiment: str, run_dir: Path, resume: bool, env_kwargs: dict | None):
    """The run's experiment: for a resume, built with the env arguments its checkpoint records (which
    ``--env-kwargs`` may repeat, not change)."""
    if not resume:
        return get_experiment(experiment, env_kwargs=env_kwargs)
    record = recorded_env(run_dir)
    recorded = record.get("env_kwargs") or {}
    if env_kwargs is not None and env_kwargs != recorded:
        raise UserError(f"--env-kwargs cannot change on a resume: the run in {run_dir} was started with "
                        f"{recorded or 'none'}")
    return get_experiment(experiment, record or None)


def refuse_nothing_to_train(spec: RunSpec, state: dict) -> None:
    """A finished run whose model holds its last checkpoint, resumed with the rule that ended it still
    met (the same or a smaller budget, an unchanged goal), would train nothing and only evaluate again:
    one line, before any agent, env or file is touched. A run whose model is missing or older than its
    checkpoint (stopped between the two) goes on to write it."""
    import json

    from rlcore.training.episodes import EpisodeBook
    from rlcore.training.periodic_eval import PeriodicEvaluation
    from rlcore.training.stopping import StopRules

    try:
        meta = json.loads((spec.run_dir / "model" / "meta.json").read_text())
    except (OSError, ValueError):
        return
    episodes, env_steps = len(state.get("returns") or []), int(state.get("env_steps", 0))
    if (meta.get("episodes"), meta.get("env_steps")) != (episodes, env_steps):
        return
    cfg = spec.config
    book = EpisodeBook(cfg.window, spec.experiment.solved_score, state.get("returns"), state.get("successes"),
                       state.get("counted_returns"))
    ended = StopRules(cfg).reason(book, env_steps, PeriodicEvaluation(cfg, state))
    if ended:
        field, _, value = ended.partition(" ")
        budget = {"max_episodes": "episodes", "max_env_steps": "steps"}.get(field)
        what = (f"give a larger {flag(budget)}" + (" (a larger --episodes alone does not lift a step budget)"
                                                    if budget == "steps" else "")
                if budget else f"change {flag(field)}")
        raise UserError(f"nothing to train: the run in {spec.run_dir} is finished, and what ended it still holds "
                        f"({flag(field)} {value}, at episode {episodes:,}, env step {env_steps:,}); {what}")


def run_training(spec: RunSpec, on_progress: Callable[[dict, str], None] | None = None) -> Path:
    """Train ``spec`` to its end; return the model folder. ``on_progress(row, table)`` sees every row
    the run logs as it is logged. Ctrl-C (or ``spec.stop_file``) raises ``Interrupted`` after the
    checkpoint is written. A run folder that another process writes is refused (``RunFolderBusy``)."""
    from rlcore.files.run_lock import hold_run_folder

    if on_progress is not None:
        spec.on_progress = on_progress
    train = family(spec.kind).train  # an unknown kind: one line, before the folder is held
    _import_the_end_of_a_run()
    with hold_run_folder(spec.run_dir):  # one writer per run folder (a second one is refused here)
        return train(spec)


#: what the end of a run imports inside its functions: its model, the final evaluation, meta.json, the
#: video of ``--video`` (rlcore.api's render)
END_OF_RUN_MODULES = ("rlcore.api", "rlcore.api.models", "rlcore.files.atomic", "rlcore.files.model_meta",
                      "rlcore.training.evaluation", "rlcore.environments.gym_experiment", "rlcore.host.machine",
                      "rlcore.networks.acting", "rlcore.networks.saving", "rlcore.records.plotting", "rlcore.models.policies",
                      "rlcore.models.shipping", "rlcore.models.snapshot", "rlcore.models.video")


def _import_the_end_of_a_run() -> None:
    """Import now the modules the end of a run imports (its model, the final evaluation, meta.json). A
    run takes hours, and a package edited meanwhile must not meet this process's older modules there:
    a module loaded only at the end, asking a module loaded at the start for a name the edit added,
    fails (a Minitaur trial, 2026-11-27: trained 1M steps, then "cannot import name" before its evaluation)."""
    for name in END_OF_RUN_MODULES:
        importlib.import_module(name)


def budget_overrides(episodes: int | None, steps: int | None, given: dict | None = None) -> dict:
    """``episodes`` / ``steps`` (``--episodes`` / ``--steps``) as the config fields they set; ``given``:
    the hyperparameters set beside them, where ``max_episodes`` and ``episodes`` together would be two
    answers to one question (a :class:`UserError`)."""
    budget = {"max_episodes": episodes, "max_env_steps": steps}
    for name, value in budget.items():
        if value is not None and name in (given or {}):
            short = flag("episodes" if name == "max_episodes" else "steps")
            raise UserError(f"{short} and {flag(name)} set the same budget: give one")
    return {name: value for name, value in budget.items() if value is not None}


def check_new_run_dir(run_dir: Path) -> None:
    """A new run may not start in a folder that holds one: it would append to its tables and
    overwrite its checkpoint."""
    from rlcore.training.spec import CHECKPOINT_FILE

    if Path(run_dir).exists() and not Path(run_dir).is_dir():
        raise UserError(f"{setting('run_dir', str(run_dir))} is a file, not a folder")
    held = [name for name in (CHECKPOINT_FILE, "metrics.csv") if (Path(run_dir) / name).is_file()]
    if held:
        raise UserError(f"{setting('run_dir', str(run_dir))} already holds a run ({held[0]}); continue it with "
                        f"{resume_words(run_dir)}, or give another {flag('run_dir')}")


def untrained_note(config) -> str | None:
    """A note where the env-step budget ends an off-policy run (DQN, SAC) before its first gradient step:
    its model would be the untrained network (a short --steps with the default --learning-starts)."""
    starts, budget = getattr(config, "learning_starts", None), getattr(config, "max_env_steps", 0)
    if starts is None or not budget:
        return None
    first = max(starts, getattr(config, "batch_size", 0))
    if budget > first:
        return None
    return (f"note: {setting('max_env_steps', budget)} is no more than the {first:,} env steps the run collects "
            f"before its first update ({flag('learning_starts')} {starts:,}): it will learn little or nothing")


def train_and_evaluate(spec: RunSpec, on_progress: Callable[[dict, str], None] | None = None,
                       say: Callable[[str], None] = print) -> tuple[Path, dict]:
    """What ``main.py train`` and :func:`rlcore.api.train` both run: :func:`run_training`, then the
    final evaluation on unseen seeds recorded in meta.json (``spec.final_eval_episodes``: None = the
    experiment's default, 0 = none). Returns the model folder and its meta.json."""
    import json

    from rlcore.models import shipping

    if note := untrained_note(spec.config):
        say(note)
    model_dir = run_training(spec, on_progress)
    meta = json.loads((model_dir / "meta.json").read_text())
    say(f"trained: {meta['episodes']} episodes, {meta['env_steps']} env steps, "
        f"{meta['wall_seconds']:.0f} s; last-100 average {meta['final_average']:.1f}")
    episodes = shipping.eval_episodes(spec.experiment, spec.final_eval_episodes)
    if episodes > 0:
        meta = shipping.record_evaluation(model_dir, episodes, replace=True)  # the model just trained
    return model_dir, meta
