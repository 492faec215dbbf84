"""Sweeps on Ray Tune: one trial per (seed, grid value ...) combination, each an ordinary run folder.

    sweeps/<name>/sweep.json            what the sweep is (experiment, algo, preset, seeds, grid, budgets)
    sweeps/<name>/<trial>/              metrics.csv, checkpoint.npz, model/ (meta.json) ...: a run folder
    sweeps/<name>/trials.log            a line per start and end of each trial's attempt
    sweeps/<name>/_tune/                Ray Tune's own records

A trial calls :func:`rlcore.run.run_training`, the function ``main.py train`` calls, and reports
every logged row to Tune as it comes. Fault tolerance lives in the run folder, not in Tune: a trial
that starts where a checkpoint exists resumes it (so a trial whose worker was killed and that Tune
restarts continues its counters; one killed before its first checkpoint starts over, its tables
cleared), and a trial whose ``model/meta.json`` exists has trained and is not trained again
(``--resume``): it is finished once that file holds its evaluation on unseen seeds, and evaluated first
where the process ended before it. A trial that fails with a user error (a bad value, a diverged loss, a
run folder another process writes) is reported once, not retried: a retry would fail the same way. Ctrl-C or SIGTERM writes ``sweeps/<name>/STOP``: every running trial
stops at its next safe point with a checkpoint, and the sweep ends (then Ray is shut down; a driver
killed outright would leave Ray's workers running).

Local Ray is started here with a fixed CPU count, no dashboard and every service on 127.0.0.1;
``address`` joins an existing cluster instead. This module is TensorFlow-free (trials import it).
"""
from __future__ import annotations

import argparse
import contextlib
import itertools
import json
import os
import signal
import sys
import time
import dataclasses
from dataclasses import asdict, dataclass, field
from pathlib import Path

from rlcore.atomic import writable_folder, write_json
from rlcore.errors import UserError
from rlcore.trainers.stopping import STOP_SIGNALS, announce_stop

SWEEP_FILE = "sweep.json"
STOP_FILE = "STOP"
TRIALS_LOG = "trials.log"


@dataclass
class Sweep:
    """What a sweep runs: every combination of ``seeds`` and the ``grid`` values, on top of a preset."""
    experiment: str
    algo: str
    name: str
    folder: str  # absolute path of sweeps/<name>, where it is now: not written to sweep.json
    seeds: list[int]
    grid: dict[str, list] = field(default_factory=dict)  # hyperparameter -> values
    preset: str | None = None
    overrides: dict = field(default_factory=dict)  # budgets (max_env_steps, max_episodes)
    cpus_per_run: float = 1.0
    max_concurrent: int = 0  # 0 = as many as the CPUs allow
    final_eval_episodes: int | None = None  # None = the experiment's default

    def trials(self) -> list[dict]:
        """One dict per trial: the seed and one value of every grid field."""
        names = sorted(self.grid)
        combos = itertools.product(*(self.grid[n] for n in names)) if names else [()]
        return [{**dict(zip(names, values)), "seed": seed} for values in combos for seed in self.seeds]

    def save(self) -> None:
        # the folder is where sweep.json lies; an absolute path would name this machine's checkout
        write_json(Path(self.folder) / SWEEP_FILE, {k: v for k, v in asdict(self).items() if k != "folder"})

    @classmethod
    def load(cls, folder: Path) -> "Sweep":
        path = Path(folder) / SWEEP_FILE
        if not path.is_file():
            raise UserError(f"no sweep to resume in {folder} (no {SWEEP_FILE}); start it without --resume")
        data = json.loads(path.read_text())
        data["folder"] = str(Path(folder).resolve())  # where it is now (a clone elsewhere), not where it began
        return cls(**data)


def trial_name(trial: dict) -> str:
    """``lr=0.0001__seed=3``: the grid values in name order, the seed last."""
    parts = [f"{k}={trial[k]}" for k in sorted(trial) if k != "seed"] + [f"seed={trial['seed']}"]
    return "__".join(parts)


def parse_seeds(text: str) -> list[int]:
    """``0-4`` or ``0,3,7`` (or both: ``0-2,9``)."""
    from rlcore.seeding import MAX_RUN_SEED

    seeds = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                low, high = (int(x) for x in part.split("-", 1))
                if high < low:
                    raise UserError(f"--seeds {text!r} is invalid: the range {part} runs downward; "
                                    f"write {high}-{low}")
                seeds.extend(range(low, high + 1))
            elif part:
                seeds.append(int(part))
        except ValueError:
            raise UserError(f"--seeds {text!r} is invalid: give a range (0-4) or a list (0,3,7)") from None
    if not seeds or min(seeds) < 0 or max(seeds) > MAX_RUN_SEED or len(set(seeds)) != len(seeds):
        raise UserError(f"--seeds {text!r} is invalid: allowed are distinct whole numbers from 0 to "
                        f"{MAX_RUN_SEED}")
    return seeds


# settings a grid may not vary, and why
UNSWEPT = {"init_from": "each trial's folder is named by its values, and a path cannot be part of a folder's "
                        "name; fine-tune one run with `main.py train ... --init-from`"}


def parse_grid(items: list[str], config) -> dict[str, list]:
    """``["lr=1e-4,3e-4", "world=1,2"]`` -> ``{"lr": [0.0001, 0.0003], "world": [1, 2]}``, each value
    parsed by its field's type; an unknown name is a :class:`UserError`."""
    from rlcore.hparams import field_types

    types = field_types(type(config))
    grid = {}
    for item in items:
        name, sep, values = item.partition("=")
        name = name.strip().lstrip("-").replace("-", "_")
        if not sep or not values.strip():
            raise UserError(f"--grid {item!r} is invalid: write NAME=V1,V2 (e.g. --grid lr=1e-4,3e-4)")
        if name not in types:
            raise UserError(f"--grid {item!r}: {name!r} is not a hyperparameter of {type(config).__name__}; "
                            f"`main.py train EXPERIMENT ALGO --help` lists them")
        if name in UNSWEPT:
            raise UserError(f"--grid {item!r}: a sweep cannot set {name} ({UNSWEPT[name]})")
        try:
            # tuple fields (hidden sizes) take ';' between values: --grid hidden=64,64;128,128
            sep_values = values.split(";") if isinstance(getattr(config, name), tuple) else values.split(",")
            grid[name] = [types[name](v.strip()) for v in sep_values if v.strip()]
        except argparse.ArgumentTypeError as exc:  # a bad true/false says what it allows
            raise UserError(f"--grid {item!r} is invalid: {exc}") from None
        except ValueError:  # float('abc') says "could not convert string to float"
            raise UserError(f"--grid {item!r} is invalid: {name} takes {_takes(config, name)}") from None
    return grid


def _takes(config, name: str) -> str:
    """What field ``name`` of ``config`` takes, in words, for a --grid value that is no such thing."""
    from rlcore.allowed import field_words

    f = next(f for f in dataclasses.fields(config) if f.name == name)
    kind = {"int": "whole numbers", "float": "numbers", "tuple[int, ...]": "lists of whole numbers"}
    words = field_words(f) or kind.get(str(f.type), str(f.type))
    return words + (" (values apart with ';')" if str(f.type).startswith("tuple") else "")


def check(sweep: Sweep) -> None:
    """Build every trial's config once, so a bad value stops the sweep before Ray starts."""
    from rlcore.experiment import get_experiment
    from rlcore.hparams import apply_overrides, check_no_inert

    exp = get_experiment(sweep.experiment)
    base = exp.preset(sweep.algo, sweep.preset)
    for trial in sweep.trials():
        values = {k: v for k, v in trial.items() if k != "seed"}
        check_no_inert(apply_overrides(base, {**sweep.overrides, **values}), values)


# ------------------------------------------------------------------------------------- the trial
def run_trial(trial: dict, sweep: dict, modules: dict, report) -> dict:
    """Run (or resume, or skip if finished) one trial's run folder; ``report(metrics)`` is Tune's.

    Returns the final metrics: the evaluation on unseen seeds from ``meta.json``.
    """
    from rlcore import experiment as registry

    registry.EXPERIMENT_MODULES.update(modules)  # experiments registered by the caller (tests' toys)
    sweep = Sweep(**sweep)
    run_dir = Path(sweep.folder) / trial_name(trial)
    meta_path = run_dir / "model" / "meta.json"
    meta = json.loads(meta_path.read_text()) if meta_path.is_file() else None
    if meta is not None and not _wants_evaluation(sweep, meta):  # finished before: not run again
        return final_metrics(meta, skipped=True)
    if (Path(sweep.folder) / STOP_FILE).exists():  # the sweep is stopping: a trial not begun stays so
        return {"interrupted": 1, "not_started": 1}
    from rlcore.run_lock import hold_run_folder

    log_trial(sweep, trial, "started" if meta is None else "trained but not evaluated: evaluating")
    try:
        with hold_run_folder(run_dir):  # one writer: a trial restarted while its old worker lives is refused
            (run_dir / "worker.pid").write_text(f"{os.getpid()}\n")
            result = (_train_trial(trial, sweep, run_dir, report) if meta is None
                      else final_metrics(_evaluate_trial(sweep, run_dir)))
        log_trial(sweep, trial, "stopped at a checkpoint" if result.get("interrupted") else "finished")
        return result
    except UserError as exc:  # a bad value, a diverged loss, a busy folder: a retry would fail the same way
        log_trial(sweep, trial, f"failed: {exc}")
        return {"error": str(exc), "failed": 1}
    except BaseException as exc:  # the worker's own end (Ray restarts it from the checkpoint)
        log_trial(sweep, trial, f"stopped: {type(exc).__name__}")
        raise


def _wants_evaluation(sweep: Sweep, meta: dict) -> bool:
    """A trained trial whose evaluation on unseen seeds never ran (the process ended between the two)
    and whose sweep asks for one: it is evaluated before it counts as finished, so no trained seed drops
    out of the report."""
    return not meta.get("evaluation") and sweep.final_eval_episodes != 0


def _evaluate_trial(sweep: Sweep, run_dir: Path) -> dict:
    """Evaluate a trained trial's model on unseen seeds into its meta.json; return the meta."""
    from rlcore import shipping
    from rlcore.experiment import get_experiment

    episodes = shipping.eval_episodes(get_experiment(sweep.experiment), sweep.final_eval_episodes)
    return shipping.evaluate_into_meta(run_dir / "model", episodes, replace=True)  # the trial's own model


def log_trial(sweep: Sweep, trial: dict, event: str) -> None:
    """One line in the sweep's trials.log per start and per end of a trial's attempt (with the worker's
    pid), so restarts and failures can be counted afterwards."""
    line = f"{time.strftime('%Y-%m-%dT%H:%M:%S')} {trial_name(trial)} pid {os.getpid()} {event}\n"
    with open(Path(sweep.folder) / TRIALS_LOG, "a") as log:
        log.write(line)


def _train_trial(trial: dict, sweep: Sweep, run_dir: Path, report) -> dict:
    """The trial's run in ``run_dir``, resumed where a checkpoint exists; its final metrics."""
    from rlcore import shipping
    from rlcore.run import build_spec, run_training
    from rlcore.trainers.stopping import Interrupted

    resume = (run_dir / "checkpoint.npz").is_file()
    if not resume:  # a start killed before its first checkpoint: its rows go, the run begins again
        for table in run_dir.glob("*.csv"):
            table.unlink()
    values = {k: v for k, v in trial.items() if k != "seed"}
    command = (f"python main.py sweep {sweep.experiment} {sweep.algo} --name {sweep.name} "
               f"(trial {trial_name(trial)}{', resumed' if resume else ''})")
    spec = build_spec(sweep.experiment, sweep.algo, preset=sweep.preset, seed=int(trial["seed"]),
                      overrides={**sweep.overrides, **values}, run_dir=run_dir, resume=resume,
                      wandb_mode="off", progress=False, command=command)
    spec.stop_file = Path(sweep.folder) / STOP_FILE
    last = [0.0]

    def on_progress(row: dict, table: str) -> None:
        now = time.monotonic()
        if table != "metrics" or now - last[0] >= 1.0:  # episodes at most once a second
            last[0] = now
            report({f"{table}/{k}" if table != "metrics" else k: v for k, v in row.items()
                    if isinstance(v, (int, float)) and not isinstance(v, bool)})
    try:
        model_dir = run_training(spec, on_progress)
    except Interrupted:
        return {"interrupted": 1}
    episodes = shipping.eval_episodes(spec.experiment, sweep.final_eval_episodes)
    meta = (shipping.evaluate_into_meta(model_dir, episodes, replace=True) if episodes > 0
            else json.loads((model_dir / "meta.json").read_text()))
    return final_metrics(meta)


def final_metrics(meta: dict, skipped: bool = False) -> dict:
    ev = meta.get("evaluation") or {}
    score = ev.get("success_share", ev.get("mean"))
    return {"final_score": float("nan") if score is None else float(score), "env_steps": meta["env_steps"],
            "wall_seconds": meta["wall_seconds"], "finished": 1, "skipped": int(skipped)}


def _trainable(config: dict, sweep: dict, modules: dict, threads: int):
    os.environ["TF_NUM_INTRAOP_THREADS"] = str(threads)  # TensorFlow is not loaded yet in this worker
    os.environ["TF_NUM_INTEROP_THREADS"] = "1"
    from ray import tune

    final = run_trial(config, sweep, modules, tune.report)
    tune.report(final)


# ----------------------------------------------------------------------------------------- Ray
def start_ray(address: str | None, num_cpus: int | None) -> bool:
    """Start local Ray on 127.0.0.1 (or join ``address``). Returns whether this call started it."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # never phone home
    if not address:
        loopback_only()
    import ray

    if ray.is_initialized():
        return False
    project_root = str(Path(__file__).resolve().parents[1])
    runtime_env = {"env_vars": {"PYTHONPATH": project_root, "RAY_USAGE_STATS_ENABLED": "0",
                                "TF_CPP_MIN_LOG_LEVEL": "3"}}
    if address:
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
        return True
    from rlcore.quiet import filtered_stderr
    with filtered_stderr(), ignoring_stop_signals():
        # "local": a new instance of our own, even where RAY_ADDRESS is set or a `ray start` cluster runs
        # (without it Ray joins that, and refuses the CPU count: "When connecting to an existing cluster...")
        ray.init(address="local", num_cpus=num_cpus or os.cpu_count(), include_dashboard=False,
                 _node_ip_address="127.0.0.1", runtime_env=runtime_env, log_to_driver=False,
                 configure_logging=False)
    return True


def loopback_only() -> None:
    """Keep every socket of a local Ray on 127.0.0.1 (never call it when joining a cluster).

    Seen with Ray 2.60: without ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0`` its services also listen on
    the machine's network address. Ray's services read the variable when they start (they inherit it);
    this process read it when it first imported Ray, which may have happened already (the sweep
    command's check for its extra imports ``ray.tune``), so the flag it derived is set here as well."""
    os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
    constants = sys.modules.get("ray._private.ray_constants")
    if constants is not None:
        constants.ENABLE_RAY_CLUSTER = False


def quiet_tune() -> None:
    """No "may be a performance bottleneck" lines from Tune in the sweep's console: a trial reports at
    most once a second, and a slow report is Tune's own bookkeeping (seen at 0.5 s on this 2-core CPU).
    Tune reads ``TUNE_WARN_THRESHOLD_S`` when ``ray.tune`` is first imported, which the check for the
    sweep extra has done by now, so the threshold it derived is set as well."""
    os.environ.setdefault("TUNE_WARN_THRESHOLD_S", "600")
    util = sys.modules.get("ray.tune.utils.util")
    if util is not None:
        util.warn_if_slow.DEFAULT_THRESHOLD = float(os.environ["TUNE_WARN_THRESHOLD_S"])


@contextlib.contextmanager
def ignoring_stop_signals():
    """The stop signals (SIGINT, SIGTERM, SIGHUP) blocked while local Ray starts its services, which
    inherit the mask: a signal to the whole process group (Ctrl-C, timeout, a scheduler, a terminal
    that closes) then reaches only the driver,
    which stops every trial at a checkpoint and shuts Ray down, instead of killing Ray's services under
    the trials. (Ray blocks SIGINT in its services itself; SIGTERM ended them at once.)"""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, set(STOP_SIGNALS))
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


def run_sweep(sweep: Sweep, address: str | None = None, num_cpus: int | None = None) -> list[dict]:
    """Run every unfinished trial of ``sweep`` on Ray Tune; return one result row per trial."""
    from rlcore import experiment as registry
    from rlcore.extras import require

    require("ray.tune", "A sweep")  # the sweep extra, or one line saying so (before any folder)
    check(sweep)
    folder = writable_folder(sweep.folder, "sweep folder")
    sweep.save()
    (folder / STOP_FILE).unlink(missing_ok=True)
    os.environ["TUNE_DISABLE_SIGINT_HANDLER"] = "1"  # our handler: stop trials at a checkpoint
    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")
    quiet_tune()
    started = start_ray(address, num_cpus)
    from ray import tune

    def on_stop_signal(signum, frame):  # Ctrl-C, SIGTERM, SIGHUP: a killed driver would orphan Ray's workers
        (folder / STOP_FILE).touch()
        announce_stop(signum, "every running trial stops at its next checkpoint; --resume continues the sweep",
                      write=lambda text: print(text, file=sys.stderr))
    previous = {number: signal.signal(number, on_stop_signal) for number in STOP_SIGNALS}
    try:
        trainable = tune.with_parameters(_trainable, sweep=asdict(sweep),
                                         modules=dict(registry.EXPERIMENT_MODULES),
                                         threads=max(1, int(sweep.cpus_per_run)))
        space = {"seed": tune.grid_search(sweep.seeds),
                 **{name: tune.grid_search(values) for name, values in sweep.grid.items()}}
        tuner = tune.Tuner(
            tune.with_resources(trainable, {"cpu": sweep.cpus_per_run}), param_space=space,
            # reuse_actors: a worker loads TensorFlow once, not once per trial (4 toy trials on 2
            # CPUs: 25.6 s against 60.8 s here, measured beside a training)
            tune_config=tune.TuneConfig(max_concurrent_trials=sweep.max_concurrent or None, reuse_actors=True),
            run_config=tune.RunConfig(name="tune", storage_path=str((folder / "_tune").resolve()), verbose=0,
                                      failure_config=tune.FailureConfig(max_failures=3)))
        grid = tuner.fit()
    finally:
        for number, old in previous.items():
            signal.signal(number, old)
        if started:
            import ray
            ray.shutdown()
    rows = []
    for result in grid:
        metrics = result.metrics or {}
        error = str(result.error).splitlines()[0] if result.error else metrics.get("error")
        rows.append({"trial": trial_name({k: v for k, v in result.config.items()}), **metrics, "error": error})
    return rows
