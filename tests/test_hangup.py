"""SIGHUP, as a terminal that closes or an ssh connection that drops sends it: the run ends at its next
safe point with a checkpoint, although every write to its terminal now fails (EIO), its env workers outlive
the signal, and nothing is left behind. A real pseudo-terminal is the run's controlling terminal, and
closing it is the hang-up."""
import csv
import fcntl
import os
import pty
import select
import subprocess
import sys
import termios
import threading
import time
from pathlib import Path

from rlcore.files.checkpoint import read_checkpoint_state
from tests.test_stop_signals import group_is_gone

ROOT = Path(__file__).resolve().parents[1]


def episodes_logged(run_dir: Path) -> int:
    table = run_dir / "metrics.csv"
    if not table.is_file():
        return 0
    with table.open() as f:
        return sum(1 for _ in csv.DictReader(f))


def test_closing_the_terminal_checkpoints_a_process_pool_run(tmp_path):
    run_dir = tmp_path / "run"
    master, slave = pty.openpty()

    def on_the_terminal():  # in the child, after setsid: the pty becomes its controlling terminal
        fcntl.ioctl(0, termios.TIOCSCTTY, 0)

    proc = subprocess.Popen(
        [sys.executable, "main.py", "train", "cartpole", "a2c", "--vec", "processes", "--num-envs", "2",
         "--episodes", "100000", "--run-dir", str(run_dir), "--wandb", "off", "--final-eval-episodes", "0"],
        cwd=ROOT, stdin=slave, stdout=slave, stderr=slave, start_new_session=True, preexec_fn=on_the_terminal)
    os.close(slave)
    hang_up = threading.Event()
    seen = bytearray()

    def terminal():  # reads what the run prints (its progress bar too) until the terminal closes
        while not hang_up.is_set():
            if select.select([master], [], [], 0.05)[0]:
                try:
                    seen.extend(os.read(master, 65536))
                except OSError:
                    break
        os.close(master)
    reader = threading.Thread(target=terminal, daemon=True)
    reader.start()
    try:
        deadline = time.monotonic() + 180
        while episodes_logged(run_dir) < 20:
            assert proc.poll() is None, f"the run ended early ({proc.returncode})"
            assert time.monotonic() < deadline, "no episodes logged in time"
            time.sleep(0.2)
    finally:
        hang_up.set()
        reader.join(10)
    assert proc.wait(timeout=120) == 130, seen.decode(errors="replace")[-1500:]
    state = read_checkpoint_state(run_dir / "checkpoint.npz")
    assert len(state["returns"]) == episodes_logged(run_dir) >= 20  # the checkpoint of the last logged episode
    assert group_is_gone(proc.pid)


def test_a_terminal_stream_that_hung_up_swallows_writes_and_nothing_else():
    import errno

    import pytest

    from rlcore.training.stopping import HangupSafe

    class Terminal:
        def __init__(self, error):
            self.error, self.text = error, ""

        def write(self, text):
            if self.error:
                raise OSError(self.error, os.strerror(self.error))
            self.text += text

        def flush(self):
            pass

        def isatty(self):
            return True

    alive = HangupSafe(Terminal(None))
    assert alive.write("progress") == 8 and alive._stream.text == "progress" and alive.isatty()
    gone = HangupSafe(Terminal(errno.EIO))  # the terminal hung up: the progress bar's write is dropped
    assert gone.write("progress") == 8 and gone.hung_up and not gone.isatty()
    full = HangupSafe(Terminal(errno.ENOSPC))  # any other failure is still an error
    with pytest.raises(OSError):
        full.write("x")
