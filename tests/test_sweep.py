"""Sweeps on a local Ray (2 CPUs, 127.0.0.1, one instance for this module): trials run to the end,
survive a SIGKILL of their worker, stop at a checkpoint on Ctrl-C, resume without re-running
finished trials, and leave no Ray process behind; the report of a finished sweep against its run
folders. The tests that need no Ray of this module's own are in tests/test_sweep_without_ray.py."""
import json
import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from rlcore.environments import registry
from rlcore.files.checkpoint import read_checkpoint_state
from rlcore.records.report import load_runs, summarize
from rlcore.sweeps.on_ray import run_sweep, start_ray
from rlcore.sweeps.sweep import STOP_FILE, Sweep
from tests.processes import alive, listening, outside_loopback, own_ray_processes

ROOT = Path(__file__).resolve().parents[1]
BUDGET = {"max_episodes": 40, "stop_score": 99.0, "checkpoint_every": 10}


# Ray processes that were running before these tests started theirs (a developer's own sweep, say):
# the tests look at their own Ray only


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray of this module's own, started while RAY_ADDRESS names a cluster (as on a machine where
    the user works with one): a sweep without --address still starts its own."""
    registry.EXPERIMENT_MODULES["toy"] = "tests.toy"  # trials get the registry from the driver
    before = os.environ.get("RAY_ADDRESS")
    os.environ["RAY_ADDRESS"] = "127.0.0.1:1"  # nothing listens there
    try:
        start_ray(None, 2)
    finally:
        if before is None:
            del os.environ["RAY_ADDRESS"]
        else:
            os.environ["RAY_ADDRESS"] = before
    yield
    import ray
    ray.shutdown()
    registry.EXPERIMENT_MODULES.pop("toy", None)


def _sweep(tmp_path, name, seeds=(0, 1), **budget):
    return Sweep("toy", "dqn", name, str(tmp_path / name), list(seeds), {}, None, {**BUDGET, **budget},
                 1.0, 0, 5)


def _ray_sockets():
    """The sockets this module's Ray listens on."""
    return listening({p.pid for p in own_ray_processes()})


def _wait_for(path, timeout=120):
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.02)


def test_local_ray_listens_on_loopback_only(local_ray):
    sockets = _ray_sockets()
    assert sockets, "no Ray service found listening"
    assert not outside_loopback(sockets), sockets


def test_a_two_seed_sweep_runs_to_the_end_and_its_report_matches_the_run_folders(local_ray, tmp_path):
    """On a Gymnasium id, which is not one of the package's experiments: the trials build the env from
    it (the other tests sweep a toy experiment that the driver registers)."""
    sweep = Sweep("CartPole-v1", "dqn", "two", str(tmp_path / "two"), [0, 1], {}, None,
                  {"max_episodes": 5, "checkpoint_every": 5}, 1.0, 0, 5)
    rows = run_sweep(sweep)
    assert sorted(r["trial"] for r in rows) == ["seed=0", "seed=1"]
    assert all(r["error"] is None and r["finished"] == 1 for r in rows), rows
    metas = [json.loads((tmp_path / "two" / t / "model" / "meta.json").read_text()) for t in ("seed=0", "seed=1")]
    assert [m["experiment"] for m in metas] == ["CartPole-v1"] * 2 and [m["seed"] for m in metas] == [0, 1]
    assert all(m["evaluation"]["episodes"] == 5 for m in metas)
    log = (tmp_path / "two" / "trials.log").read_text()
    assert log.count(" started\n") == 2 and log.count(" finished\n") == 2, log
    scores = np.array([[m["evaluation"]["mean"]] for m in metas])
    result = summarize([tmp_path / "two"], reps=500)
    (mean, median, iqm) = (result["sweeps"][0]["aggregates"][k][0] for k in ("mean", "median", "iqm"))
    assert mean == pytest.approx(scores.mean()) and median == pytest.approx(np.median(scores))
    assert iqm == pytest.approx(scores.mean())  # with 2 runs nothing is trimmed
    assert [r["env_steps"] for r in load_runs(tmp_path / "two")] == [m["env_steps"] for m in metas]


def test_a_killed_trial_resumes_from_its_checkpoint(local_ray, tmp_path):
    sweep = _sweep(tmp_path, "kill", seeds=(0,), max_episodes=100, checkpoint_every=5)
    trial = tmp_path / "kill" / "seed=0"
    killed = {}

    def killer():
        _wait_for(trial / "checkpoint.npz")
        _wait_for(trial / "worker.pid")
        killed["pid"] = int((trial / "worker.pid").read_text())
        os.kill(killed["pid"], signal.SIGKILL)
    thread = threading.Thread(target=killer, daemon=True)
    thread.start()
    rows = run_sweep(sweep)
    thread.join(5)
    assert killed and rows[0]["error"] is None, rows
    meta = json.loads((trial / "model" / "meta.json").read_text())
    assert len(meta["commands"]) == 2 and meta["commands"][1].endswith("resumed)"), meta["commands"]
    assert int((trial / "worker.pid").read_text()) != killed["pid"]
    episodes = [int(line.split(",")[0]) for line in (trial / "metrics.csv").read_text().splitlines()[1:]]
    assert episodes == list(range(1, len(episodes) + 1)) and len(episodes) >= 100


def test_ctrl_c_stops_at_a_checkpoint_and_resume_skips_finished_trials(local_ray, tmp_path):
    """Ctrl-C (SIGINT) to the sweep's driver; SIGTERM takes the same handler, and the test of a SIGTERM
    to the whole process group below sends it to a sweep started from the command line."""
    signal_name = "SIGINT"
    sweep = _sweep(tmp_path, "stop", seeds=(0,), max_episodes=4000, checkpoint_every=5)
    trial = tmp_path / "stop" / "seed=0"

    def ctrl_c():
        _wait_for(trial / "checkpoint.npz")
        os.kill(os.getpid(), getattr(signal, signal_name))  # the sweep's handler writes STOP
    threading.Thread(target=ctrl_c, daemon=True).start()
    rows = run_sweep(sweep)
    assert rows[0].get("interrupted") == 1, rows
    assert (tmp_path / "stop" / STOP_FILE).exists() and not (trial / "model").exists()
    stopped_at = read_checkpoint_state(trial / "checkpoint.npz")["env_steps"]
    # --resume (budget lowered so the run ends at once): the trial continues from its checkpoint
    resumed = Sweep.load(tmp_path / "stop")
    resumed.overrides = {**resumed.overrides, "max_episodes": 1}
    rows = run_sweep(resumed)
    meta = json.loads((trial / "model" / "meta.json").read_text())
    assert meta["env_steps"] >= stopped_at and rows[0]["skipped"] == 0
    finished_mtime = (trial / "model" / "meta.json").stat().st_mtime
    rows = run_sweep(Sweep.load(tmp_path / "stop"))
    assert rows[0]["skipped"] == 1
    assert (trial / "model" / "meta.json").stat().st_mtime == finished_mtime


def test_a_stopped_sweep_does_not_begin_the_trials_still_waiting(local_ray, tmp_path):
    """One trial at a time, stopped during the first: the second is not begun (no run folder, no
    step-0 checkpoint), and a resume starts it."""
    sweep = Sweep("toy", "dqn", "queue", str(tmp_path / "queue"), [0, 1], {}, None,
                  {**BUDGET, "max_episodes": 4000, "checkpoint_every": 5}, 1.0, 1, 5)
    first = tmp_path / "queue" / "seed=0"

    def stop():
        _wait_for(first / "checkpoint.npz")
        (tmp_path / "queue" / STOP_FILE).touch()  # as the driver's signal handler does
    threading.Thread(target=stop, daemon=True).start()
    rows = {row["trial"]: row for row in run_sweep(sweep)}
    assert rows["seed=0"].get("interrupted") == 1 and rows["seed=1"].get("not_started") == 1, rows
    assert not (tmp_path / "queue" / "seed=1").exists()


def test_a_trial_that_fails_with_a_user_error_is_reported_once_not_retried(local_ray, tmp_path):
    """Its run folder is written by another process (this one): the trial is refused, and a retry
    would be refused the same way, so there is none."""
    from rlcore.files.run_lock import hold_run_folder

    sweep = _sweep(tmp_path, "busy", seeds=(0,))
    with hold_run_folder(tmp_path / "busy" / "seed=0"):
        rows = run_sweep(sweep)
    assert "is being written by process" in rows[0]["error"], rows
    log = (tmp_path / "busy" / "trials.log").read_text().splitlines()
    assert [line.split()[-1] if "started" in line else line.split()[4] for line in log] == ["started", "failed:"]


def test_no_ray_process_is_left_behind(local_ray):
    """Every Ray process this module's Ray started is gone after shutdown (followed by process, so a Ray
    that another test worker's sweep starts meanwhile does not count)."""
    import ray
    ours = own_ray_processes()
    assert ours, "this module's Ray has no process to follow"
    ray.shutdown()
    deadline = time.monotonic() + 20
    while alive(ours) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not alive(ours), alive(ours)
