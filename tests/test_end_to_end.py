"""The two trainers that otherwise meet their real envs only in multi-hour runs, end to end on the real
components: Mario PPO on the NES emulator through the process pool (restarts on), killed with -9 and
resumed; Minitaur SAC on pybullet past learning_starts, stopped and resumed. Each through the command
line; in a process of its own where the test kills it, else in this one (one TensorFlow start-up)."""
import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from rlcore.files.checkpoint import read_checkpoint_state
from tests.test_cli import run  # the command line in this process

ROOT = Path(__file__).resolve().parents[1]
QUICK = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


def rows(path: Path) -> list[dict]:
    if not path.is_file():
        return []
    with path.open() as f:
        return list(csv.DictReader(f))


def route_keys(checkpoint: Path) -> set[str]:
    with np.load(checkpoint) as data:
        return {name for name in data.files if name.startswith("array/env/")}


def test_mario_ppo_through_the_process_pool_survives_kill_9_and_resumes(tmp_path, capsys):
    run_dir = tmp_path / "mario"
    argv = ["train", "mario_ppo", "ppo", "--preset", "levels", "--num-envs", "2", "--vec", "processes",
            "--n-steps", "64", "--epochs", "1", "--minibatch", "64", "--checkpoint-rollouts", "2",
            "--restart-every", "60", "--run-dir", str(run_dir), *QUICK]
    proc = subprocess.Popen([sys.executable, "main.py", *argv, "--steps", "100000"], cwd=ROOT,
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 240
    while len(rows(run_dir / "rollouts.csv")) < 5:  # a checkpoint at rollout 4, rows past it
        assert proc.poll() is None, proc.stderr.read().decode()[-2000:]
        assert time.monotonic() < deadline, "no rollouts in time"
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)  # a crash: no handler runs, the workers go with it
    proc.wait()
    proc.stderr.close()
    state = read_checkpoint_state(run_dir / "checkpoint.npz")
    assert state["rollouts"] % 2 == 0 and state["rollouts"] >= 4
    routes = route_keys(run_dir / "checkpoint.npz")
    assert routes, "the restart points' routes are not in the checkpoint"
    logged = [int(r["rollout"]) for r in rows(run_dir / "rollouts.csv")]
    assert logged[-1] > state["rollouts"]  # rows past the checkpoint, which the resume drops

    budget = state["env_steps"] + 2 * 128
    assert run(capsys, "train", "mario_ppo", "ppo", "--resume", str(run_dir), "--steps", str(budget), *QUICK)[0] == 0
    after = [int(r["rollout"]) for r in rows(run_dir / "rollouts.csv")]
    assert after == list(range(1, state["rollouts"] + 3))  # dropped past the checkpoint, then two more
    steps = [int(r["env_steps"]) for r in rows(run_dir / "rollouts.csv")]
    assert steps[-1] == budget and np.all(np.diff(steps) == 128)
    final = read_checkpoint_state(run_dir / "checkpoint.npz")
    assert final["rollouts"] == state["rollouts"] + 2
    from rlcore.host.cpu import cpu_description

    assert final["command_starts"][-1] == {"env_steps": state["env_steps"], "episodes": len(state["returns"]),
                                           "wall_seconds": round(float(state["wall_seconds"]), 1),
                                           "cpu": cpu_description(), "rollouts": state["rollouts"],
                                           "changed": {"max_env_steps": [100000, budget]}}  # what the resume changed
    # the resumed pool got the routes back and kept them (the envs replay them from the level's start)
    assert {name.split("/")[3] for name in route_keys(run_dir / "checkpoint.npz")} >= \
        {name.split("/")[3] for name in routes}


def test_minitaur_sac_on_pybullet_learns_past_learning_starts_and_resumes(tmp_path, capsys):
    run_dir = tmp_path / "minitaur"
    # small, and one gradient step per compiled call: the preset's four took 31 s of CPU for the test against
    # 16 s, most of it compiling them in each of the two runs (stacked updates: tests/rlcore/algorithms/test_sac.py)
    small = ["--max-episode-steps", "50", "--learning-starts", "100", "--batch-size", "32", "--buffer-size", "5000",
             "--updates-per-call", "1", "--checkpoint-every", "1"]
    assert run(capsys, "train", "minitaur", "sac", *small, "--steps", "200", "--run-dir", str(run_dir), *QUICK)[0] == 0
    metrics = rows(run_dir / "metrics.csv")
    learned = [r for r in metrics if int(r["env_steps"]) > 100]
    assert learned and all(np.isfinite(float(r["critic_loss"])) for r in learned), metrics[-1]
    state = read_checkpoint_state(run_dir / "checkpoint.npz")
    assert state["env_steps"] >= 200 and (run_dir / "replay.npz").is_file()
    assert run(capsys, "train", "minitaur", "sac", "--resume", str(run_dir), "--steps", "300", *QUICK)[0] == 0
    final = read_checkpoint_state(run_dir / "checkpoint.npz")
    assert final["env_steps"] >= 300 and len(final["returns"]) > len(state["returns"])
    assert final["commands"][-1].startswith("python main.py train minitaur sac --resume")
    steps = [int(r["env_steps"]) for r in rows(run_dir / "metrics.csv")]
    assert steps == sorted(steps) and steps[-1] == final["env_steps"]
