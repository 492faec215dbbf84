"""A full disk or an unwritable folder while a run writes: one line naming the path and the OS error,
a non-zero exit, no temporary file left, and the last good checkpoint still resumes. The disk is a
real, small tmpfs (mounting one needs root, as CI and developer machines here run; skipped elsewhere)."""
import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rlcore.errors import WriteFailed

ROOT = Path(__file__).resolve().parents[1]
QUICK = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


@pytest.fixture
def small_disk(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    mount = tmp_path / "disk"
    mount.mkdir()
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", str(mount)],
                          capture_output=True, text=True)
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.strip()}")
    yield mount
    subprocess.run(["umount", "-l", str(mount)], capture_output=True)


def fill(disk: Path, leave: int) -> Path:
    """Take all but about ``leave`` bytes of the disk's free space."""
    filler = disk / "filler"
    stats = os.statvfs(disk)
    size = max(0, stats.f_bavail * stats.f_frsize - leave)
    with open(filler, "wb") as f:
        try:
            f.write(b"\0" * size)
        except OSError as exc:
            assert exc.errno == errno.ENOSPC
    return filler


def main_py(*argv: str) -> subprocess.CompletedProcess:
    """A command in a process of its own: its whole stderr is what a user would see."""
    return subprocess.run([sys.executable, "main.py", *argv], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)


def in_process(*argv: str) -> int:
    """A command whose output is not under test, in this process (no second TensorFlow start-up)."""
    from rlcore import cli

    return cli.main(list(argv))


def test_a_full_disk_is_one_line_and_the_last_checkpoint_resumes(small_disk):
    """Full at a checkpoint (64 kB left: the rows fit, the Q-networks, Adam and replay do not), then full
    at the first CSV row (nothing left): each is one line, and the run resumes once there is room."""
    run_dir = small_disk / "run"
    assert in_process("train", "cartpole", "dqn", "--episodes", "3", "--checkpoint-every", "1",
                      "--run-dir", str(run_dir), *QUICK) == 0
    good = (run_dir / "checkpoint.npz").read_bytes()
    for leave in (64_000, 0):
        filler = fill(small_disk, leave)
        full = main_py("train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "40", *QUICK)
        assert full.returncode == 2, full.stderr
        lines = full.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"error: cannot write {run_dir}/"), (leave, lines)
        assert "No space left on device" in lines[0] and "free some space" in lines[0]
        assert not [p for p in run_dir.rglob("*") if ".tmp" in p.name], "a temporary file was left behind"
        assert (run_dir / "checkpoint.npz").read_bytes() == good
        filler.unlink()
    assert in_process("train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "5", *QUICK) == 0


def test_a_read_only_disk_is_one_clear_error_and_the_run_resumes_once_writable(small_disk):
    run_dir = small_disk / "run"
    assert in_process("train", "cartpole", "dqn", "--episodes", "2", "--run-dir", str(run_dir), *QUICK) == 0
    subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], check=True)
    try:
        refused = main_py("train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK)
        lines = refused.stderr.strip().splitlines()
        assert refused.returncode == 2 and len(lines) == 1, refused.stderr
        assert str(run_dir) in lines[0] and "Read-only file system" in lines[0]
        out = main_py("render", "cartpole", "dqn", "--model", str(run_dir / "model"),
                      "--out", str(small_disk / "video.mp4"))
        assert out.returncode == 2 and "--out" in out.stderr and "Read-only" in out.stderr, out.stderr
    finally:
        subprocess.run(["mount", "-o", "remount,rw", str(small_disk)], check=True)
    assert in_process("train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK) == 0


def test_write_failed_names_the_path_and_what_to_do(tmp_path):
    error = WriteFailed(tmp_path / "x.npz", OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)))
    assert str(error).startswith(f"cannot write {tmp_path}/x.npz: No space left on device; the disk is full")
