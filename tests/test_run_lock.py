"""One writer per run folder: a second process that would train or resume a folder another process
writes is refused in one line naming the folder and the holder's pid, and changes nothing there; the
lock dies with its holder, so after `kill -9` the run resumes."""
import hashlib
import signal
import subprocess
import sys
from pathlib import Path

from rlcore.files.run_lock import hold_run_folder
from tests.test_cli import run

ROOT = Path(__file__).resolve().parents[1]
QUICK = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "0"]


def hold_elsewhere(folder: Path) -> subprocess.Popen:
    """Another process that holds the folder's lock until killed."""
    code = ("import sys, time; from rlcore.files.run_lock import hold_run_folder\n"
            "with hold_run_folder(sys.argv[1]):\n    print('held', flush=True); time.sleep(600)")
    holder = subprocess.Popen([sys.executable, "-c", code, str(folder)], cwd=ROOT, stdout=subprocess.PIPE,
                              text=True)
    assert holder.stdout.readline().strip() == "held"
    return holder


def fingerprint(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_second_writer_is_refused_and_a_killed_holder_leaves_no_stale_lock(tmp_path, capfd):
    run_dir = tmp_path / "run"
    # every run in this process (the holder is another): the refused one's whole stderr is checked
    assert run(capfd, "train", "cartpole", "dqn", "--episodes", "2", "--run-dir", str(run_dir), *QUICK)[0] == 0
    holder = hold_elsewhere(run_dir)
    before = fingerprint(run_dir)
    try:
        code, out, err = run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK)
        assert code == 2
        assert out == "", out  # refused before the checkpoint is read: no "resuming ..." or "training ..." line first
        lines = err.strip().splitlines()
        assert len(lines) == 1 and str(run_dir.resolve()) in lines[0] and str(holder.pid) in lines[0], lines
        assert fingerprint(run_dir) == before  # nothing written, nothing dropped
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert run(capfd, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4", *QUICK)[0] == 0


def test_a_process_may_reenter_its_own_lock_and_another_may_not(tmp_path):
    with hold_run_folder(tmp_path / "run") as folder:
        with hold_run_folder(folder):  # a sweep trial holds it, then run_training takes it again
            pass
        holder_line = (folder / ".lock").read_text().strip()
        assert holder_line.isdigit()
        other = subprocess.run([sys.executable, "-c", "import sys; from rlcore.files.run_lock import hold_run_folder\n"
                                "with hold_run_folder(sys.argv[1]): pass", str(folder)],
                               cwd=ROOT, capture_output=True, text=True)
        assert other.returncode != 0 and "RunFolderBusy" in other.stderr
    with hold_run_folder(tmp_path / "run"):  # released at the end of the block: taken again
        pass


def test_a_folder_made_for_a_run_that_wrote_nothing_goes_and_a_given_one_stays(tmp_path):
    """A run that fails before writing anything leaves no folder holding only .lock; a folder that existed
    before (a user's, or a resumed run's) stays, and so does one the run wrote into."""
    with hold_run_folder(tmp_path / "new"):
        pass
    assert not (tmp_path / "new").exists()
    (tmp_path / "given").mkdir()
    with hold_run_folder(tmp_path / "given"):
        pass
    assert (tmp_path / "given").is_dir()
    with hold_run_folder(tmp_path / "wrote") as folder:
        (folder / "metrics.csv").write_text("episode\n")
    assert (tmp_path / "wrote" / "metrics.csv").is_file()


def test_a_lock_on_a_lock_file_removed_meanwhile_is_not_held(tmp_path):
    """Taking a lock on a lock file another process removed (its folder dropped) would let a third process
    lock the new file too: the lock checks that its file is still the folder's, and takes the new one."""
    import os

    from rlcore.files.run_lock import _lock, _still_there

    folder = tmp_path / "run"
    fd = _lock(folder)
    assert _still_there(fd, folder / ".lock")
    (folder / ".lock").unlink()
    assert not _still_there(fd, folder / ".lock")
    again = _lock(folder)  # the old descriptor still locks the removed file: the new one is free
    assert _still_there(again, folder / ".lock")
    os.close(fd)
    os.close(again)
