"""A sweep on Ray Tune: every unfinished trial of it (:mod:`rlcore.sweeps.trial`), on local Ray or a cluster.

Ctrl-C or SIGTERM writes ``sweeps/<name>/STOP``: every running trial stops at its next safe point with
a checkpoint, and the sweep ends (then Ray is shut down; a driver killed outright would leave Ray's
workers running). Local Ray is started here with a fixed CPU count, no dashboard and every service on
127.0.0.1; ``address`` joins an existing cluster instead.
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
from dataclasses import asdict
from pathlib import Path

from rlcore.files.atomic import writable_folder
from rlcore.sweeps.sweep import STOP_FILE, Sweep, check, trial_name
from rlcore.sweeps.trial import run_trial
from rlcore.training.stopping import STOP_SIGNALS, announce_stop


def _trainable(config: dict, sweep: dict, modules: dict, threads: int):
    os.environ["TF_NUM_INTRAOP_THREADS"] = str(threads)  # TensorFlow is not loaded yet in this worker
    os.environ["TF_NUM_INTEROP_THREADS"] = "1"
    from ray import tune

    final = run_trial(config, sweep, modules, tune.report)
    tune.report(final)


def start_ray(address: str | None, num_cpus: int | None) -> bool:
    """Start local Ray on 127.0.0.1 (or join ``address``). Returns whether this call started it."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # never phone home
    if not address:
        loopback_only()
    import ray

    if ray.is_initialized():
        return False
    project_root = str(Path(__file__).resolve().parents[2])
    runtime_env = {"env_vars": {"PYTHONPATH": project_root, "RAY_USAGE_STATS_ENABLED": "0",
                                "TF_CPP_MIN_LOG_LEVEL": "3"}}
    if address:
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
        return True
    from rlcore.host.quiet import filtered_stderr
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
    from rlcore.environments import registry
    from rlcore.host.extras import require

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
