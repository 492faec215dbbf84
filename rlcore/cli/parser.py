"""The command line (``deeprl``, or ``python main.py`` in a checkout): one subcommand per mode, and for `train` one flag per hyperparameter
of the chosen experiment's preset, a function per command below. Every value is checked here, before any
run folder exists; a bad command line is one line and exit status 2 (the parser class: rlcore.cli.parser_class).

TensorFlow-free, so `--help` is quick.
"""
from __future__ import annotations

import argparse
import functools

from rlcore.cli.parser_class import CommandParser, QuietParser, Unparsable
from rlcore.environments.seeding import MAX_RUN_SEED
from rlcore.errors import UserError
from rlcore.hyperparams import allowed
from rlcore.hyperparams.allowed import Allowed, whole_number
from rlcore.hyperparams.limits import EVAL_COUNT, FINAL_EVALUATION, FRAME_RATE, RUN_SEEDS


def folder_name(text: str) -> str:
    """A sweep's ``--name``: one folder under sweeps/, not a path that leads out of it."""
    if text.strip() in ("", ".", "..") or any(sep in text for sep in ("/", "\\")):
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: give a folder name (no '/'), such as lr_grid")
    return text


PRESET_HELP = ("a named set of hyperparameters: article, default, or another that `list` shows "
               "(default: default)")
COUNT, NON_NEGATIVE = whole_number(allowed.COUNT), whole_number(allowed.NON_NEGATIVE)
SEED = whole_number(RUN_SEEDS)
EVAL_EPISODES = whole_number(EVAL_COUNT)
FINAL_EVAL_EPISODES = whole_number(FINAL_EVALUATION)


EXAMPLES = """examples:
  {prog} list                                    experiments, algorithms, presets, shipped models
  {prog} render mario_ppo ppo --world 1 --stage 1 --out mario.gif
  {prog} evaluate lunar_lander dqn --episodes 20  a shipped model on unseen seeds
  {prog} train lunar_lander dqn --seed 1 --lr 5e-4
  {prog} train Acrobot-v1 ppo --steps 200000      any Gymnasium id whose spaces fit the algorithm
  {prog} train lunar_lander dqn --resume          continue the latest run from its checkpoint
  {prog} export minitaur sac --format onnx --out exports/minitaur
the docs: docs/ in the repository (`make docs` builds the site)"""


def program_name(argv0: str | None = None) -> str:
    """``deeprl`` when run as the installed script, else ``main.py`` (a checkout, the tests, the docs)."""
    import os
    import sys

    name = os.path.basename(sys.argv[0] if argv0 is None else argv0)
    return "deeprl" if name.startswith("deeprl") else "main.py"


def package_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("deeprl-tf2")
    except PackageNotFoundError:  # a checkout that was never installed
        return "unknown (not installed: pip install -e .)"


def _algorithms_by_experiment() -> str:
    from rlcore.environments.registry import experiment_names, get_experiment

    return "; ".join(f"{name}: {', '.join(get_experiment(name).algos)}" for name in experiment_names())


def env_kwargs_value(text: str) -> dict:
    """``--env-kwargs``'s value: a bad one is argparse's one line and exit status 2."""
    from rlcore.environments.env_kwargs import parse_env_kwargs

    try:
        return parse_env_kwargs(text)
    except UserError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--env-kwargs").lstrip(": ")) from None


def build_parser(argv: list[str], prog: str | None = None) -> argparse.ArgumentParser:
    """The whole command line; ``argv`` tells ``train`` which experiment's hyperparameters to add."""
    from rlcore.environments.registry import eval_episodes_words

    episodes = eval_episodes_words()
    prog = prog or program_name()
    parser = CommandParser(
        prog=prog, description="TensorFlow 2 / Keras deep RL: train, evaluate, render and export agents.",
        epilog=EXAMPLES.format(prog=prog), formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"%(prog)s {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=CommandParser)

    text = "experiments, algorithms, presets and shipped models with their scores"
    sub.add_parser("list", help=text, description=text[0].upper() + text[1:] + ", as the shipped models' "
                   "meta.json record them.")

    _add_train(sub, prog, episodes, argv)
    _add_evaluate_and_render(sub, episodes)
    _add_export(sub)
    _add_sweep(sub, episodes)
    _add_report(sub)
    _add_plot_status_and_docs(sub)
    return parser


def _add_train(sub, prog: str, episodes: str, argv: list[str]) -> None:
    """``train``: the run's own options, then one flag per hyperparameter of the chosen preset."""
    from rlcore.environments.registry import experiment_names

    train = sub.add_parser("train", help="train an agent (Ctrl-C or SIGTERM saves a checkpoint; --resume continues)",
                           description="Train an agent. Every hyperparameter of the chosen preset can be "
                                       f"overridden; `{prog} train EXPERIMENT ALGO --help` lists them.")
    train.add_argument("experiment", help=f"one of {', '.join(experiment_names())}, or any registered Gymnasium "
                                          "id whose spaces fit ALGO (Acrobot-v1; MODULE:ID imports the module "
                                          "that registers your own env first)")
    train.add_argument("algo", help=f"an algorithm of the experiment ({_algorithms_by_experiment()}); for a "
                                    "Gymnasium id: dqn, ddqn, dueling_dqn, dueling_ddqn, a2c, ppo (discrete "
                                    "actions) or sac (continuous actions)")
    train.add_argument("--preset", default=None, help=PRESET_HELP)
    train.add_argument("--episodes", type=COUNT, default=None, help="episode budget (max_episodes): DQN and SAC stop at it; A2C "
                       "and PPO check it after each rollout, so their envs may finish more, up to a rollout's worth")
    train.add_argument("--steps", type=COUNT, default=None, help="env step budget (max_env_steps), checked at the end of each episode (DQN, SAC) "
                       "or rollout (A2C, PPO: n_steps x num_envs env steps): a run ends at it or just past it")
    train.add_argument("--seed", type=SEED, default=None,
                       help=f"0 to {MAX_RUN_SEED}: seeds numpy, TensorFlow and the envs (default 0); each run "
                            "seed owns its own training env seeds, all below the evaluation seeds")
    train.add_argument("--wandb", default=None, choices=["auto", "online", "offline", "off"],
                       help="auto = online when logged in, else offline (default auto; a resume: the run's)")
    train.add_argument("--resume", nargs="?", const="latest", default=None, metavar="RUN_DIR",
                       help="continue a run from its checkpoint (default: the latest run of this algo)")
    train.add_argument("--run-dir", default=None, help="where the run writes (default runs/<name>)")
    train.add_argument("--final-eval-episodes", type=FINAL_EVAL_EPISODES, default=None,
                       help="evaluation episodes after training, on unseen seeds "
                            f"({episodes}; 0 = none; a resume: the run's)")
    train.add_argument("--video", action="store_true", help="also render an MP4 of the trained agent")
    train.add_argument("--publish", action="store_true",
                       help="copy the trained model into saved_networks/EXPERIMENT/ALGO/, replacing the "
                            "shipped one, if its evaluation on unseen seeds meets that model's bar")
    train.add_argument("--no-progress", action="store_true", help="no progress bar")
    train.add_argument("--env-kwargs", type=env_kwargs_value, default=None, metavar="KWARGS",
                       help="a Gymnasium id's constructor arguments, as key=value pairs or a JSON object "
                            "(continuous=True for LunarLander-v3, to train SAC); each is checked against the "
                            "env's parameters and recorded, so evaluate, render and export rebuild the env")
    _add_hyperparameters(train, argv)


def _add_evaluate_and_render(sub, episodes: str) -> None:
    """``evaluate`` (a saved model on unseen seeds, recorded or not) and ``render`` (a video of it)."""
    from rlcore.environments.registry import experiment_names

    for name, text in (("evaluate", "mean +- std of a saved model's return on unseen seeds, acting greedily "
                                    "(SAC: its mean action; Mario: actions drawn from pi, and the share of "
                                    "episodes reaching the flag)"),
                       ("render", "an MP4 or GIF of a saved model playing as evaluate plays it (greedily; SAC "
                                  "its mean action; Mario draws from pi)")):
        p = sub.add_parser(name, help=text, description=text)
        _add_model_choice(p, experiment_names())
        if name == "evaluate":
            p.add_argument("--episodes", type=EVAL_EPISODES, default=None, help=episodes)
            p.add_argument("--seed-base", type=NON_NEGATIVE, default=None,
                           help="episode i uses seed SEED_BASE+i (default: the experiment's unseen range)")
            p.add_argument("--record", action="store_true",
                           help="write the result into the model folder's meta.json as its evaluation "
                                "(refused if it records one, unless --replace)")
            p.add_argument("--replace", action="store_true",
                           help="with --record: overwrite the evaluation meta.json records")
            p.add_argument("--record-further", action="store_true",
                           help="add the result to the model folder's meta.json as a further evaluation on other "
                                "unseen seeds, its evaluation kept; by default on the seeds right after the last "
                                "ones recorded (more episodes, on seeds nothing chose the model by)")
        else:
            p.add_argument("--out", default=None,
                           help="an .mp4 or a .gif path (a GIF: ~320 px wide, every few frames, looping), "
                                "or a folder for an MP4, made if new (default videos/EXPERIMENT_ALGO.mp4)")
            p.add_argument("--fps", type=whole_number(FRAME_RATE), default=None,
                           help="frames per second (default: experiment's)")
            p.add_argument("--episodes", type=EVAL_EPISODES, default=None, help="default 1; Minitaur 3")
            p.add_argument("--seed", type=NON_NEGATIVE, default=None,
                           help="episode i uses seed SEED+i (default: the first evaluation seed)")


def _add_export(sub) -> None:
    """``export``: the acting network to SavedModel, TFLite or ONNX, checked against the Keras model."""
    from rlcore.environments.registry import experiment_names

    export = sub.add_parser(
        "export", help="the acting network as a TF SavedModel, a TFLite (LiteRT) file or an ONNX file, "
                       "checked against the Keras model",
        description="Export the acting network (Q-network, A2C actor, PPO's policy logits, SAC's mean "
                    "action with its Standardize layer) and check it before reporting success: the file, "
                    "loaded by its own runtime, against the Keras model on observations from the "
                    "experiment's env on evaluation seeds. OUT gets the file and export.json; a failed "
                    "check is one line, exit status 2, and OUT is left as it was. See docs/export.md.")
    _add_model_choice(export, experiment_names())
    export.add_argument("--format", required=True, choices=["savedmodel", "tflite", "onnx"],
                        help="savedmodel: a TF SavedModel folder (tf.saved_model.load, TF Serving); tflite: a .tflite "
                             "file for LiteRT; onnx: an .onnx file for onnxruntime (needs the export extra)")
    export.add_argument("--out", default=None, metavar="OUT",
                        help="the export folder, new or an earlier export (default "
                             "exports/EXPERIMENT_ALGO_FORMAT)")
    export.add_argument("--observations", type=whole_number(Allowed(low=1, high=100_000)), default=256,
                        help="observations the parity check feeds both networks (default 256)")


def _add_sweep(sub, episodes: str) -> None:
    """``sweep``: seeds x grid values on Ray Tune, each trial a run folder."""
    from rlcore.environments.registry import experiment_names

    sweep = sub.add_parser(
        "sweep", help="many runs (seeds x grid values) on Ray Tune, locally or on a cluster",
        description="One trial per combination of --seeds and --grid values; each trial is an ordinary "
                    "run folder under DIR/NAME/ (evaluate, render and plot work on it). A trial "
                    "restarted after a crash resumes from its checkpoint; Ctrl-C or SIGTERM stops every trial "
                    "at a checkpoint; --resume continues and skips finished trials.")
    sweep.add_argument("experiment", help=f"one of {', '.join(experiment_names())}, or any registered Gymnasium "
                                          "id whose spaces fit ALGO (as train takes)")
    sweep.add_argument("algo", help="an algorithm of the experiment (`list` shows them)")
    sweep.add_argument("--seeds", default="0-4", help="a range or a list: 0-4, 0,3,7 (default 0-4)")
    sweep.add_argument("--grid", action="append", default=[], metavar="NAME=V1,V2",
                       help="a hyperparameter and its values (repeatable), e.g. --grid lr=1e-4,3e-4")
    sweep.add_argument("--preset", default=None, help=PRESET_HELP)
    sweep.add_argument("--env-kwargs", type=env_kwargs_value, default=None, metavar="KWARGS",
                       help="a Gymnasium id's constructor arguments for every trial, as train's --env-kwargs")
    sweep.add_argument("--episodes", type=COUNT, default=None, help="episode budget of each run (as train's --episodes: A2C and PPO "
                       "check it after each rollout)")
    sweep.add_argument("--steps", type=COUNT, default=None, help="env step budget of each run (as train's --steps: it ends at the end of the "
                       "episode or rollout that reaches it)")
    sweep.add_argument("--final-eval-episodes", type=FINAL_EVAL_EPISODES, default=None,
                       help=f"evaluation episodes on unseen seeds after each run ({episodes})")
    sweep.add_argument("--max-concurrent", type=NON_NEGATIVE, default=0,
                       help="trials at once (default 0: as many as the CPUs allow)")
    sweep.add_argument("--cpus-per-run", type=whole_number(Allowed(low=1, high=256)), default=1,
                       help="CPUs reserved per trial; TensorFlow's threads follow it (default 1)")
    sweep.add_argument("--num-cpus", type=COUNT, default=None,
                       help="CPUs of the local Ray instance (default: all of this machine's)")
    sweep.add_argument("--name", type=folder_name, default=None,
                       help="sweep folder name, under --dir (default EXPERIMENT__ALGO)")
    sweep.add_argument("--dir", default="sweeps", metavar="DIR",
                       help="the folder that holds sweep folders (default sweeps, which git ignores; "
                            "long_runs/sweeps for a sweep that outlives a session)")
    sweep.add_argument("--address", default=None,
                       help="join a running Ray cluster (e.g. 10.0.0.5:6379) instead of starting local Ray")
    sweep.add_argument("--resume", action="store_true", help="continue the sweep NAME; finished trials are kept")


def _add_report(sub) -> None:
    """``report``: sweeps' results over seeds, and keeping them in results/."""
    report = sub.add_parser("report", help="results of sweeps: per run, and mean / median / IQM with 95%% CIs",
                            description="Per run: the final evaluation on unseen seeds, env steps, wall time, "
                                        "and what its periodic evaluations saw (collapses, the weights kept). "
                                        "Over runs: mean, median and IQM with 95% stratified bootstrap CIs "
                                        "(rliable's method); with two sweeps, P(first beats second). Where runs "
                                        "log a critic's Q (DQN family, SAC), each run's mean Q at its end beside "
                                        "its largest return. Writes report.md and report_curves.png into the "
                                        "sweep folder (several sweeps: into --out, else nothing is written), "
                                        "with report_success.png where runs log a goal's successes (Mario's "
                                        "flag: the share of the last 100 episodes), report_evals.png where "
                                        "they evaluated periodically and report_critic.png where they log Q.")
    report.add_argument("sweep_dirs", nargs="+", metavar="SWEEP_DIR",
                        help="a sweep's folder (several: one report, compared); with --keep, finished run "
                             "folders of one recipe over seeds (main.py train ... --seed S) may be given instead")
    report.add_argument("--reps", type=whole_number(Allowed(low=100, high=10**6)), default=5000, help="bootstrap resamples")
    report.add_argument("--out", metavar="DIR", default=None,
                        help="folder for report.md and its PNGs (default: the sweep's folder; a report of several "
                             "sweeps is only printed without it, so no sweep's own report is replaced)")
    report.add_argument("--keep", metavar="DIR", default=None,
                        help="first copy sweep.json and, per run, model/meta.json, the model's .h5 files and "
                             "its CSV tables (not the checkpoints) into DIR, a folder git keeps such as "
                             "results/sweeps/NAME, and write the report there; run folders go to DIR/seed=S "
                             "with a sweep.json written for them, each refused unless it followed one recipe "
                             "from random weights (no --init-from; its resumes changed budgets only)")


def _add_plot_status_and_docs(sub) -> None:
    """``plot`` and ``status`` (a run folder read back from its CSV tables), and ``docs``."""
    plot = sub.add_parser("plot", help="write the training plots of a run folder (running, interrupted "
                                       "or finished)",
                          description="Write the training plots of a run folder from its CSV tables: score "
                                      "per episode, periodic evaluations; for Mario, x position and flag "
                                      "share, a map of where episodes ended, and what killed Mario.")
    plot.add_argument("run_dir", help="a run folder, e.g. runs/mario_ppo__ppo__0__<time>")
    plot.add_argument("--out", default=None, help="folder for the PNGs (default RUN_DIR/plots)")

    status = sub.add_parser("status", help="where a run or a sweep stands, in a few lines: its pace, the hours "
                                           "left, the latest episodes (running, interrupted or finished)",
                            description="Print where a run stands from its CSV tables: per block of "
                                        "episodes that started where evaluations start, the success "
                                        "share, mean progress and mean return, the restarted episodes "
                                        "beside them, and what ended the failures; for a run without a "
                                        "goal (Minitaur), the mean episode length and metres walked; "
                                        "for PPO, per block of rollouts, the same shares beside "
                                        "the update sizes, learning rate and entropy weight; "
                                        "then the last periodic evaluations. Under the first line: a run "
                                        "in progress's env steps/s lately and the hours left at that pace "
                                        "to its env-step budget, and where the run was resumed and what "
                                        "each resume changed.")
    status.add_argument("run_dir", help="a run folder, e.g. long_runs/mario_ppo/2-2, or a sweep's folder "
                                        "(a line per trial, then the hours of training the sweep has left)")
    status.add_argument("--block", type=COUNT, default=200, help="episodes per block (default 200)")
    status.add_argument("--blocks", type=COUNT, default=6, help="how many of the newest blocks (default 6)")
    status.add_argument("--rollout-block", type=COUNT, default=20,
                        help="PPO: rollouts per block in the lines that show update sizes, the "
                             "learning rate and the entropy weight (default 20)")

    docs = sub.add_parser("docs", help="rewrite the README's and the docs' generated tables, the model cards "
                                       "and the reference pages from meta.json, results/ and the registry",
                          description="Rewrite every generated file and marked region (python -m tools.docgen).")
    docs.add_argument("--check", action="store_true",
                      help="write nothing; exit 1 listing every file that differs from what would be written")


def _add_model_choice(p: argparse.ArgumentParser, experiments: list[str]) -> None:
    """EXPERIMENT ALGO and which of its models: --model, or the fields that choose a shipped model where an
    experiment ships one per value of them (Mario's --world/--stage; evaluate, render, export)."""
    p.add_argument("experiment", help=f"one of {', '.join(experiments)}, or the Gymnasium id a --model was "
                                      "trained on")
    p.add_argument("algo", help="an algorithm of the experiment (`list` shows them)")
    p.add_argument("--model", default=None,
                   help="model folder, a finished run's folder, or a run in progress (its last "
                        "checkpoint) (default saved_networks/EXPERIMENT/ALGO)")
    for name, (parse, text) in shipped_by_options().items():
        p.add_argument(f"--{name.replace('_', '-')}", dest=name, type=parse, default=None, help=text)


@functools.cache
def shipped_by_options() -> dict[str, tuple]:
    """field -> (parse, help) of the config fields that choose a shipped model, for every registered
    experiment that ships one model per value of some fields (``Experiment.shipped_by``; Mario: world and
    stage -> ``--world``, ``--stage``). Parsed with the field's type and checked against its allowed values."""
    import dataclasses

    from rlcore.environments.registry import experiment_names, get_experiment
    from rlcore.hyperparams.flags import field_types

    options: dict[str, tuple] = {}
    for name in experiment_names():
        exp = get_experiment(name)
        if exp.shipped_by is None:
            continue
        config = exp.preset(next(iter(exp.algos)), None)
        fields = {f.name: f for f in dataclasses.fields(config)}
        types = field_types(type(config))
        for field_name, default in exp.shipped_by.default_values().items():
            allowed = fields[field_name].metadata.get("allowed")
            parse = whole_number(allowed) if types[field_name] is int and allowed is not None else types[field_name]
            options.setdefault(field_name, (parse, f"{name}: the shipped model of this {field_name} (default {default})"))
    return options


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
    first = QuietParser(add_help=False)
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
    except Unparsable:
        return
    from rlcore.environments.registry import get_experiment
    from rlcore.hyperparams.flags import add_arguments

    given = env_kwargs_value(names.env_kwargs) if names.env_kwargs else None
    from rlcore.training.spec import recorded_env

    # a resume's flags are its run's (a change of --env-kwargs is refused later)
    recorded = recorded_env(names.resume) if names.resume and names.resume != "latest" else {}
    experiment = get_experiment(names.experiment, recorded or None, env_kwargs=None if recorded else given)
    add_arguments(train, experiment.preset(names.algo, names.preset))
