"""Every stop signal keeps the work: SIGINT or SIGTERM to a run's whole process group (Ctrl-C in a
terminal, GNU timeout, a job scheduler) ends it at a safe point with a checkpoint, exit status 130,
no process left behind, and a resume that continues from there. Real signals, real process pool,
Mario's real emulator."""
import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rlcore.files.checkpoint import read_checkpoint_state

ROOT = Path(__file__).resolve().parents[1]
# a short Mario run over a pool of 2 env processes: 64 transitions per rollout, one quick update
MARIO = ["train", "mario_ppo", "ppo", "--num-envs", "2", "--vec", "processes", "--n-steps", "32",
         "--epochs", "1", "--minibatch", "32", "--checkpoint-rollouts", "1000", "--wandb", "off",
         "--no-progress", "--final-eval-episodes", "0"]


def start(argv: list[str]) -> subprocess.Popen:
    """main.py in a process group of its own, as a terminal or a scheduler starts a job."""
    return subprocess.Popen([sys.executable, "main.py", *argv], cwd=ROOT, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def rollouts_logged(run_dir: Path) -> list[int]:
    table = run_dir / "rollouts.csv"
    if not table.is_file():
        return []
    with table.open() as f:
        return [int(row["rollout"]) for row in csv.DictReader(f)]


def wait_for_rollouts(proc: subprocess.Popen, run_dir: Path, count: int, timeout: float = 240) -> None:
    deadline = time.monotonic() + timeout
    while len(rollouts_logged(run_dir)) < count:
        if proc.poll() is not None:
            out, err = proc.communicate()
            pytest.fail(f"the run ended early ({proc.returncode}): {err[-2000:]}")
        assert time.monotonic() < deadline, "no rollout logged in time"
        time.sleep(0.2)


def group_is_gone(pgid: int, timeout: float = 15) -> bool:
    """Whether every process of the group has exited (env workers, the forkserver ...)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_to_the_process_group_checkpoints_a_process_pool_run(number, tmp_path, capsys):
    run_dir = tmp_path / "run"
    proc = start([*MARIO, "--steps", "100000", "--run-dir", str(run_dir)])
    wait_for_rollouts(proc, run_dir, 2)
    os.killpg(proc.pid, number)  # the whole group: trainer and env workers alike
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err[-2000:]
    assert "env worker" not in err, err[-2000:]  # the workers outlived the signal; the trainer closed them
    assert "interrupted; checkpoint saved" in err
    assert group_is_gone(proc.pid)
    state = read_checkpoint_state(run_dir / "checkpoint.npz")
    logged = rollouts_logged(run_dir)
    assert state["rollouts"] == logged[-1] >= 2  # the checkpoint is that of the last finished rollout
    if number != signal.SIGINT:
        return
    # and the plain resume continues from it: the next rollout is the one after
    env_steps = state["env_steps"]
    from tests.test_cli import run  # in this process: nothing signals it

    assert run(capsys, "train", "mario_ppo", "ppo", "--resume", str(run_dir), "--steps", str(env_steps + 128),
               "--no-progress", "--wandb", "off", "--final-eval-episodes", "0")[0] == 0
    after = rollouts_logged(run_dir)
    assert after[:len(logged)] == logged and after[len(logged):] == [logged[-1] + 1, logged[-1] + 2]


def test_a_second_signal_aborts_at_once(tmp_path):
    """The first signal asks for a checkpoint; a second one does not wait for it."""
    run_dir = tmp_path / "run"
    proc = start([*MARIO, "--steps", "100000", "--n-steps", "4096", "--run-dir", str(run_dir)])
    deadline = time.monotonic() + 120
    while not (run_dir / "metrics.csv").is_file() or (run_dir / "metrics.csv").stat().st_size == 0:
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGINT)  # a 8,192-transition rollout takes far longer than this test waits
    time.sleep(1.0)
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err[-2000:]
    assert "aborted" in err
    assert not (run_dir / "checkpoint.npz").exists()
    assert group_is_gone(proc.pid)
