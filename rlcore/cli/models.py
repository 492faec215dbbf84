"""The commands that play a saved model: ``evaluate``, ``render`` and ``export``, and which model folder
their flags choose (``--model``, else the shipped model; Mario's ``--world``/``--stage``). A model of a
user's Gymnasium env is registered as the run that trained it had (:func:`register_recorded_env`)."""
from __future__ import annotations

import contextlib
import importlib
import json
import tempfile
from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.atomic import writable_folder
from rlcore.models import shipping


def _shipped_choice(args) -> dict:
    """The shipped-model fields given on the command line (Mario: ``{"world": 1}`` for ``--world 1``)."""
    from rlcore.cli.parser import shipped_by_options

    return {name: getattr(args, name) for name in shipped_by_options() if getattr(args, name, None) is not None}


def _flags(names) -> str:
    return "/".join(f"--{name.replace('_', '-')}" for name in names)


def _model_dir(args) -> Path:
    """--model, else the shipped model (where an experiment ships one per value of some fields, that of
    the values given: Mario's --world/--stage, default 1-1)."""
    from rlcore.environments.gym_experiment import algorithms
    from rlcore.environments.registry import get_experiment

    exp = get_experiment(args.experiment)
    if not (args.model and exp.env_record and args.algo in algorithms()):
        exp.algo(args.algo)  # unknown names -> clear error; a model's own env (--env-kwargs) is read from it
    given = _shipped_choice(args)
    if not given and args.model:
        from rlcore.models.snapshot import given_folder

        return given_folder(args.model)
    if not given:
        return shipping.require_shipped(shipping.shipped_dir(args.experiment, args.algo),
                                        f"{args.experiment} {args.algo}")
    if exp.shipped_by is None or set(given) - set(exp.shipped_by.fields):
        from rlcore.environments.registry import experiment_names

        owners = [name for name in experiment_names() if (by := get_experiment(name).shipped_by)
                  and set(given) <= set(by.fields)]
        raise UserError(f"{_flags(given)} choose{'s' if len(given) == 1 else ''} among the shipped models of "
                        f"{', '.join(owners)}; {exp.name} ships one model per "
                        + (f"{exp.shipped_by.noun} ({_flags(exp.shipped_by.fields)})" if exp.shipped_by else "algorithm"))
    if args.model:
        raise UserError(f"give either --model or {_flags(exp.shipped_by.fields)}, not both")
    folder = shipping.models_root() / exp.name / exp.shipped_by.folder_from(given)
    return shipping.require_shipped(folder, f"for {exp.shipped_by.noun} {folder.name}")


def _output_name(args) -> str:
    """``mario_ppo_ppo_1-1`` for the shipped model chosen by its fields, else ``EXPERIMENT_ALGO``."""
    from rlcore.environments.registry import get_experiment
    from rlcore.training.spec import folder_safe

    name = f"{folder_safe(args.experiment)}_{args.algo}"
    shipped_by = get_experiment(args.experiment).shipped_by
    if shipped_by and _shipped_choice(args):
        name += f"_{shipped_by.folder_from(_shipped_choice(args))}"
    return name


@contextlib.contextmanager
def _model(args):
    """Yield ``(model folder, its name for the console)``: the chosen model folder, or for a run in
    progress (a checkpoint, no model yet) a snapshot of its last checkpoint in a temporary folder."""
    from rlcore.models.snapshot import is_run_in_progress, model_from_checkpoint

    folder = _model_dir(args)
    if not is_run_in_progress(folder):
        yield folder, str(folder)
        return
    if getattr(args, "record", False) or getattr(args, "record_further", False):
        flag = "--record" if args.record else "--record-further"
        raise UserError(f"{flag} writes into a model folder; {folder} is a run in progress, which has none")
    with tempfile.TemporaryDirectory(prefix="snapshot-") as tmp:
        meta = model_from_checkpoint(folder, tmp, args.experiment, args.algo)
        print(f"model:   the last checkpoint of {folder} (episode {meta['episodes']:,}, "
              f"env step {meta['env_steps']:,})")
        yield Path(tmp), f"{folder}, last checkpoint"


def cmd_evaluate(args) -> int:
    from rlcore.models.policies import load_policy

    if args.record and args.record_further:
        raise UserError("give --record (the model's evaluation) or --record-further (one more), not both")
    if args.replace and not args.record:
        raise UserError("--replace goes with --record (it lets the new evaluation overwrite the recorded one)")
    with _model(args) as (model_dir, name):
        if args.record or args.record_further:  # seeds checked before the model loads; it must match the names
            episodes = shipping.eval_episodes(shipping.experiment_of(model_dir), args.episodes)
            shipping.record_evaluation(model_dir, episodes, args.seed_base, args.experiment, args.algo,
                                       further=args.record_further, replace=args.replace)
            print(f"recorded in {model_dir / 'meta.json'}" + (" (further_evaluations)" if args.record_further else ""))
            return 0
        exp, meta, policy = load_policy(model_dir, args.experiment, args.algo)
        episodes = shipping.eval_episodes(exp, args.episodes)
        _, line = shipping.run_evaluation(exp, policy, episodes, args.seed_base, meta)
    print(f"{exp.name} {args.algo} ({name}): {line}")
    return 0


def render_video(model_dir: Path, out: Path, fps: int | None, episodes: int | None, seed: int | None) -> None:
    from rlcore.api.models import load, render_policy

    result = render_policy(load(model_dir), out, fps, episodes, seed)
    shown = (f"{result['frames']} frames at {result['fps']} fps" if "every" not in result else
             f"{result['frames']} frames from {result['frames_played']} at {result['fps']} fps: 1 in "
             f"{result['every']} kept, repeats merged; {result['bytes'] / 1e6:.2f} MB")
    reached = (f"; reached the goal in {sum(map(bool, result['success']))} of {len(result['success'])}"
               if "success" in result else "")
    print(f"video:   {out} ({shown}; "
          f"episode returns {', '.join(f'{r:.1f}' for r in result['returns'])}{reached})")


def cmd_render(args) -> int:
    from rlcore.models.policies import load_policy

    name = _output_name(args)
    from rlcore.models.video import video_path
    out = video_path(args.out or "videos", name)  # .mp4 or .gif (by the suffix), or a folder, else one line
    with _model(args) as (model_dir, _):
        load_policy(model_dir, args.experiment, args.algo)  # checks before any file is written
        writable_folder(out.parent, "--out")
        render_video(model_dir, out, args.fps, args.episodes, args.seed)
    return 0


def cmd_export(args) -> int:
    from rlcore.models.export import export_model, summary

    name = _output_name(args)
    out = Path(args.out) if args.out else Path("exports") / f"{name}_{args.format}"
    earlier = _earlier_export(out)
    with _model(args) as (model_dir, source):
        record = export_model(model_dir, args.format, out, observations=args.observations, source=source,
                              experiment=args.experiment, algo=args.algo)
    replaced = f"; it replaced the earlier {earlier} export there" if earlier else ""
    print(f"export:  {out / record['file']} ({record['format']}, runs on {record['runtime']['name']} "
          f"{record['runtime']['version']}{replaced})")
    print(f"parity:  {summary(record)} from seeds {record['parity']['seeds']}: passed")
    print(f"record:  {out / 'export.json'}")
    return 0


def _earlier_export(out: Path) -> str | None:
    """The format and model of the export ``out`` holds, which a new export there replaces whole."""
    import json

    try:
        record = json.loads((out / "export.json").read_text())
        return f"{record['format']} ({record['experiment']} {record['algo']})"
    except (OSError, ValueError, KeyError, TypeError):
        return None


def register_recorded_env(model: str | None) -> None:
    """A model (or a run in progress) of a user's Gymnasium env, named by its id alone or as MODULE:ID:
    register the env as the process that trained it had, by importing its module where the run names
    one, else from the record's entry point (meta.json's, or the checkpoint's)."""
    if not model:
        return
    import gymnasium as gym

    from rlcore.environments.gym_experiment import register_from_record
    from rlcore.files.checkpoint import read_checkpoint_state

    record = None
    with contextlib.suppress(ValueError, OSError, UserError):
        for path in (Path(model) / "meta.json", Path(model) / "model" / "meta.json"):
            if path.is_file():
                record = json.loads(path.read_text())
                break
        else:  # a run in progress: its checkpoint records the same
            if (Path(model) / "checkpoint.npz").is_file():
                record = read_checkpoint_state(Path(model) / "checkpoint.npz")
    if not record:
        return
    module, _, _ = str(record.get("experiment")).rpartition(":")
    if module:  # trained as MODULE:ID: the module registers it, as it did then (once, not twice)
        with contextlib.suppress(ImportError):  # not importable here: the record's entry point may be
            importlib.import_module(module)
    if (record.get("env") or {}).get("gymnasium_id") not in gym.registry:
        register_from_record(record.get("env") or {})
