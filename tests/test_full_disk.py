"""A full disk or an unwritable folder while a run writes: one line naming the path and the OS error,
a non-zero exit, no temporary file left, and the last good checkpoint still resumes. The disk is a
real, small tmpfs (mounting one needs root, as CI and developer machines here run; skipped elsewhere)."""
import errno
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from rlcore.errors import WriteFailed
from tests.test_cli import run  # in this process; capfd reads what it wrote to the stderr descriptor

QUICK = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


@pytest.fixture
def small_disk(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    if shutil.which("mount") is None:
        pytest.skip("no mount command here")
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


def test_a_full_disk_is_one_line_and_the_last_checkpoint_resumes(small_disk, capfd):
    """Full at a checkpoint (64 kB left: the rows fit, the Q-networks, Adam and replay do not), then full
    at the first CSV row (nothing left): each is one line, and the run resumes once there is room."""
    run_dir = small_disk / "run"
    assert run(capfd, "train", "cartpole", "dqn", "--episodes", "3", "--checkpoint-every", "1",
               "--run-dir", str(run_dir), *QUICK)[0] == 0
    good = (run_dir / "checkpoint.npz").read_bytes()
    for leave in (64_000, 0):
        filler = fill(small_disk, leave)
        code, _, err = run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "40", *QUICK)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith(f"error: cannot write {run_dir}/"), (leave, lines)
        assert "No space left on device" in lines[0] and "free some space" in lines[0]
        assert not [p for p in run_dir.rglob("*") if ".tmp" in p.name], "a temporary file was left behind"
        assert (run_dir / "checkpoint.npz").read_bytes() == good
        filler.unlink()
    assert run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "5", *QUICK)[0] == 0


def test_a_read_only_disk_is_one_clear_error_and_the_run_resumes_once_writable(small_disk, capfd):
    run_dir = small_disk / "run"
    assert run(capfd, "train", "cartpole", "dqn", "--episodes", "2", "--run-dir", str(run_dir), *QUICK)[0] == 0
    subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], check=True)
    try:
        code, _, err = run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1, lines
        assert str(run_dir) in lines[0] and "Read-only file system" in lines[0]
        code, _, err = run(capfd, "render", "cartpole", "dqn", "--model", str(run_dir / "model"),
                           "--out", str(small_disk / "video.mp4"))
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and "--out" in lines[0] and "Read-only" in lines[0], lines
    finally:
        subprocess.run(["mount", "-o", "remount,rw", str(small_disk)], check=True)
    assert run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK)[0] == 0


def test_write_failed_names_the_path_and_what_to_do(tmp_path):
    error = WriteFailed(tmp_path / "x.npz", OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)))
    assert str(error).startswith(f"cannot write {tmp_path}/x.npz: No space left on device; the disk is full")


@pytest.mark.parametrize("fmt", ["savedmodel", "tflite", "onnx"])
def test_an_export_onto_a_full_disk_is_one_line_and_an_earlier_export_stays_whole(small_disk, capfd, fmt):
    """TensorFlow's SavedModel writer, the TFLite converter and tf2onnx raise their own errors on a full
    disk (ResourceExhaustedError ...): each is the one WriteFailed line, into a new folder or over an
    earlier export, which stays as it was."""
    earlier = small_disk / "earlier"
    code, _, err = run(capfd, "export", "lunar_lander", "dqn", "--format", fmt, "--out", str(earlier))
    assert code == 0, err
    before = {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()}
    filler = fill(small_disk, 0)
    for out in (small_disk / "new", earlier):
        code, _, err = run(capfd, "export", "lunar_lander", "dqn", "--format", fmt, "--out", str(out))
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith(f"error: cannot write {out}"), lines
        assert "No space left on device" in lines[0] and "then export again" in lines[0]
        assert not (small_disk / "new").exists()
        assert {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()} == before
        assert not [p for p in small_disk.iterdir() if p.name.startswith(".")], "a temporary folder was left"
    filler.unlink()


@pytest.mark.parametrize("suffix", ["gif", "mp4"])
def test_a_video_onto_a_full_disk_is_one_line_and_an_earlier_one_stays_whole(small_disk, capfd, suffix):
    """Pillow failed again in imageio's __del__ (a traceback after our line), and ffmpeg printed its log and
    a broken pipe: each is now the one line naming the video, with no temporary file left."""
    video = small_disk / f"lander.{suffix}"
    assert run(capfd, "render", "lunar_lander", "dqn", "--out", str(video))[0] == 0
    before = video.read_bytes()
    filler = fill(small_disk, 0)
    code, _, err = run(capfd, "render", "lunar_lander", "dqn", "--out", str(video))
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith(f"error: cannot write {video}: No space left"), lines
    assert lines[0].endswith("then render again")
    assert video.read_bytes() == before
    assert not [p for p in small_disk.iterdir() if p.name.startswith(".")], "a temporary file was left"
    filler.unlink()


def test_a_report_and_a_keep_onto_a_full_disk_are_one_line(small_disk, capfd):
    """report.md, its PNGs and a kept folder: one line each naming the file, what to do next in the
    command's own words; --keep leaves no half-made folder."""
    sweep = small_disk / "sweep"
    shutil.copytree(Path(__file__).resolve().parents[1] / "results" / "sweeps" / "cartpole__a2c", sweep)
    filler = fill(small_disk, 0)
    code, _, err = run(capfd, "report", str(sweep), "--out", str(small_disk / "report"))
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "No space left" in lines[0] and lines[0].endswith("then report again"), lines
    code, _, err = run(capfd, "report", str(sweep / "seed=0"), str(sweep / "seed=1"), "--keep", str(small_disk / "kept"))
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "No space left" in lines[0] and "Traceback" not in err, lines
    assert not (small_disk / "kept").exists()
    assert not [p for p in small_disk.iterdir() if p.name.startswith(".")], "a temporary folder was left"
    filler.unlink()
