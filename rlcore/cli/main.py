#!/usr/bin/env python3
"""Train, evaluate and render the package's deep-RL systems.

  python main.py list
  python main.py train lunar_lander dqn [--preset article|default] [--seed 0] [--lr 5e-4 ...]
  python main.py evaluate lunar_lander dqn [--model saved_networks/lunar_lander/dqn] [--episodes 100]
  python main.py render lunar_lander dqn [--out lander.mp4]

TensorFlow is imported only inside the commands that need it, so `list` and `--help` are quick.
The command line itself (every flag and the values it allows) is :mod:`rlcore.cli.parser`; the
installed ``deeprl`` script and a checkout's ``main.py`` both call :func:`main`. Here: ``list``,
``train`` and ``docs``; the commands that play a saved model are :mod:`rlcore.cli.models`, those that
read run and sweep folders :mod:`rlcore.cli.runs`.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

from rlcore.cli.models import cmd_evaluate, cmd_export, cmd_render, register_recorded_env, render_video  # noqa: E402
from rlcore.cli.parser import build_parser  # noqa: E402  (TF-free, as the rest here)
from rlcore.cli.runs import cmd_plot, cmd_report, cmd_status, cmd_sweep  # noqa: E402
from rlcore.errors import UserError  # noqa: E402
from rlcore.models import shipping  # noqa: E402


# ---------------------------------------------------------------- commands
def cmd_list(args) -> int:
    from rlcore.environments.registry import experiment_names, get_experiment

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
    """``--episodes`` / ``--steps`` as the config fields they set (:func:`rlcore.training.run.budget_overrides`)."""
    from rlcore.training.run import budget_overrides

    return budget_overrides(args.episodes, args.steps, given)


def _spec_from_args(args):
    from rlcore.hyperparams.flags import overrides_from_args, resuming_changes
    from rlcore.training.run import build_spec, check_new_run_dir
    from rlcore.training.spec import latest_run_dir, new_run_dir

    given = overrides_from_args(args)
    overrides = {**given, **_budget_overrides(args, given)}
    common = dict(preset=args.preset, seed=args.seed, overrides=overrides, wandb_mode=args.wandb,
                  progress=not args.no_progress, command=getattr(args, "command_line", None),
                  final_eval_episodes=args.final_eval_episodes, env_kwargs=args.env_kwargs)
    if args.resume is not None:
        run_dir = latest_run_dir(args.experiment, args.algo) if args.resume == "latest" else Path(args.resume)
        spec = build_spec(args.experiment, args.algo, run_dir=run_dir, resume=True,
                          nothing_to_train_ok=getattr(args, "publish", False), **common)
        from rlcore.files.checkpoint import read_checkpoint_state
        state = read_checkpoint_state(run_dir / "checkpoint.npz")
        print(f"resuming {run_dir} at episode {len(state['returns'])}, env step {state['env_steps']}"
              + resuming_changes(spec.changes))
        return spec
    run_dir = Path(args.run_dir) if args.run_dir else new_run_dir(args.experiment, args.algo, args.seed or 0)
    check_new_run_dir(run_dir)
    return build_spec(args.experiment, args.algo, run_dir=run_dir, **common)


def cmd_train(args) -> int:
    from rlcore.training.run import train_and_evaluate
    from rlcore.training.spec import folder_safe

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
        render_video(model_dir, model_dir / f"{folder_safe(spec.experiment.name)}_{spec.algo}.mp4", None, None, None)
    if args.publish:
        target = shipping.shipped_dir(spec.experiment.name, spec.algo, spec.config)
        if why := shipping.publish_refusal(spec.experiment, target, meta):
            raise UserError(f"not published to {target}/: {why}; the model stays in {model_dir}/")
        shipping.publish(model_dir, target)
        print(f"published to {target}/")
        if (bar := spec.experiment.bar(target.name)) and not bar.met_by(meta["evaluation"]):  # it spent its budget
            print(f"it ships short of its bar, having spent its budget: write where it stalls into the registry's "
                  f"below_bar reason for {target.name}, which its card gives")
    return 0


def cmd_docs(args) -> int:
    """The docs generator reads the checkout it lives in (tools/docgen/), not the installed package."""
    import subprocess

    checkout = Path(__file__).resolve().parents[2]
    if not (checkout / "tools" / "docgen" / "main.py").is_file():
        raise UserError("the docs generator is part of a checkout of the repository (tools/docgen/), not of "
                        "the installed package: run `python main.py docs` in a clone")
    return subprocess.call([sys.executable, "-m", "tools.docgen", *(["--check"] if args.check else [])], cwd=checkout)


COMMANDS = {"list": cmd_list, "train": cmd_train, "evaluate": cmd_evaluate, "render": cmd_render,
            "plot": cmd_plot, "status": cmd_status, "sweep": cmd_sweep, "report": cmd_report, "docs": cmd_docs,
            "export": cmd_export}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        args = build_parser(argv).parse_args(argv)
        if argv != sys.argv[1:]:  # called with its own arguments (a test, a script): record those, not
            import shlex  # the arguments of the process that called it
            args.command_line = shlex.join(["python", "main.py", *argv])
        if args.command in ("train", "evaluate", "render", "export"):
            from rlcore.training.stopping import guard_terminal_streams
            guard_terminal_streams()  # a terminal that closes (SIGHUP) must not cost a run its checkpoint
            from rlcore.environments.registry import require_experiment
            register_recorded_env(getattr(args, "model", None))
            require_experiment(args.experiment)  # a missing extra (mario, minitaur): one line, no run folder
            from rlcore.host.quiet import load_tensorflow
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
        from rlcore.training.stopping import Interrupted
        if isinstance(exc, Interrupted):
            print(str(exc), file=sys.stderr)
            return 130
        raise


if __name__ == "__main__":
    sys.exit(main())
