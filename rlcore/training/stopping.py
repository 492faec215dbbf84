"""When a run stops. Two kinds of reason, kept apart:

- :class:`StopRequest`: someone asked (Ctrl-C, SIGTERM or SIGHUP, or a sweep's stop file). The loop stops at
  its next safe point, writes a checkpoint and raises :class:`Interrupted`; the run can be resumed.
- :class:`StopRules`: the run is done (a budget is spent or a goal reached). It then writes its
  model folder; ``meta.json`` records which rule ended it.
"""
from __future__ import annotations

import contextlib
import errno
import os
import signal
import stat
import sys
import threading
import time
from pathlib import Path

from tqdm.auto import tqdm  # a widget in a notebook, text in a terminal

from rlcore.hyperparams.allowed import resume_words

# each asks for a stop at the next safe point, with a checkpoint (SIGHUP: the terminal closed, an ssh
# connection dropped)
STOP_SIGNALS = {signal.SIGINT: "Ctrl-C", signal.SIGTERM: "SIGTERM", signal.SIGHUP: "SIGHUP"}


def detach_from_terminal() -> None:
    """After SIGHUP the terminal is gone and every write to it fails (EIO), which would end the run
    before its checkpoint: standard output and error that were that terminal go to /dev/null from here
    on (as under nohup). Pipes and files are kept, so a log still gets the last lines."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in (1, 2):
            with contextlib.suppress(OSError):
                if stat.S_ISCHR(os.fstat(fd).st_mode):  # a terminal (isatty() fails once it hung up)
                    os.dup2(devnull, fd)
    finally:
        os.close(devnull)


def announce_stop(signum: int, text: str, write=tqdm.write) -> None:
    """A stop handler's message (a run's, a sweep driver's), said so that a terminal that hung up (SIGHUP)
    cannot make the saying fail: its streams go to /dev/null first, and a failed write is dropped."""
    if signum == signal.SIGHUP:
        detach_from_terminal()
    with contextlib.suppress(OSError):
        write(f"\n{STOP_SIGNALS[signum]}: {text}")


class HangupSafe:
    """A terminal's text stream whose writes, once the terminal has hung up (they fail with EIO), go
    nowhere instead of raising: the write of a progress bar may come before the SIGHUP handler runs, and
    must not end the run before its checkpoint. Everything else is the stream's own."""

    def __init__(self, stream):
        self._stream = stream
        self.hung_up = False

    def _guarded(self, call, *args):
        if not self.hung_up:
            try:
                return call(*args)
            except OSError as exc:
                if exc.errno != errno.EIO:
                    raise
                self.hung_up = True
        return None

    def write(self, text: str) -> int:
        self._guarded(self._stream.write, text)
        return len(text)

    def flush(self) -> None:
        self._guarded(self._stream.flush)

    def isatty(self) -> bool:
        return not self.hung_up and self._stream.isatty()

    def __getattr__(self, name):
        return getattr(self._stream, name)


def guard_terminal_streams() -> None:
    """Standard output and error, where they are terminals, become :class:`HangupSafe` (the commands
    that train call it first, before any progress bar takes hold of ``sys.stderr``)."""
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if not isinstance(stream, HangupSafe) and getattr(stream, "isatty", lambda: False)():
            setattr(sys, name, HangupSafe(stream))


class Interrupted(Exception):
    """Raised after a stop request (Ctrl-C, SIGTERM, a stop file) once the checkpoint is safely written."""

    def __init__(self, checkpoint: Path):
        super().__init__(f"interrupted; checkpoint saved to {checkpoint}; continue with {resume_words(checkpoint.parent)}")
        self.checkpoint = checkpoint


class StopRequest:
    """Ctrl-C, SIGTERM or a stop file: ``requested`` turns true, and stays true. The file is looked at no
    more than once per ``FILE_CHECK_SECONDS`` (loops poll every env step)."""
    FILE_CHECK_SECONDS = 0.5

    def __init__(self, stop_file: Path | None = None):
        self.stop_file = stop_file
        self.requested = False
        self._next_look = 0.0

    def poll(self) -> bool:
        if not self.requested and self.stop_file is not None and time.monotonic() >= self._next_look:
            self._next_look = time.monotonic() + self.FILE_CHECK_SECONDS
            self.requested = self.stop_file.exists()
        return self.requested

    @contextlib.contextmanager
    def catching_stop_signals(self):
        """The first Ctrl-C, SIGTERM (``kill``, ``timeout``, a job scheduler) or SIGHUP (the terminal
        closed) sets ``requested``: the loop checkpoints and stops. A second one aborts without saving."""
        def handler(signum, frame):
            if self.requested:
                if signum == signal.SIGHUP:
                    detach_from_terminal()  # the abort's own line must not fail on a terminal that is gone
                raise KeyboardInterrupt
            self.requested = True
            announce_stop(signum, "stopping at the next safe point and saving a checkpoint "
                                  "(a second one aborts without saving)")
        if threading.current_thread() is not threading.main_thread():
            yield  # a Ray trial runs in a worker thread: its sweep stops it through the stop file
            return
        previous = {number: signal.signal(number, handler) for number in STOP_SIGNALS}
        try:
            yield
        finally:
            for number, old in previous.items():
                signal.signal(number, old)


class StopRules:
    """The budgets and goals of a config (``RunBudget`` and its subclasses), checked in this order:

    episodes: ``max_episodes`` finished; steps: ``max_env_steps`` spent (0 = no limit);
    eval score: a periodic evaluation reached ``stop_eval_score``; success share: at least
    ``stop_success_share`` of the last ``window`` episodes succeeded (e.g. reached the flag);
    average: the mean return of the last ``window`` episodes reached ``stop_score``.
    """

    def __init__(self, cfg):
        self.cfg = cfg
        self.success_share = getattr(cfg, "stop_success_share", 0.0)  # only PPOConfig declares it

    def reason(self, book, env_steps: int, evaluation) -> str | None:
        cfg = self.cfg
        if book.episodes >= cfg.max_episodes:
            return f"max_episodes {cfg.max_episodes}"
        if cfg.max_env_steps and env_steps >= cfg.max_env_steps:
            return f"max_env_steps {cfg.max_env_steps}"
        if evaluation.reached_stop_score():
            return f"stop_eval_score {evaluation.stop_score}"
        share = book.settled_success_share
        if self.success_share and share is not None and share >= self.success_share:
            return f"stop_success_share {self.success_share}"
        if book.full_window() and book.average >= cfg.stop_score:
            return f"stop_score {cfg.stop_score}"
        return None
