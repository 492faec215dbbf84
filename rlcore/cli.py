#!/usr/bin/env python3
"""Train, evaluate and render the package's deep-RL systems.

  python main.py list
  python main.py train lunar_lander dqn [--preset article|default] [--seed 0] [--lr 5e-4 ...]
  python main.py evaluate lunar_lander dqn [--model saved_networks/lunar_lander/dqn] [--episodes 100]
  python main.py render lunar_lander dqn [--out lander.mp4]

TensorFlow is imported only inside the commands that need it, so `list` and `--help` are quick.
The command line itself (every flag and the values it allows) is :mod:`rlcore.command_line`; the
installed ``deeprl`` script and a checkout's ``main.py`` both call :func:`main`.
"""
from __future__ import annotations

import contextlib
import importlib
import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

from rlcore.command_line import build_parser  # noqa: E402  (TF-free, as the rest here)
from rlcore import shipping  # noqa: E402
from rlcore.errors import UserError  # noqa: E402
from rlcore.atomic import writable_folder  # noqa: E402

# ---------------------------------------------------------------- commands
def cmd_list(args) -> int:
    from rlcore.experiment import experiment_names, get_experiment

    for name in experiment_names():
        exp = get_experiment(name)
        print(f"{name}: {exp.description}")
        for algo, spec in exp.algos.items():
            folders = ([shipping.shipped_dir(name, algo)] if exp.shipped_by is None
                       else sorted((shipping.models_root() / name).glob("*-*")))
            shipped = [shipping.shipped_summary(f) for f in folders if (f / "meta.json").is_file()]
            print(f"  {algo:<14} {spec.description:<24} presets: {', '.join(spec.presets):<25} "
                  f"{'; '.join(shipped) or 'no shipped model'}")
    return 0


def _budget_overrides(args, given: dict | None = None) -> dict:
    """``--episodes`` / ``--steps`` as the config fields they set (:func:`rlcore.run.budget_overrides`)."""
    from rlcore.run import budget_overrides

    return budget_overrides(args.episodes, args.steps, given)


def _spec_from_args(args):
    from rlcore.hparams import overrides_from_args, resuming_changes
    from rlcore.run import build_spec, check_new_run_dir
    from rlcore.trainers.spec import latest_run_dir, new_run_dir

    given = overrides_from_args(args)
    overrides = {**given, **_budget_overrides(args, given)}
    common = dict(preset=args.preset, seed=args.seed, overrides=overrides, wandb_mode=args.wandb,
                  progress=not args.no_progress, command=getattr(args, "command_line", None),
                  final_eval_episodes=args.final_eval_episodes)
    if args.resume is not None:
        run_dir = latest_run_dir(args.experiment, args.algo) if args.resume == "latest" else Path(args.resume)
        spec = build_spec(args.experiment, args.algo, run_dir=run_dir, resume=True,
                          nothing_to_train_ok=getattr(args, "publish", False), **common)
        from rlcore.checkpoint import read_checkpoint_state
        state = read_checkpoint_state(run_dir / "checkpoint.npz")
        print(f"resuming {run_dir} at episode {len(state['returns'])}, env step {state['env_steps']}"
              + resuming_changes(spec.changes))
        return spec
    run_dir = Path(args.run_dir) if args.run_dir else new_run_dir(args.experiment, args.algo, args.seed or 0)
    check_new_run_dir(run_dir)
    return build_spec(args.experiment, args.algo, run_dir=run_dir, **common)


def cmd_train(args) -> int:
    from rlcore.run import train_and_evaluate
    from rlcore.trainers.spec import folder_safe

    spec = _spec_from_args(args)
    final = spec.final_eval_episodes  # given, or on a resume the run's
    if args.publish and final is not None and final < spec.experiment.eval_episodes:
        given = "" if args.final_eval_episodes is not None else " (the run's; give it again to change it)"
        raise UserError(f"--publish needs the evaluation a shipped model has ({spec.experiment.eval_episodes} episodes "
                        f"on unseen seeds), not --final-eval-episodes {final}{given}")
    print(f"training {spec.experiment.name} {spec.algo} ({spec.preset} preset, seed {spec.seed}) "
          f"-> {spec.run_dir}")
    model_dir, meta = train_and_evaluate(spec)
    print(f"model:   {model_dir}/")
    print(f"plot:    {model_dir / meta['plot']}")
    print(f"metrics: {model_dir / 'metrics.csv'}")
    if args.video:
        _render(model_dir, model_dir / f"{folder_safe(spec.experiment.name)}_{spec.algo}.mp4", None, None, None)
    if args.publish:
        target = shipping.shipped_dir(spec.experiment.name, spec.algo, spec.config)
        if why := shipping.publish_refusal(spec.experiment, target, meta):
            raise UserError(f"not published to {target}/: {why}; the model stays in {model_dir}/")
        shipping.publish(model_dir, target)
        print(f"published to {target}/")
    return 0


def _shipped_choice(args) -> dict:
    """The shipped-model fields given on the command line (Mario: ``{"world": 1}`` for ``--world 1``)."""
    from rlcore.command_line import shipped_by_options

    return {name: getattr(args, name) for name in shipped_by_options() if getattr(args, name, None) is not None}


def _flags(names) -> str:
    return "/".join(f"--{name.replace('_', '-')}" for name in names)


def _model_dir(args) -> Path:
    """--model, else the shipped model (where an experiment ships one per value of some fields, that of
    the values given: Mario's --world/--stage, default 1-1)."""
    from rlcore.experiment import get_experiment

    exp = get_experiment(args.experiment)
    exp.algo(args.algo)  # unknown names -> clear error
    given = _shipped_choice(args)
    if not given and args.model:
        folder = Path(args.model)
        finished = folder / "model"  # a finished run's folder: its model
        return finished if (finished / "meta.json").is_file() and not (folder / "meta.json").is_file() else folder
    if not given:
        return shipping.require_shipped(shipping.shipped_dir(args.experiment, args.algo),
                                        f"{args.experiment} {args.algo}")
    if exp.shipped_by is None or set(given) - set(exp.shipped_by.fields):
        from rlcore.experiment import experiment_names

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
    from rlcore.experiment import get_experiment
    from rlcore.trainers.spec import folder_safe

    name = f"{folder_safe(args.experiment)}_{args.algo}"
    shipped_by = get_experiment(args.experiment).shipped_by
    if shipped_by and _shipped_choice(args):
        name += f"_{shipped_by.folder_from(_shipped_choice(args))}"
    return name


@contextlib.contextmanager
def _model(args):
    """Yield ``(model folder, its name for the console)``: the chosen model folder, or for a run in
    progress (a checkpoint, no model yet) a snapshot of its last checkpoint in a temporary folder."""
    from rlcore.snapshot import is_run_in_progress, model_from_checkpoint

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
    from rlcore.policies import load_policy

    if args.record and args.record_further:
        raise UserError("give --record (the model's evaluation) or --record-further (one more), not both")
    if args.replace and not args.record:
        raise UserError("--replace goes with --record (it lets the new evaluation overwrite the recorded one)")
    with _model(args) as (model_dir, name):
        if args.record or args.record_further:  # seeds checked before the model loads; it must match the names
            record = shipping.evaluate_further_into_meta if args.record_further else shipping.evaluate_into_meta
            episodes = shipping.eval_episodes(shipping.experiment_of(model_dir), args.episodes)
            extra = {} if args.record_further else {"replace": args.replace}
            record(model_dir, episodes, args.seed_base, args.experiment, args.algo, **extra)
            print(f"recorded in {model_dir / 'meta.json'}" + (" (further_evaluations)" if args.record_further else ""))
            return 0
        exp, meta, policy = load_policy(model_dir, args.experiment, args.algo)
        episodes = shipping.eval_episodes(exp, args.episodes)
        _, line = shipping.run_evaluation(exp, policy, episodes, args.seed_base, meta)
    print(f"{exp.name} {args.algo} ({name}): {line}")
    return 0


def _render(model_dir: Path, out: Path, fps: int | None, episodes: int | None, seed: int | None) -> None:
    from rlcore.api import load, render_policy

    result = render_policy(load(model_dir), out, fps, episodes, seed)
    shown = (f"{result['frames']} frames at {result['fps']} fps" if "every" not in result else
             f"{result['frames']} frames from {result['frames_played']} at {result['fps']} fps: 1 in "
             f"{result['every']} kept, repeats merged; {result['bytes'] / 1e6:.2f} MB")
    reached = f"; reached the goal: {result['success']}" if "success" in result else ""
    print(f"video:   {out} ({shown}; "
          f"episode returns {', '.join(f'{r:.1f}' for r in result['returns'])}{reached})")


def cmd_render(args) -> int:
    from rlcore.policies import load_policy

    name = _output_name(args)
    out = Path(args.out) if args.out else Path("videos") / f"{name}.mp4"
    if out.is_dir():
        out = out / f"{name}.mp4"
    from rlcore.video import check_video_path
    out = check_video_path(out)  # .mp4 or .gif (by the suffix), else one line
    with _model(args) as (model_dir, _):
        load_policy(model_dir, args.experiment, args.algo)  # checks before any file is written
        writable_folder(out.parent, "--out")
        _render(model_dir, out, args.fps, args.episodes, args.seed)
    return 0


def cmd_export(args) -> int:
    from rlcore.export import export_model, summary

    name = _output_name(args)
    out = Path(args.out) if args.out else Path("exports") / f"{name}_{args.format}"
    with _model(args) as (model_dir, source):
        record = export_model(model_dir, args.format, out, observations=args.observations, source=source,
                              experiment=args.experiment, algo=args.algo)
    print(f"export:  {out / record['file']} ({record['format']}, runs on {record['runtime']['name']} "
          f"{record['runtime']['version']})")
    print(f"parity:  {summary(record)} from seeds {record['parity']['seeds']}: passed")
    print(f"record:  {out / 'export.json'}")
    return 0


def _run_folder(run_dir: Path) -> dict:
    """What the run in ``run_dir`` trained (:func:`rlcore.status.run_record`: its model's meta.json once
    finished, its checkpoint's state while training or resumed past its model); a folder with neither,
    or without metrics.csv, is a clear error."""
    from rlcore.status import run_record

    if not run_dir.is_dir():
        raise UserError(f"{run_dir}: no such folder; give a run folder such as runs/<name>")
    if not (run_dir / "metrics.csv").is_file():
        raise UserError(f"no metrics.csv in {run_dir}; give a run folder such as runs/<name>")
    record = run_record(run_dir)
    if record is None:
        raise UserError(f"{run_dir} has neither a checkpoint nor a model/meta.json to say what it trained")
    return record


def cmd_plot(args) -> int:
    from rlcore.experiment import get_experiment
    from rlcore.plotting import plot_run

    run_dir = Path(args.run_dir)
    about = _run_folder(run_dir)
    out_dir = Path(args.out) if args.out else run_dir / "plots"
    writable_folder(out_dir, "--out")
    for path in plot_run(run_dir, out_dir, get_experiment(about["experiment"]), about):
        print(f"plot:    {path}")
    return 0


def cmd_status(args) -> int:
    from rlcore.experiment import get_experiment
    from rlcore.status import run_status

    run_dir = Path(args.run_dir)
    if (run_dir / "sweep.json").is_file():  # a sweep's folder: a line per trial
        from rlcore.sweep_status import sweep_status
        print("\n".join(sweep_status(run_dir)))
        return 0
    about = _run_folder(run_dir)
    print("\n".join(run_status(run_dir, get_experiment(about["experiment"]), about, args.block, args.blocks,
                                      args.rollout_block)))
    return 0


def cmd_sweep(args) -> int:
    from rlcore.experiment import get_experiment
    from rlcore.extras import require
    from rlcore.sweep import Sweep, parse_grid, parse_seeds, run_sweep

    require("ray.tune", "The sweep command")  # the sweep extra, or one line saying so
    exp = get_experiment(args.experiment)
    base = exp.preset(args.algo, args.preset)
    name = args.name or f"{args.experiment}__{args.algo}"
    folder = (Path(args.dir) / name).resolve()
    if args.resume:
        sweep = Sweep.load(folder)
        if (sweep.experiment, sweep.algo) != (args.experiment, args.algo):
            raise UserError(f"sweep {name} runs {sweep.experiment} {sweep.algo}, "
                            f"not {args.experiment} {args.algo}")
    else:
        if (folder / "sweep.json").exists():
            raise UserError(f"sweep {name} exists in {folder}; continue it with --resume or pick another --name")
        sweep = Sweep(args.experiment, args.algo, name, str(folder), parse_seeds(args.seeds),
                      parse_grid(args.grid, base), args.preset, _budget_overrides(args), args.cpus_per_run,
                      args.max_concurrent, args.final_eval_episodes)
    trials = sweep.trials()
    print(f"sweep {name}: {len(trials)} trials of {sweep.experiment} {sweep.algo} -> {folder}/")
    rows = run_sweep(sweep, address=args.address, num_cpus=args.num_cpus)
    for row in sorted(rows, key=lambda r: r["trial"]):
        if row.get("error"):
            status = f"failed: {row['error']}"
        elif row.get("not_started"):
            status = "not started (--resume starts it)"
        elif row.get("interrupted"):
            status = "stopped at a checkpoint (--resume continues it)"
        else:
            status = (f"final score {row.get('final_score', float('nan')):.3f}, "
                      f"{row.get('env_steps', 0):,} env steps"
                      + (" (finished earlier)" if row.get("skipped") else ""))
        print(f"  {row['trial']}: {status}")
    print(f"report: python main.py report {folder}")
    return 130 if (folder / "STOP").exists() else 0


def cmd_report(args) -> int:
    from rlcore.extras import require
    from rlcore.report import KEPT_FILES, is_run_folder, keep, keep_runs, markdown, summarize
    from rlcore.report_plots import plot_critic, plot_curves, plot_evals

    require("rliable.metrics", "The report command")  # the sweep extra, or one line saying so
    folders = [Path(d) for d in args.sweep_dirs]
    runs = [d for d in folders if is_run_folder(d)]
    if runs and not args.keep:
        raise UserError(f"{runs[0]} is a finished run, not a sweep: to report single runs of one recipe over "
                        f"seeds, keep them together first (--keep DIR)")
    if args.keep:
        if runs and len(runs) != len(folders):
            raise UserError("--keep takes one sweep folder, or finished run folders only, not both")
        if not runs and len(folders) != 1:
            raise UserError("--keep copies one sweep: give one SWEEP_DIR with it")
        folders = [keep_runs(runs, Path(args.keep)) if runs else keep(folders[0], Path(args.keep))]
        print(f"kept: {folders[0]} (sweep.json; per run {', '.join(KEPT_FILES)}, where the run has them)")
    result = summarize(folders, reps=args.reps)
    text = markdown(result)
    print(text)
    first = folders[0]
    from rlcore.atomic import write_atomic
    write_atomic(first / "report.md", lambda p: p.write_text(text + "\n"))
    pngs = [plot_curves(result, first / "report_curves.png"), plot_evals(result, first / "report_evals.png"),
            plot_critic(result, first / "report_critic.png")]
    for name, png in (("report_evals.png", pngs[1]), ("report_critic.png", pngs[2])):
        if png is None:  # nothing to draw now: an earlier report's figure would describe other runs
            (first / name).unlink(missing_ok=True)
    print(f"written: {first / 'report.md'}, {', '.join(str(p) for p in pngs if p)}")
    return 0


def cmd_docs(args) -> int:
    from rlcore.docgen import main as docgen_main

    return docgen_main(["--check"] if args.check else [])


def _register_recorded_env(model: str | None) -> None:
    """A model (or a run in progress) of a user's Gymnasium env, named by its id alone or as MODULE:ID:
    register the env as the process that trained it had, by importing its module where the run names
    one, else from the record's entry point (meta.json's, or the checkpoint's)."""
    if not model:
        return
    import gymnasium as gym

    from rlcore.checkpoint import read_checkpoint_state
    from rlcore.gym_experiment import register_from_record

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


COMMANDS = {"list": cmd_list, "train": cmd_train, "evaluate": cmd_evaluate, "render": cmd_render,
            "plot": cmd_plot, "status": cmd_status, "sweep": cmd_sweep, "report": cmd_report, "docs": cmd_docs,
            "export": cmd_export}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        args = build_parser(argv).parse_args(argv)
        if argv != sys.argv[1:]:  # called with its own arguments (a test, a script): record those, not
            import shlex          # the arguments of the process that called it
            args.command_line = shlex.join(["python", "main.py", *argv])
        if args.command in ("train", "evaluate", "render", "export"):
            from rlcore.trainers.stopping import guard_terminal_streams
            guard_terminal_streams()  # a terminal that closes (SIGHUP) must not cost a run its checkpoint
            from rlcore.extras import require_experiment
            _register_recorded_env(getattr(args, "model", None))
            require_experiment(args.experiment)  # a missing extra (mario, minitaur): one line, no run folder
            from rlcore.quiet import load_tensorflow
            load_tensorflow()  # before any other module imports it: its start-up noise is dropped
        return COMMANDS[args.command](args)
    except UserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\naborted (no checkpoint written by this interrupt)", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader left (`main.py status RUN | head -1`): nothing to say to it
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # so exit's flush is quiet
        return 1
    except Exception as exc:
        from rlcore.trainers.stopping import Interrupted
        if isinstance(exc, Interrupted):
            print(str(exc), file=sys.stderr)
            return 130
        raise


if __name__ == "__main__":
    sys.exit(main())
