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
import json
import os
import shutil
import sys
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

from rlcore.errors import UserError  # noqa: E402  (TF-free)

SAVED_NETWORKS = Path("saved_networks")


def shipped_dir(experiment: str, algo: str, config=None) -> Path:
    """saved_networks/EXPERIMENT/ALGO, or for Mario saved_networks/mario_ppo/WORLD-STAGE (one
    model per level: ``extra["ship_by"]`` names the config fields; without a config, the
    experiment's ``extra["default_model"]``)."""
    from rlcore.experiment import get_experiment

    extra = get_experiment(experiment).extra
    if "ship_by" not in extra:
        return SAVED_NETWORKS / experiment / algo
    if config is None:
        return SAVED_NETWORKS / experiment / extra["default_model"]
    return SAVED_NETWORKS / experiment / "-".join(str(getattr(config, f)) for f in extra["ship_by"])


# ---------------------------------------------------------------- commands
def cmd_list(args) -> int:
    from rlcore.experiment import experiment_names, get_experiment

    for name in experiment_names():
        exp = get_experiment(name)
        print(f"{name}: {exp.description}")
        for algo, spec in exp.algos.items():
            folders = ([shipped_dir(name, algo)] if "ship_by" not in exp.extra
                       else sorted((SAVED_NETWORKS / name).glob("*-*")))
            shipped = [_shipped_summary(f) for f in folders if (f / "meta.json").is_file()]
            print(f"  {algo:<14} {spec.description:<24} presets: {', '.join(spec.presets):<18} "
                  f"{'; '.join(shipped) or 'no shipped model'}")
    return 0


def _shipped_summary(folder: Path) -> str:
    from rlcore.policies import read_meta

    ev = read_meta(folder).get("evaluation")
    if not ev:
        return f"{folder.name}: shipped (not evaluated)"
    if "success_share" in ev:
        return f"{folder.name}: success in {ev['success_share']:.0%} of {ev['episodes']} episodes"
    return f"shipped: {ev['mean']:.1f} +- {ev['std']:.1f} over {ev['episodes']} episodes"


def _spec_from_args(args):
    from rlcore.experiment import get_experiment
    from rlcore.hparams import apply_overrides, overrides_from_args
    from rlcore.trainers.session import RunSpec, check_resumable, latest_run_dir, new_run_dir

    exp = get_experiment(args.experiment)
    overrides = overrides_from_args(args)
    if args.episodes is not None:
        overrides["max_episodes"] = args.episodes
    if args.steps is not None:
        overrides["max_env_steps"] = args.steps
    if args.resume is not None:
        run_dir = latest_run_dir(exp.name, args.algo) if args.resume == "latest" else Path(args.resume)
        spec = RunSpec(exp, args.algo, args.preset or "", None, args.seed, args.wandb, run_dir, True,
                       progress=not args.no_progress)
        state = check_resumable(spec)
        from rlcore.hparams import from_dict
        config_class = type(exp.preset(args.algo, None))
        # the checkpoint's own hyperparameters; budgets may be raised from the command line
        spec.config = apply_overrides(from_dict(config_class, state["config"]), overrides)
        spec.preset, spec.seed = state["preset"], state["seed"]
        print(f"resuming {run_dir} at episode {len(state['returns'])}, env step {state['env_steps']}")
        return spec
    config = apply_overrides(exp.preset(args.algo, args.preset), overrides)
    preset = args.preset or exp.algo(args.algo).default_preset
    return RunSpec(exp, args.algo, preset, config, args.seed, args.wandb,
                   Path(args.run_dir) if args.run_dir else new_run_dir(exp.name, args.algo, args.seed),
                   progress=not args.no_progress)


def cmd_train(args) -> int:
    import importlib

    spec = _spec_from_args(args)
    trainer = importlib.import_module(f"rlcore.trainers.{spec.kind}")
    print(f"training {spec.experiment.name} {spec.algo} ({spec.preset} preset, seed {spec.seed}) "
          f"-> {spec.run_dir}")
    model_dir = trainer.train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    print(f"trained: {meta['episodes']} episodes, {meta['env_steps']} env steps, "
          f"{meta['wall_seconds']:.0f} s; last-100 average {meta['final_average']:.1f}")
    episodes = _eval_episodes(spec.experiment, args.final_eval_episodes)
    if episodes > 0:
        meta = _evaluate_into_meta(model_dir, episodes)
    print(f"model:   {model_dir}/")
    print(f"plot:    {model_dir / meta['plot']}")
    print(f"metrics: {model_dir / 'metrics.csv'}")
    if args.video:
        _render(model_dir, model_dir / f"{spec.experiment.name}_{spec.algo}.mp4", None, None, None)
    if args.publish:
        target = shipped_dir(spec.experiment.name, spec.algo, spec.config)
        _publish(model_dir, target)
        print(f"published to {target}/")
    return 0


def _eval_episodes(exp, requested: int | None) -> int:
    return exp.extra.get("eval_episodes", 100) if requested is None else requested


def _run_evaluation(exp, policy, episodes: int, seed_base: int | None) -> tuple[dict, str]:
    """Evaluate a loaded policy on unseen seeds: ``(summary for meta.json, one-line report)``.

    Experiments with a success event (Mario's flag) draw actions from pi with a per-episode seed
    (their greedy play is one deterministic trajectory); the others play greedily.
    """
    seed_base = exp.eval_seed_base if seed_base is None else seed_base
    seeds = f"{seed_base}..{seed_base + episodes - 1}"
    success_key, progress_key = exp.extra.get("success_key"), exp.extra.get("progress_key")
    if success_key:
        from rlcore.evaluation import evaluate_success, summarize_success

        records = evaluate_success(policy.make_env, policy.sample, episodes, seed_base, success_key,
                                   progress_key)
        summary = {**summarize_success(records, progress_key), "seeds": seeds,
                   "policy": "sampled from pi, numpy RNG seeded per episode",
                   "per_episode": records}
        line = (f"{success_key} in {sum(r['success'] for r in records)}/{len(records)} episodes "
                f"({summary['success_share']:.0%}); mean return {summary['mean_return']:.1f}")
        if progress_key:
            line += (f"; {progress_key} mean {summary[f'mean_{progress_key}']:.0f}, "
                     f"max {summary[f'max_{progress_key}']:.0f}")
        return summary, line + f" (seeds {seeds}, actions sampled from pi)"
    from rlcore.evaluation import evaluate

    returns = evaluate(exp, policy, episodes, seed_base, make_env=policy.make_env)
    summary = {"episodes": episodes, "mean": round(float(returns.mean()), 2),
               "std": round(float(returns.std()), 2), "min": round(float(returns.min()), 2),
               "seeds": seeds, "policy": "greedy"}
    line = (f"greedy return {returns.mean():.1f} +- {returns.std():.1f} over {len(returns)} episodes "
            f"(min {returns.min():.1f}, max {returns.max():.1f})")
    if exp.solved_score is not None:
        line += f"; solved threshold {exp.solved_score:g}: {'met' if returns.mean() >= exp.solved_score else 'not met'}"
    return summary, line


def _evaluate_into_meta(model_dir: Path, episodes: int, seed_base: int | None = None) -> dict:
    from rlcore.atomic import write_json
    from rlcore.policies import load_policy

    exp, meta, policy = load_policy(model_dir)
    meta["evaluation"], line = _run_evaluation(exp, policy, episodes, seed_base)
    write_json(model_dir / "meta.json", meta)
    print(f"evaluation (unseen seeds): {line}")
    return meta


def _publish(model_dir: Path, target: Path) -> None:
    """Copy a finished model folder into saved_networks/, each file atomically, meta.json last."""
    from rlcore.atomic import write_atomic

    target.mkdir(parents=True, exist_ok=True)
    files = sorted(p for p in model_dir.iterdir() if p.is_file() and p.name != "meta.json")
    for src in files + [model_dir / "meta.json"]:
        write_atomic(target / src.name, lambda tmp, src=src: shutil.copyfile(src, tmp))


def _model_dir(args) -> Path:
    from rlcore.experiment import get_experiment

    get_experiment(args.experiment).algo(args.algo)  # unknown names -> clear error
    return Path(args.model) if args.model else shipped_dir(args.experiment, args.algo)


def cmd_evaluate(args) -> int:
    from rlcore.policies import load_policy

    model_dir = _model_dir(args)
    exp, meta, policy = load_policy(model_dir, args.experiment, args.algo)
    episodes = _eval_episodes(exp, args.episodes)
    if args.record:
        _evaluate_into_meta(model_dir, episodes, args.seed_base)
        print(f"recorded in {model_dir / 'meta.json'}")
        return 0
    _, line = _run_evaluation(exp, policy, episodes, args.seed_base)
    print(f"{exp.name} {args.algo} ({model_dir}): {line}")
    return 0


def _render(model_dir: Path, out: Path, fps: int | None, episodes: int | None, seed: int | None) -> None:
    from rlcore.policies import load_policy
    from rlcore.video import record_video

    exp, meta, policy = load_policy(model_dir)
    episodes = exp.extra.get("episodes_per_video", 1) if episodes is None else episodes
    act = policy.sample if exp.extra.get("success_key") else None  # Mario plays as it was evaluated
    result = record_video(exp, policy, out, fps or exp.video_fps, episodes, seed,
                          make_env=policy.make_env, act=act)
    print(f"video:   {out} ({result['frames']} frames at {result['fps']} fps; "
          f"episode returns {', '.join(f'{r:.1f}' for r in result['returns'])})")


def cmd_render(args) -> int:
    model_dir = _model_dir(args)
    from rlcore.policies import load_policy
    load_policy(model_dir, args.experiment, args.algo)  # checks before any file is written
    out = Path(args.out) if args.out else Path("videos") / f"{args.experiment}_{args.algo}.mp4"
    _render(model_dir, out, args.fps, args.episodes, args.seed)
    return 0


# ------------------------------------------------------------------ parser
class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad command line as one line (and exit status 2)."""

    def error(self, message):
        self.exit(2, f"error: {message} (see `{self.prog} --help`)\n")


def build_parser(argv: list[str]) -> argparse.ArgumentParser:
    parser = _Parser(
        prog="main.py", description="TensorFlow 2 / Keras deep RL: train, evaluate and render agents.",
        epilog="`main.py list` shows experiments, algorithms, presets and shipped models.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)

    sub.add_parser("list", help="experiments, algorithms, presets and shipped models with their scores")

    train = sub.add_parser("train", help="train an agent (Ctrl-C saves a checkpoint; --resume continues)",
                           description="Train an agent. Every hyperparameter of the chosen preset can be "
                                       "overridden; `main.py train EXPERIMENT ALGO --help` lists them.")
    train.add_argument("experiment", help="e.g. lunar_lander")
    train.add_argument("algo", help="e.g. dqn, ddqn, dueling_dqn, dueling_ddqn, a2c")
    train.add_argument("--preset", default=None, help="article | default (default: default)")
    train.add_argument("--episodes", type=int, default=None, help="episode budget (max_episodes)")
    train.add_argument("--steps", type=int, default=None, help="env step budget (max_env_steps)")
    train.add_argument("--seed", type=int, default=0, help="seeds numpy, TensorFlow and the env (default 0)")
    train.add_argument("--wandb", default="auto", choices=["auto", "online", "offline", "off"],
                       help="auto = online when logged in, else offline (default auto)")
    train.add_argument("--resume", nargs="?", const="latest", default=None, metavar="RUN_DIR",
                       help="continue a run from its checkpoint (default: the latest run of this algo)")
    train.add_argument("--run-dir", default=None, help="where the run writes (default runs/<name>)")
    train.add_argument("--final-eval-episodes", type=int, default=None,
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
                       help="model folder (default saved_networks/EXPERIMENT/ALGO)")
        if name == "evaluate":
            p.add_argument("--episodes", type=int, default=None, help="default 100; Mario 10")
            p.add_argument("--seed-base", type=int, default=None,
                           help="episode i uses seed SEED_BASE+i (default: the experiment's unseen range)")
            p.add_argument("--record", action="store_true",
                           help="write the result into the model folder's meta.json as its evaluation")
        else:
            p.add_argument("--out", default=None, help="MP4 path (default videos/EXPERIMENT_ALGO.mp4)")
            p.add_argument("--fps", type=int, default=None, help="frames per second (default: experiment's)")
            p.add_argument("--episodes", type=int, default=None, help="default 1; Minitaur 3")
            p.add_argument("--seed", type=int, default=None)
    return parser


def _add_hyperparameters(train: argparse.ArgumentParser, argv: list[str]) -> None:
    """Once EXPERIMENT and ALGO are on the command line, add one flag per hyperparameter."""
    if argv[:1] != ["train"]:
        return
    names = [a for a in argv[1:3] if not a.startswith("-")]
    if len(names) < 2:
        return
    from rlcore.experiment import get_experiment
    from rlcore.hparams import add_arguments

    preset = argv[argv.index("--preset") + 1] if "--preset" in argv[:-1] else None
    add_arguments(train, get_experiment(names[0]).preset(names[1], preset))


COMMANDS = {"list": cmd_list, "train": cmd_train, "evaluate": cmd_evaluate, "render": cmd_render}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        args = build_parser(argv).parse_args(argv)
        return COMMANDS[args.command](args)
    except UserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\naborted (no checkpoint written by this interrupt)", file=sys.stderr)
        return 130
    except Exception as exc:
        from rlcore.trainers.session import Interrupted
        if isinstance(exc, Interrupted):
            print(str(exc), file=sys.stderr)
            return 130
        raise


if __name__ == "__main__":
    sys.exit(main())
