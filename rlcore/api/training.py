"""The Python API's training: :func:`train` a new run, :func:`resume` a stopped one, each returning a
:class:`Run` (:mod:`rlcore.api.models`); re-exported by :mod:`rlcore.api`. What ``main.py train`` runs (:func:`rlcore.training.run.train_and_evaluate`), with the same
records; meta.json's ``command`` records the call."""
from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any, Callable, Iterator, Literal

from rlcore.api.models import Run
from rlcore.errors import UserError
from rlcore.hyperparams.allowed import COUNT, check_whole, named_as_python
from rlcore.hyperparams.limits import FINAL_EVALUATION, RUN_SEEDS

#: ``callback(row, table)``: every row the run logs, as it is logged; ``table`` is ``"metrics"`` (one
#: row per episode), ``"evals"`` (periodic evaluations) or ``"rollouts"`` (PPO: one row per update)
ProgressCallback = Callable[[dict[str, Any], str], None]
WandbMode = Literal["auto", "online", "offline", "off"]


@named_as_python  # errors name settings as the call gave them (lr=-1.0), not as flags
def train(env: str, algo: str, *, preset: str | None = None, seed: int = 0,
          run_dir: str | os.PathLike[str] | None = None, episodes: int | None = None,
          steps: int | None = None, final_eval_episodes: int | None = None, wandb: WandbMode = "off",
          progress: bool = True, callback: ProgressCallback | None = None, env_kwargs: dict[str, Any] | None = None,
          **hyperparameters: Any) -> Run:
    """Train ``algo`` on ``env`` and evaluate it as ``main.py train`` does; return the :class:`Run`.

    ``env``: an experiment of this package (``"lunar_lander"``), any registered Gymnasium id whose
    spaces fit ``algo`` (``"Acrobot-v1"``), or ``"my_module:MyEnv-v0"`` to import the module that
    registers it first. ``preset``: a named set of hyperparameters (default ``"default"``; for a
    Gymnasium id the algorithm's defaults). ``episodes`` / ``steps``: the budget (``max_episodes`` /
    ``max_env_steps``). ``final_eval_episodes``: episodes on unseen seeds after training (None: the
    experiment's default, 100; 0: none). ``run_dir``: where the run writes (default
    ``runs/ENV__ALGO__SEED__TIME``). ``env_kwargs``: a Gymnasium id's constructor arguments
    (``{"continuous": True}``), checked and recorded as ``--env-kwargs``. ``hyperparameters``: any field of the algorithm's config, e.g.
    ``lr=5e-4, hidden=(128, 128)``; each is checked as the CLI checks it. ``callback(row, table)``
    sees every logged row. ``progress``: the progress bar and the summary lines.
    """
    from rlcore.environments.registry import require_experiment
    from rlcore.host.quiet import load_tensorflow
    from rlcore.training.run import build_spec, check_new_run_dir
    from rlcore.training.spec import new_run_dir

    check_whole("seed", seed, RUN_SEEDS)  # as the command line checks them, before any folder exists
    _check_budgets(episodes, steps, final_eval_episodes, wandb)
    require_experiment(env)  # a missing extra (mario, minitaur): one line, before any folder exists
    load_tensorflow()
    overrides = _overrides(hyperparameters, episodes, steps)
    folder = Path(run_dir) if run_dir is not None else new_run_dir(env, algo, seed)
    check_new_run_dir(folder)
    command = _call("train", [env, algo], dict(preset=preset, seed=seed, run_dir=run_dir, episodes=episodes,
                                                 steps=steps, final_eval_episodes=final_eval_episodes,
                                                 **({"env_kwargs": env_kwargs} if env_kwargs else {}),
                                                 **hyperparameters))
    spec = build_spec(env, algo, preset=preset, seed=seed, overrides=overrides, run_dir=folder,
                      wandb_mode=wandb, progress=progress, command=command, final_eval_episodes=final_eval_episodes,
                      env_kwargs=env_kwargs)
    return _train_and_evaluate(spec, f"training {env} {algo} ({spec.preset} preset, seed {spec.seed}) -> {folder}",
                               callback, progress)


@named_as_python
def resume(run: str | os.PathLike[str] | Run, *, episodes: int | None = None, steps: int | None = None,
           final_eval_episodes: int | None = None, wandb: WandbMode | None = None, progress: bool = True,
           callback: ProgressCallback | None = None, **hyperparameters: Any) -> Run:
    """Continue the run in ``run`` (its folder, or a :class:`Run`) from its last checkpoint, as ``main.py
    train ENV ALGO --resume RUN_DIR`` does, and evaluate it; return the :class:`Run`.
    ``final_eval_episodes`` and ``wandb`` left None: as the run had them.

    A run stopped by Ctrl-C (``Interrupted``) or a crash goes on from its checkpoint; a finished one goes
    on if given a larger budget (``episodes`` / ``steps``, in all, not more). ``hyperparameters``: rates,
    coefficients and budgets may change (each change is recorded in meta.json's ``command_starts``); what
    the run is (its env, networks, seed, preset, the model it started from) may not, and saying so raises
    :class:`UserError`.
    """
    from rlcore.environments.registry import require_experiment
    from rlcore.files.checkpoint import read_checkpoint_state
    from rlcore.host.quiet import load_tensorflow
    from rlcore.hyperparams.flags import resuming_changes
    from rlcore.training.run import build_spec
    from rlcore.training.spec import CHECKPOINT_FILE

    _check_budgets(episodes, steps, final_eval_episodes, wandb)
    folder = Path(run.run_dir if isinstance(run, Run) else run)
    if not (folder / CHECKPOINT_FILE).is_file():
        raise UserError(f"{folder} holds no {CHECKPOINT_FILE} to resume from; give the folder of a run "
                        f"(api.train's run_dir)")
    state = read_checkpoint_state(folder / CHECKPOINT_FILE)
    env, algo = str(state["experiment"]), str(state["algo"])
    require_experiment(env)
    load_tensorflow()
    command = _call("resume", [str(folder)], dict(episodes=episodes, steps=steps,
                                                  final_eval_episodes=final_eval_episodes, **hyperparameters))
    spec = build_spec(env, algo, overrides=_overrides(hyperparameters, episodes, steps), run_dir=folder,
                      resume=True, wandb_mode=wandb, progress=progress, command=command,
                      final_eval_episodes=final_eval_episodes)
    return _train_and_evaluate(spec, f"resuming {folder} at episode {len(state['returns'])}, env step "
                                     f"{state['env_steps']}{resuming_changes(spec.changes)}", callback, progress)


def _check_budgets(episodes: int | None, steps: int | None, final_eval_episodes: int | None,
                   wandb: str | None = None) -> None:
    """``episodes``, ``steps`` and ``final_eval_episodes`` as ``--episodes``, ``--steps`` and
    ``--final-eval-episodes`` are checked (None: not given), and ``wandb`` as ``--wandb``'s choices: before
    anything is printed or made."""
    from rlcore.training.tracking import WANDB_MODES

    if wandb is not None and wandb not in WANDB_MODES:
        raise UserError(f"wandb={wandb!r} is invalid: choose one of {', '.join(map(repr, WANDB_MODES))}")
    for name, value, allowed in (("episodes", episodes, COUNT), ("steps", steps, COUNT),
                                 ("final_eval_episodes", final_eval_episodes, FINAL_EVALUATION)):
        if value is not None:
            check_whole(name, value, allowed)


def _overrides(hyperparameters: dict[str, Any], episodes: int | None, steps: int | None) -> dict[str, Any]:
    """The config fields a call sets: its hyperparameters (lists as tuples, paths as strings) and its budgets."""
    from rlcore.training.run import budget_overrides

    given = {name: tuple(value) if isinstance(value, list) else os.fspath(value) if isinstance(value, os.PathLike)
             else value for name, value in hyperparameters.items()}
    return {**given, **budget_overrides(episodes, steps, given)}


def _train_and_evaluate(spec: Any, first_line: str, callback: ProgressCallback | None, progress: bool) -> Run:
    from rlcore.training.run import train_and_evaluate

    say: Callable[[str], None] = print if progress else (lambda line: None)
    say(first_line)
    with _quiet_unless(progress):
        model_dir, meta = train_and_evaluate(spec, on_progress=callback, say=say)
    return Run(spec.run_dir, model_dir, meta)


def _call(name: str, args: list[Any], kwargs: dict[str, Any]) -> str:
    """``rlcore.api.train('Acrobot-v1', 'dqn', seed=0, lr=0.0005)``: the call, as meta.json's command
    (defaults left out, paths as strings)."""
    defaults = {"preset": None, "run_dir": None, "episodes": None, "steps": None, "final_eval_episodes": None}
    shown = [repr(a) for a in args] + [f"{k}={str(v)!r}" if isinstance(v, os.PathLike) else f"{k}={v!r}"
                                       for k, v in kwargs.items() if not (k in defaults and v is None)]
    return f"rlcore.api.{name}({', '.join(shown)})"


@contextlib.contextmanager
def _quiet_unless(loud: bool) -> Iterator[None]:
    """With ``progress=False``, the trainer's per-rollout lines and the evaluation line go nowhere."""
    if loud:
        yield
        return
    import io
    from contextlib import redirect_stdout

    from tqdm.auto import tqdm

    write = tqdm.write
    tqdm.write = lambda *args, **kwargs: None
    try:
        with redirect_stdout(io.StringIO()):
            yield
    finally:
        tqdm.write = write
