#!/usr/bin/env python3
"""Train, evaluate and render the package's deep-RL systems.

  python main.py list
  python main.py train lunar_lander dqn [--preset article|default] [--seed 0] [--lr 5e-4 ...]
  python main.py evaluate lunar_lander dqn [--model saved_networks/lunar_lander/dqn] [--episodes 100]
  python main.py render lunar_lander dqn [--out lander.mp4]

TensorFlow is imported only inside the commands that need it, so `list` and `--help` are quick.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

from rlcore import shipping  # noqa: E402  (TF-free)
from rlcore import allowed  # noqa: E402
from rlcore.allowed import Allowed, whole_number  # noqa: E402
from rlcore.seeding import MAX_RUN_SEED  # noqa: E402
from rlcore.errors import UserError  # noqa: E402
from mario_ppo.levels import STAGE, WORLD  # noqa: E402  (TF-free)
from rlcore.atomic import writable_folder  # noqa: E402  (TF-free)

# ---------------------------------------------------------------- commands
def cmd_list(args) -> int:
    from rlcore.experiment import experiment_names, get_experiment

    for name in experiment_names():
        exp = get_experiment(name)
        print(f"{name}: {exp.description}")
        for algo, spec in exp.algos.items():
            folders = ([shipping.shipped_dir(name, algo)] if not exp.ship_by
                       else sorted((shipping.SAVED_NETWORKS / name).glob("*-*")))
            shipped = [shipping.shipped_summary(f) for f in folders if (f / "meta.json").is_file()]
            print(f"  {algo:<14} {spec.description:<24} presets: {', '.join(spec.presets):<25} "
                  f"{'; '.join(shipped) or 'no shipped model'}")
    return 0


def _budget_overrides(args) -> dict:
    """``--episodes`` / ``--steps`` as the config fields they set."""
    budget = {"max_episodes": args.episodes, "max_env_steps": args.steps}
    return {name: value for name, value in budget.items() if value is not None}


def _spec_from_args(args):
    from rlcore.hparams import overrides_from_args
    from rlcore.run import build_spec
    from rlcore.trainers.spec import latest_run_dir, new_run_dir

    overrides = {**overrides_from_args(args), **_budget_overrides(args)}
    common = dict(preset=args.preset, seed=args.seed, overrides=overrides, wandb_mode=args.wandb,
                  progress=not args.no_progress)
    if args.resume is not None:
        run_dir = latest_run_dir(args.experiment, args.algo) if args.resume == "latest" else Path(args.resume)
        spec = build_spec(args.experiment, args.algo, run_dir=run_dir, resume=True, **common)
        from rlcore.checkpoint import read_checkpoint_state
        state = read_checkpoint_state(run_dir / "checkpoint.npz")
        print(f"resuming {run_dir} at episode {len(state['returns'])}, env step {state['env_steps']}")
        return spec
    run_dir = Path(args.run_dir) if args.run_dir else new_run_dir(args.experiment, args.algo, args.seed)
    return build_spec(args.experiment, args.algo, run_dir=run_dir, **common)


def cmd_train(args) -> int:
    from rlcore.run import run_training

    spec = _spec_from_args(args)
    print(f"training {spec.experiment.name} {spec.algo} ({spec.preset} preset, seed {spec.seed}) "
          f"-> {spec.run_dir}")
    model_dir = run_training(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    print(f"trained: {meta['episodes']} episodes, {meta['env_steps']} env steps, "
          f"{meta['wall_seconds']:.0f} s; last-100 average {meta['final_average']:.1f}")
    episodes = shipping.eval_episodes(spec.experiment, args.final_eval_episodes)
    if episodes > 0:
        meta = shipping.evaluate_into_meta(model_dir, episodes)
    print(f"model:   {model_dir}/")
    print(f"plot:    {model_dir / meta['plot']}")
    print(f"metrics: {model_dir / 'metrics.csv'}")
    if args.video:
        _render(model_dir, model_dir / f"{spec.experiment.name}_{spec.algo}.mp4", None, None, None)
    if args.publish:
        target = shipping.shipped_dir(spec.experiment.name, spec.algo, spec.config)
        shipping.publish(model_dir, target)
        print(f"published to {target}/")
    return 0


def _model_dir(args) -> Path:
    """--model, else the shipped model (for Mario, that of --world/--stage, default 1-1)."""
    from rlcore.experiment import get_experiment

    exp = get_experiment(args.experiment)
    exp.algo(args.algo)  # unknown names -> clear error
    level = (args.world, args.stage)
    if level == (None, None) and args.model:
        folder = Path(args.model)
        finished = folder / "model"  # a finished run's folder: its model
        return finished if (finished / "meta.json").is_file() and not (folder / "meta.json").is_file() else folder
    if level == (None, None):
        return shipping.shipped_dir(args.experiment, args.algo)
    if not exp.ship_by:
        raise UserError(f"--world/--stage choose a Mario level; {exp.name} ships one model per algorithm")
    if args.model:
        raise UserError("give either --model or --world/--stage, not both")
    from types import SimpleNamespace

    folder = shipping.shipped_dir(exp.name, args.algo, SimpleNamespace(world=args.world or 1,
                                                                       stage=args.stage or 1))
    if not (folder / "meta.json").is_file():
        shipped = sorted(p.parent.name for p in folder.parent.glob("*-*/meta.json"))
        raise UserError(f"no shipped model for level {folder.name}; shipped levels: {', '.join(shipped) or 'none'}"
                        f" (or pass --model RUN_DIR/model)")
    return folder


@contextlib.contextmanager
def _model(args):
    """Yield ``(model folder, its name for the console)``: the chosen model folder, or for a run in
    progress (a checkpoint, no model yet) a snapshot of its last checkpoint in a temporary folder."""
    from rlcore.snapshot import is_run_in_progress, model_from_checkpoint

    folder = _model_dir(args)
    if not is_run_in_progress(folder):
        yield folder, str(folder)
        return
    if getattr(args, "record", False):
        raise UserError(f"--record writes into a model folder; {folder} is a run in progress, which has none")
    with tempfile.TemporaryDirectory(prefix="snapshot-") as tmp:
        meta = model_from_checkpoint(folder, tmp, args.experiment, args.algo)
        print(f"model:   the last checkpoint of {folder} (episode {meta['episodes']:,}, "
              f"env step {meta['env_steps']:,})")
        yield Path(tmp), f"{folder}, last checkpoint"


def cmd_evaluate(args) -> int:
    from rlcore.policies import load_policy

    with _model(args) as (model_dir, name):
        exp, meta, policy = load_policy(model_dir, args.experiment, args.algo)
        episodes = shipping.eval_episodes(exp, args.episodes)
        if args.record:
            shipping.evaluate_into_meta(model_dir, episodes, args.seed_base)
            print(f"recorded in {model_dir / 'meta.json'}")
            return 0
        _, line = shipping.run_evaluation(exp, policy, episodes, args.seed_base)
    print(f"{exp.name} {args.algo} ({name}): {line}")
    return 0


def _render(model_dir: Path, out: Path, fps: int | None, episodes: int | None, seed: int | None) -> None:
    from rlcore.policies import load_policy
    from rlcore.video import record_video

    exp, meta, policy = load_policy(model_dir)
    episodes = exp.episodes_per_video if episodes is None else episodes
    act = policy.sample if exp.success_key else None  # Mario plays as it was evaluated
    result = record_video(exp, policy, out, fps or exp.video_fps, episodes, seed,
                          make_env=policy.make_env, act=act)
    print(f"video:   {out} ({result['frames']} frames at {result['fps']} fps; "
          f"episode returns {', '.join(f'{r:.1f}' for r in result['returns'])})")


def cmd_render(args) -> int:
    from rlcore.policies import load_policy

    name = f"{args.experiment}_{args.algo}"
    if args.world or args.stage:
        name += f"_{args.world or 1}-{args.stage or 1}"
    out = Path(args.out) if args.out else Path("videos") / f"{name}.mp4"
    if out.is_dir():
        out = out / f"{name}.mp4"
    if out.suffix.lower() != ".mp4":
        raise UserError(f"--out {out}: give a file name ending in .mp4, or a folder")
    with _model(args) as (model_dir, _):
        load_policy(model_dir, args.experiment, args.algo)  # checks before any file is written
        writable_folder(out.parent, "--out")
        _render(model_dir, out, args.fps, args.episodes, args.seed)
    return 0


def cmd_plot(args) -> int:
    from rlcore.checkpoint import read_checkpoint_state
    from rlcore.experiment import get_experiment
    from rlcore.plotting import plot_run
    from rlcore.trainers.spec import CHECKPOINT_FILE

    run_dir = Path(args.run_dir)
    if not (run_dir / "metrics.csv").is_file():
        raise UserError(f"no metrics.csv in {run_dir}; give a run folder such as runs/<name>")
    if (run_dir / "model" / "meta.json").is_file():
        about = json.loads((run_dir / "model" / "meta.json").read_text())
    elif (run_dir / CHECKPOINT_FILE).is_file():
        about = read_checkpoint_state(run_dir / CHECKPOINT_FILE)
    else:
        raise UserError(f"{run_dir} has neither a checkpoint nor a model/meta.json to say what it trained")
    out_dir = Path(args.out) if args.out else run_dir / "plots"
    writable_folder(out_dir, "--out")
    for path in plot_run(run_dir, out_dir, get_experiment(about["experiment"]), about):
        print(f"plot:    {path}")
    return 0


def cmd_sweep(args) -> int:
    from rlcore.experiment import get_experiment
    from rlcore.sweep import SWEEPS_DIR, Sweep, parse_grid, parse_seeds, run_sweep

    exp = get_experiment(args.experiment)
    base = exp.preset(args.algo, args.preset)
    name = args.name or f"{args.experiment}__{args.algo}"
    folder = (SWEEPS_DIR / name).resolve()
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
    from rlcore.report import keep, markdown, plot_curves, summarize

    folders = [Path(d) for d in args.sweep_dirs]
    if args.keep:
        if len(folders) != 1:
            raise UserError("--keep copies one sweep: give one SWEEP_DIR with it")
        folders = [keep(folders[0], Path(args.keep))]
        print(f"kept: {folders[0]} (sweep.json; per run model/meta.json, metrics.csv, evals.csv)")
    result = summarize(folders, reps=args.reps)
    text = markdown(result)
    print(text)
    first = folders[0]
    from rlcore.atomic import write_atomic
    write_atomic(first / "report.md", lambda p: p.write_text(text + "\n"))
    png = plot_curves(result, first / "report_curves.png")
    print(f"written: {first / 'report.md'}, {png}")
    return 0


# ------------------------------------------------------------------ parser
class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad command line as one line (and exit status 2)."""

    def error(self, message):
        self.exit(2, f"error: {message} (see `{self.prog} --help`)\n")


def folder_name(text: str) -> str:
    """A sweep's ``--name``: one folder under sweeps/, not a path that leads out of it."""
    if text.strip() in ("", ".", "..") or any(sep in text for sep in ("/", "\\")):
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: give a folder name (no '/'), such as lr_grid")
    return text


COUNT, NON_NEGATIVE = whole_number(allowed.COUNT), whole_number(allowed.NON_NEGATIVE)
SEED = whole_number(Allowed(low=0, high=MAX_RUN_SEED))


def build_parser(argv: list[str]) -> argparse.ArgumentParser:
    parser = _Parser(
        prog="main.py", description="TensorFlow 2 / Keras deep RL: train, evaluate and render agents.",
        epilog="`main.py list` shows experiments, algorithms, presets and shipped models.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)

    sub.add_parser("list", help="experiments, algorithms, presets and shipped models with their scores")

    train = sub.add_parser("train", help="train an agent (Ctrl-C or SIGTERM saves a checkpoint; --resume continues)",
                           description="Train an agent. Every hyperparameter of the chosen preset can be "
                                       "overridden; `main.py train EXPERIMENT ALGO --help` lists them.")
    train.add_argument("experiment", help="e.g. lunar_lander")
    train.add_argument("algo", help="e.g. dqn, ddqn, dueling_dqn, dueling_ddqn, a2c")
    train.add_argument("--preset", default=None, help="article | default; Mario also levels (default: default)")
    train.add_argument("--episodes", type=COUNT, default=None, help="episode budget (max_episodes)")
    train.add_argument("--steps", type=COUNT, default=None, help="env step budget (max_env_steps)")
    train.add_argument("--seed", type=SEED, default=0,
                       help="seeds numpy, TensorFlow and the env (default 0); training env seeds stay "
                            "below 1,000,000, apart from the evaluation seeds")
    train.add_argument("--wandb", default="auto", choices=["auto", "online", "offline", "off"],
                       help="auto = online when logged in, else offline (default auto)")
    train.add_argument("--resume", nargs="?", const="latest", default=None, metavar="RUN_DIR",
                       help="continue a run from its checkpoint (default: the latest run of this algo)")
    train.add_argument("--run-dir", default=None, help="where the run writes (default runs/<name>)")
    train.add_argument("--final-eval-episodes", type=NON_NEGATIVE, default=None,
                       help="evaluation episodes after training, on unseen seeds "
                            "(default 100; Mario 10; 0 = none)")
    train.add_argument("--video", action="store_true", help="also render an MP4 of the trained agent")
    train.add_argument("--publish", action="store_true",
                       help="copy the trained model into saved_networks/EXPERIMENT/ALGO/")
    train.add_argument("--no-progress", action="store_true", help="no progress bar")
    _add_hyperparameters(train, argv)

    for name, text in (("evaluate", "greedy mean +- std of a saved model on unseen seeds "
                                    "(Mario: share of episodes reaching the flag, x position)"),
                       ("render", "MP4 of a saved model playing (greedily; Mario samples from pi)")):
        p = sub.add_parser(name, help=text, description=text)
        p.add_argument("experiment")
        p.add_argument("algo")
        p.add_argument("--model", default=None,
                       help="model folder, a finished run's folder, or a run in progress (its last "
                            "checkpoint) (default saved_networks/EXPERIMENT/ALGO)")
        p.add_argument("--world", type=whole_number(WORLD), default=None,
                       help="Mario: the shipped model of this world (default 1)")
        p.add_argument("--stage", type=whole_number(STAGE), default=None,
                       help="Mario: the shipped model of this stage (default 1)")
        if name == "evaluate":
            p.add_argument("--episodes", type=COUNT, default=None, help="default 100; Mario 10")
            p.add_argument("--seed-base", type=NON_NEGATIVE, default=None,
                           help="episode i uses seed SEED_BASE+i (default: the experiment's unseen range)")
            p.add_argument("--record", action="store_true",
                           help="write the result into the model folder's meta.json as its evaluation")
        else:
            p.add_argument("--out", default=None,
                           help="MP4 path, or a folder for it (default videos/EXPERIMENT_ALGO.mp4)")
            p.add_argument("--fps", type=whole_number(Allowed(low=1, high=240)), default=None,
                           help="frames per second (default: experiment's)")
            p.add_argument("--episodes", type=COUNT, default=None, help="default 1; Minitaur 3")
            p.add_argument("--seed", type=NON_NEGATIVE, default=None,
                           help="episode i uses seed SEED+i (default: the first evaluation seed)")
    sweep = sub.add_parser(
        "sweep", help="many runs (seeds x grid values) on Ray Tune, locally or on a cluster",
        description="One trial per combination of --seeds and --grid values; each trial is an ordinary "
                    "run folder under sweeps/NAME/ (evaluate, render and plot work on it). A trial "
                    "restarted after a crash resumes from its checkpoint; Ctrl-C or SIGTERM stops every trial "
                    "at a checkpoint; --resume continues and skips finished trials.")
    sweep.add_argument("experiment")
    sweep.add_argument("algo")
    sweep.add_argument("--seeds", default="0-4", help="a range or a list: 0-4, 0,3,7 (default 0-4)")
    sweep.add_argument("--grid", action="append", default=[], metavar="NAME=V1,V2",
                       help="a hyperparameter and its values (repeatable), e.g. --grid lr=1e-4,3e-4")
    sweep.add_argument("--preset", default=None, help="article | default; Mario also levels (default: default)")
    sweep.add_argument("--episodes", type=COUNT, default=None, help="episode budget of each run")
    sweep.add_argument("--steps", type=COUNT, default=None, help="env step budget of each run")
    sweep.add_argument("--final-eval-episodes", type=NON_NEGATIVE, default=None,
                       help="evaluation episodes on unseen seeds after each run (default 100; Mario 10)")
    sweep.add_argument("--max-concurrent", type=NON_NEGATIVE, default=0,
                       help="trials at once (default 0: as many as the CPUs allow)")
    sweep.add_argument("--cpus-per-run", type=whole_number(Allowed(low=1, high=256)), default=1,
                       help="CPUs reserved per trial; TensorFlow's threads follow it (default 1)")
    sweep.add_argument("--num-cpus", type=COUNT, default=None,
                       help="CPUs of the local Ray instance (default: all of this machine's)")
    sweep.add_argument("--name", type=folder_name, default=None,
                       help="sweep folder name, under sweeps/ (default EXPERIMENT__ALGO)")
    sweep.add_argument("--address", default=None,
                       help="join a running Ray cluster (e.g. 10.0.0.5:6379) instead of starting local Ray")
    sweep.add_argument("--resume", action="store_true", help="continue the sweep NAME; finished trials are kept")
    report = sub.add_parser("report", help="results of sweeps: per run, and mean / median / IQM with 95%% CIs",
                            description="Per run: the final evaluation on unseen seeds, env steps, wall time. "
                                        "Over runs: mean, median and IQM with 95%% stratified bootstrap CIs "
                                        "(rliable's method); with two sweeps, P(first beats second). Writes "
                                        "report.md and report_curves.png into the first sweep folder.")
    report.add_argument("sweep_dirs", nargs="+", metavar="SWEEP_DIR")
    report.add_argument("--reps", type=whole_number(Allowed(low=100, high=10**6)), default=5000, help="bootstrap resamples")
    report.add_argument("--keep", metavar="DIR", default=None,
                        help="first copy sweep.json and, per run, model/meta.json, metrics.csv and evals.csv "
                             "(not the checkpoints) into DIR, a folder git keeps such as "
                             "results/sweeps/NAME, and write the report there")

    plot = sub.add_parser("plot", help="write the training plots of a run folder (running, interrupted "
                                       "or finished)",
                          description="Write the training plots of a run folder from its CSV tables: score "
                                      "per episode, periodic evaluations; for Mario, x position and flag "
                                      "share, and a map of where episodes ended.")
    plot.add_argument("run_dir", help="a run folder, e.g. runs/mario_ppo__ppo__0__<time>")
    plot.add_argument("--out", default=None, help="folder for the PNGs (default RUN_DIR/plots)")
    return parser


class _Unparsable(Exception):
    pass


class _QuietParser(argparse.ArgumentParser):
    def error(self, message):
        raise _Unparsable(message)


def _add_hyperparameters(train: argparse.ArgumentParser, argv: list[str]) -> None:
    """Once EXPERIMENT and ALGO are on the command line, add one flag per hyperparameter.

    A first, forgiving parse finds them (and ``--preset``) wherever they stand; a line it cannot
    read is left to the full parse, which reports it. Hyperparameter flags are not known yet, so
    it steps over any other ``--name value`` pair (every hyperparameter takes one value): a
    ``--lr 1e-3`` before the names does not make ``1e-3`` the experiment.
    """
    if argv[:1] != ["train"]:
        return
    known = {option for action in train._actions for option in action.option_strings}
    line, tokens = [], iter(argv[1:])
    for token in tokens:
        if token.startswith("--") and "=" not in token and token not in known:
            next(tokens, None)
        elif token not in ("-h", "--help"):
            line.append(token)
    first = _QuietParser(add_help=False)
    first.add_argument("experiment")
    first.add_argument("algo")
    first.add_argument("--preset")
    for action in train._actions:  # the other train options, so their values are not taken as names
        if action.option_strings and action.dest not in ("help", "preset"):
            if action.nargs == 0:
                first.add_argument(*action.option_strings, action="store_true")
            else:
                first.add_argument(*action.option_strings, nargs=action.nargs, const=action.const)
    try:
        names, _ = first.parse_known_args(line)
    except _Unparsable:
        return
    from rlcore.experiment import get_experiment
    from rlcore.hparams import add_arguments

    add_arguments(train, get_experiment(names.experiment).preset(names.algo, names.preset))


COMMANDS = {"list": cmd_list, "train": cmd_train, "evaluate": cmd_evaluate, "render": cmd_render,
            "plot": cmd_plot, "sweep": cmd_sweep, "report": cmd_report}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        args = build_parser(argv).parse_args(argv)
        if args.command in ("train", "evaluate", "render"):
            from rlcore.quiet import load_tensorflow
            load_tensorflow()  # before any other module imports it: its start-up noise is dropped
        return COMMANDS[args.command](args)
    except UserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\naborted (no checkpoint written by this interrupt)", file=sys.stderr)
        return 130
    except Exception as exc:
        from rlcore.trainers.stopping import Interrupted
        if isinstance(exc, Interrupted):
            print(str(exc), file=sys.stderr)
            return 130
        raise


if __name__ == "__main__":
    sys.exit(main())
