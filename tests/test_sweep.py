"""Sweeps on a local Ray (2 CPUs, 127.0.0.1, one instance for this module): trials run to the end,
survive a SIGKILL of their worker, stop at a checkpoint on Ctrl-C, resume without re-running
finished trials; the report's statistics against direct computations."""
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from rlcore import experiment as registry
from rlcore.checkpoint import read_checkpoint_state
from rlcore.report import aggregates, load_runs, probability_of_improvement, stratified_bootstrap_ci, summarize
from rlcore.sweep import STOP_FILE, Sweep, parse_grid, parse_seeds, run_sweep, start_ray
from tests.test_cli import run

ROOT = Path(__file__).resolve().parents[1]
BUDGET = {"max_episodes": 40, "stop_score": 99.0, "checkpoint_every": 10}


LOOPBACK = ("127.0.0.1", "[::ffff:127.0.0.1]", "[::1]")


def _ray_pids() -> set[str]:
    out = subprocess.run(["pgrep", "-f", "raylet|gcs_server|ray::"], capture_output=True, text=True).stdout
    return set(out.split())


# Ray processes that were running before these tests started theirs (a developer's own sweep, say):
# the tests look at their own Ray only
OTHERS_RAY: set[str] = set()


@pytest.fixture(scope="module")
def local_ray():
    registry.EXPERIMENT_MODULES["toy"] = "tests.toy"  # trials get the registry from the driver
    OTHERS_RAY.update(_ray_pids())
    start_ray(None, 2)
    yield
    import ray
    ray.shutdown()
    registry.EXPERIMENT_MODULES.pop("toy", None)


def _sweep(tmp_path, name, seeds=(0, 1), **budget):
    return Sweep("toy", "dqn", name, str(tmp_path / name), list(seeds), {}, None, {**BUDGET, **budget},
                 1.0, 0, 5)


def _ray_sockets():
    out = subprocess.run(["ss", "-tnlpH"], capture_output=True, text=True).stdout
    return [line for line in out.splitlines() if any(p in line for p in ("raylet", "gcs_server", "ray::"))
            and not any(f"pid={pid}," in line for pid in OTHERS_RAY)]


def _wait_for(path, timeout=120):
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.02)


def test_local_ray_listens_on_loopback_only(local_ray):
    sockets = _ray_sockets()
    assert sockets, "no Ray service found listening"
    outside = [s for s in sockets if s.split()[3].rsplit(":", 1)[0] not in LOOPBACK]
    assert not outside, outside


def test_a_two_seed_sweep_runs_to_the_end_and_its_report_matches_the_run_folders(local_ray, tmp_path):
    sweep = _sweep(tmp_path, "two")
    rows = run_sweep(sweep)
    assert sorted(r["trial"] for r in rows) == ["seed=0", "seed=1"]
    assert all(r["error"] is None and r["finished"] == 1 for r in rows), rows
    metas = [json.loads((tmp_path / "two" / t / "model" / "meta.json").read_text()) for t in ("seed=0", "seed=1")]
    assert [m["seed"] for m in metas] == [0, 1] and all(m["evaluation"]["episodes"] == 5 for m in metas)
    scores = np.array([[m["evaluation"]["mean"]] for m in metas])
    result = summarize([tmp_path / "two"], reps=500)
    (mean, median, iqm) = (result["sweeps"][0]["aggregates"][k][0] for k in ("mean", "median", "iqm"))
    assert mean == pytest.approx(scores.mean()) and median == pytest.approx(np.median(scores))
    assert iqm == pytest.approx(scores.mean())  # with 2 runs nothing is trimmed
    assert [r["env_steps"] for r in load_runs(tmp_path / "two")] == [m["env_steps"] for m in metas]


def test_a_sweep_and_its_report_work_on_a_gymnasium_id(local_ray, tmp_path):
    """Not one of the package's experiments: the trials build the env from its Gymnasium id."""
    sweep = Sweep("CartPole-v1", "dqn", "gym", str(tmp_path / "gym"), [0, 1], {}, None,
                  {"max_episodes": 5, "checkpoint_every": 5}, 1.0, 0, 2)
    rows = run_sweep(sweep)
    assert all(r["error"] is None and r["finished"] == 1 for r in rows), rows
    metas = [json.loads((tmp_path / "gym" / t / "model" / "meta.json").read_text()) for t in ("seed=0", "seed=1")]
    assert [m["experiment"] for m in metas] == ["CartPole-v1"] * 2 and [m["seed"] for m in metas] == [0, 1]
    result = summarize([tmp_path / "gym"], reps=200)
    mean = result["sweeps"][0]["aggregates"]["mean"][0]
    assert mean == pytest.approx(np.mean([m["evaluation"]["mean"] for m in metas]))


def test_a_killed_trial_resumes_from_its_checkpoint(local_ray, tmp_path):
    sweep = _sweep(tmp_path, "kill", seeds=(0,), max_episodes=400, checkpoint_every=5)
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
    assert episodes == list(range(1, len(episodes) + 1)) and len(episodes) >= 400


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
    from rlcore.run_lock import hold_run_folder

    sweep = _sweep(tmp_path, "busy", seeds=(0,))
    with hold_run_folder(tmp_path / "busy" / "seed=0"):
        rows = run_sweep(sweep)
    assert "is being written by process" in rows[0]["error"], rows
    log = (tmp_path / "busy" / "trials.log").read_text().splitlines()
    assert [line.split()[-1] if "started" in line else line.split()[4] for line in log] == ["started", "failed:"]


def test_no_ray_process_is_left_behind(local_ray):
    import ray
    ray.shutdown()
    deadline = time.monotonic() + 20
    while _ray_sockets() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _ray_sockets()
    left = _ray_pids() - OTHERS_RAY
    assert not left, left


# ------------------------------------------------------------------------- without Ray
def test_bootstrap_ci_on_known_answers():
    constant = np.full((8, 1), 3.0)
    point, ci = stratified_bootstrap_ci(aggregates, constant, reps=200)
    np.testing.assert_allclose(point, 3.0)
    np.testing.assert_allclose(ci, 3.0)
    scores = np.arange(1.0, 101.0)[:, None]
    point, ci = stratified_bootstrap_ci(aggregates, scores, reps=2000)
    np.testing.assert_allclose(point, [50.5, 50.5, 50.5])
    # the mean of 1..100 has standard error 29.01 / 10: the 95% interval is about 50.5 +- 5.7
    assert ci[0][0] == pytest.approx(50.5 - 5.7, abs=0.8) and ci[1][0] == pytest.approx(50.5 + 5.7, abs=0.8)
    # skewed scores, as a 5-seed sweep gives: the median is the middle run, not the mean again
    skewed = np.array([[500.0], [137.0], [500.0], [487.0], [278.0]])
    # the IQM of 5 runs drops one at each end (scipy's trim_mean, as rliable)
    np.testing.assert_allclose(aggregates(skewed), [380.4, 487.0, (278 + 487 + 500) / 3])
    assert probability_of_improvement(scores + 1000, scores) == 1.0
    assert probability_of_improvement(scores, scores) == pytest.approx(0.5)


def test_a_sweep_moved_to_another_folder_resumes_where_it_now_is(tmp_path):
    """A sweep kept in git (long_runs/sweeps/) resumes from a clone in another place."""
    first = _sweep(tmp_path, "here")
    Path(first.folder).mkdir()
    first.save()
    (tmp_path / "here").rename(tmp_path / "there")
    assert Sweep.load(tmp_path / "there").folder == str((tmp_path / "there").resolve())


def test_seeds_and_grid_parsing():
    from rlcore.configs import DQNConfig

    assert parse_seeds("0-4") == [0, 1, 2, 3, 4] and parse_seeds("0,3,7") == [0, 3, 7]
    assert parse_grid(["lr=1e-4,3e-4", "hidden=64,64;128"], DQNConfig()) == {
        "lr": [1e-4, 3e-4], "hidden": [(64, 64), (128,)]}


@pytest.mark.parametrize("argv, message", [
    (["sweep", "lunar_lander", "dqn", "--grid", "learning_rate=1e-3"], "'learning_rate' is not a hyperparameter"),
    (["sweep", "lunar_lander", "dqn", "--grid", "gamma=0.9,1.5"], "--gamma 1.5 is invalid"),
    (["sweep", "lunar_lander", "dqn", "--grid", "lr=fast"], "--grid 'lr=fast' is invalid"),
    (["sweep", "lunar_lander", "dqn", "--grid", "keep_best=maybe"], "--grid 'keep_best=maybe' is invalid: 'maybe'"),
    (["sweep", "lunar_lander", "dqn", "--seeds", "4-x"], "--seeds '4-x' is invalid"),
    (["sweep", "lunar_lander", "dqn", "--seeds", "4-0"], "the range 4-0 runs downward; write 0-4"),
    (["report", "/nonexistent/sweep"], "no sweep folder /nonexistent/sweep"),
    (["sweep", "lunar_lander", "dqn", "--name", "../x"], "argument --name: '../x' is invalid: give a folder name"),
    (["sweep", "lunar_lander", "dqn", "--name", ".."], "argument --name: '..' is invalid"),
])
def test_bad_sweep_values_are_one_line_and_exit_2(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    named = argv[0] == "sweep" and "--name" not in argv
    code, out, err = run(capsys, *argv, "--name", "x") if named else run(capsys, *argv)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "sweeps").exists() and not (tmp_path / "x").exists()


def test_report_groups_a_grid_sweep_by_setting(tmp_path):
    from rlcore.report import markdown

    # skewed scores, so mean, median and IQM differ and a mix-up of their names would show
    for lr, scores in (("0.001", (137.0, 278.0, 487.0, 500.0, 500.0)), ("0.01", (600.0, 601.0, 650.0))):
        for seed, score in enumerate(scores):
            model = tmp_path / "grid" / f"lr={lr}__seed={seed}" / "model"
            model.mkdir(parents=True)
            (model / "meta.json").write_text(json.dumps({
                "seed": seed, "env_steps": 100, "wall_seconds": 1.0,
                "evaluation": {"episodes": 5, "mean": score}}))
    result = summarize([tmp_path / "grid"], reps=200)
    labels = [g["label"] for g in result["sweeps"]]
    assert labels == ["grid [lr=0.001]", "grid [lr=0.01]"]
    first = result["sweeps"][0]["aggregates"]
    assert [first[k][0] for k in ("mean", "median", "iqm")] == pytest.approx([380.4, 487.0, 1265 / 3])
    assert all(lo <= point <= hi and lo < hi for point, lo, hi in first.values())
    assert result["sweeps"][1]["aggregates"]["median"][0] == 601.0
    assert result["probability_of_improvement"][0] == 0.0  # every lr=0.001 run below every lr=0.01 run
    text = markdown(result)
    assert "P(grid [lr=0.001] > grid [lr=0.01]) = 0.000" in text
    lo, hi = first["median"][1:]
    assert f"| median | 487.000 | [{lo:.3f}, {hi:.3f}] |" in text and "| mean | 380.400 |" in text


def test_report_keep_copies_what_the_report_reads_and_nothing_else(tmp_path, capsys):
    sweep, kept = tmp_path / "sweeps" / "toy__dqn", tmp_path / "results" / "toy__dqn"
    (sweep).mkdir(parents=True)
    (sweep / "sweep.json").write_text(json.dumps({"experiment": "toy"}))
    for seed, score in enumerate((100.0, 250.0, 300.0)):
        run_dir = sweep / f"seed={seed}"
        (run_dir / "model").mkdir(parents=True)
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 1000 * (seed + 1), "wall_seconds": 2.0, "evaluation": {"episodes": 5, "mean": score}}))
        (run_dir / "metrics.csv").write_text("episode,env_steps,av_latest_points\n1,10,1.0\n2,1000,%s\n" % score)
        (run_dir / "evals.csv").write_text("env_steps,mean\n1000,%s\n" % score)
        (run_dir / "checkpoint.npz").write_bytes(b"large")
    code, out, err = run(capsys, "report", str(sweep), "--keep", str(kept), "--reps", "200")
    assert code == 0, err
    copied = sorted(str(p.relative_to(kept)) for p in kept.rglob("*") if p.is_file())
    per_run = ["evals.csv", "metrics.csv", "model/meta.json"]
    assert copied == sorted(["report.md", "report_curves.png", "sweep.json"]
                            + [f"seed={s}/{name}" for s in range(3) for name in per_run])
    assert not (sweep / "report.md").exists()  # the report is written where the copies are
    again = summarize([kept], reps=200)
    assert again["sweeps"][0]["aggregates"]["mean"][0] == pytest.approx(650.0 / 3)
    assert [r["env_steps"] for r in load_runs(kept)] == [1000, 2000, 3000]
    code, _, err = run(capsys, "report", str(sweep), str(kept), "--keep", str(tmp_path / "other"))
    assert code == 2 and "--keep copies one sweep" in err and not (tmp_path / "other").exists()


def test_report_refuses_a_folder_that_mixes_experiments_or_algorithms(tmp_path, capsys):
    """`report runs/` over a user's runs of unlike tasks would average unlike scores: one line, exit 2."""
    for name, experiment, algo, score in (("a", "lunar_lander", "dqn", 200.0), ("b", "cartpole", "a2c", 500.0),
                                          ("c", "lunar_lander", "dqn", 250.0)):
        (tmp_path / "runs" / name / "model").mkdir(parents=True)
        (tmp_path / "runs" / name / "model" / "meta.json").write_text(json.dumps({
            "experiment": experiment, "algo": algo, "seed": 0, "env_steps": 10, "wall_seconds": 1.0,
            "evaluation": {"episodes": 5, "mean": score}}))
    code, out, err = run(capsys, "report", str(tmp_path / "runs"))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "holds runs of cartpole a2c and lunar_lander dqn" in err
    assert not (tmp_path / "runs" / "report.md").exists()
    (tmp_path / "runs" / "b" / "model" / "meta.json").unlink()  # the rest: one experiment and algorithm
    assert [r["score"] for r in load_runs(tmp_path / "runs")] == [200.0, 250.0]


def test_a_trial_killed_before_its_first_checkpoint_starts_over_without_its_old_rows(tmp_path):
    """No checkpoint means the trial starts from episode 1 again: rows logged by the killed start are
    not kept under the new run's (they would repeat episode numbers and mix two runs' curves)."""
    import dataclasses

    from rlcore.sweep import run_trial
    sweep = _sweep(tmp_path, "early", seeds=(0,))
    trial = tmp_path / "early" / "seed=0"
    trial.mkdir(parents=True)
    header = "episode,total_points,av_latest_points,target_ave_scores,env_steps,wall_seconds\n"
    (trial / "metrics.csv").write_text(header + "1,-12345.0,-12345.0,,7,0.1\n2,-12345.0,-12345.0,,9,0.2\n")
    run_trial({"seed": 0}, dataclasses.asdict(sweep), {"toy": "tests.toy"}, lambda metrics: None)
    rows = (trial / "metrics.csv").read_text().splitlines()[1:]
    episodes = [int(line.split(",")[0]) for line in rows]
    assert episodes == list(range(1, len(episodes) + 1)) and len(episodes) >= 2
    assert not any("-12345" in line for line in rows)


def test_sigterm_to_the_sweeps_process_group_stops_its_trials_at_a_checkpoint(tmp_path):
    """As `timeout` or a scheduler sends it: to the driver and every process it started. Ray's services
    must not die under the trials (they started with the signal blocked); the driver stops the trials."""
    from tests.test_stop_signals import group_is_gone

    folder = tmp_path / "group"
    proc = subprocess.Popen([sys.executable, "main.py", "sweep", "cartpole", "dqn", "--seeds", "0",
                             "--episodes", "5000", "--dir", str(tmp_path), "--name", "group", "--num-cpus", "1"],
                            cwd=ROOT, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    _wait_for(folder / "seed=0" / "checkpoint.npz", timeout=240)
    # the command imports ray.tune (its check for the sweep extra) before it starts Ray: still loopback only
    group = set(subprocess.run(["pgrep", "-g", str(proc.pid)], capture_output=True, text=True).stdout.split())
    sockets = [s for s in subprocess.run(["ss", "-tnlpH"], capture_output=True, text=True).stdout.splitlines()
               if any(f"pid={pid}," in s for pid in group)]
    outside = [s for s in sockets if s.split()[3].rsplit(":", 1)[0] not in LOOPBACK]
    os.killpg(proc.pid, signal.SIGTERM)
    out, err = proc.communicate(timeout=180)
    assert proc.returncode == 130, err[-2000:]
    assert sockets and not outside, outside or "no socket of the sweep's Ray found"
    assert "seed=0: stopped at a checkpoint" in out, out
    assert group_is_gone(proc.pid, timeout=30)
    log = (folder / "trials.log").read_text()
    assert log.count("started") == 1 and "failed" not in log
