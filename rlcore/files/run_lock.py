"""One writer per run folder.

A process that trains or resumes a run folder holds an advisory lock (``flock``) on its ``.lock``
file for as long as it writes there. The kernel drops the lock when the process ends, however it
ends (``kill -9`` included), so a lock is never stale: a Ray trial restarted after its worker died
takes it again. A second writer is refused in one line naming the folder and the holder's pid,
before it has written anything there.
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import os
from pathlib import Path
from typing import Iterator

from rlcore.errors import UserError

LOCK_FILE = ".lock"
_held: dict[Path, list] = {}  # folder -> [fd, depth]: a process may re-enter its own lock


class RunFolderBusy(UserError):
    """Another process writes the run folder."""


@contextlib.contextmanager
def hold_run_folder(run_dir: str | os.PathLike) -> Iterator[Path]:
    """Hold the run folder's lock for the duration of the block (creating the folder if needed)."""
    folder = Path(run_dir).resolve()
    if folder in _held:
        _held[folder][1] += 1
        try:
            yield folder
        finally:
            _held[folder][1] -= 1
        return
    created = not folder.exists()
    fd = _lock(folder)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)  # who holds it, for the message above
        _held[folder] = [fd, 1]
        yield folder
    finally:
        _held.pop(folder, None)
        if created:
            _drop_if_unwritten(folder)  # a run that failed before writing anything leaves no folder behind
        os.close(fd)  # closing the descriptor releases the lock


def refuse_if_busy(run_dir: str | os.PathLike) -> None:
    """Refuse at once a run folder that another process writes, before a command loads or prints anything
    (a resume read the checkpoint and printed its header first, and was refused ~40 s later). The lock is
    taken for real when training starts (:func:`hold_run_folder`), so a writer that begins in between is
    still refused there."""
    folder = Path(run_dir).resolve()
    if folder in _held:  # this process holds it (a sweep's trial): a second descriptor would contend with it
        return
    try:
        fd = os.open(folder / LOCK_FILE, os.O_RDWR)
    except OSError:  # no lock file: nobody has written there, or it cannot be opened (the real lock says why)
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        fcntl.flock(fd, fcntl.LOCK_UN)
    except OSError as exc:
        if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            raise _busy(folder, os.pread(fd, 32, 0)) from None
    finally:
        os.close(fd)


def _busy(folder: Path, holder: bytes) -> RunFolderBusy:
    pid = holder.decode(errors="replace").strip() or "unknown"
    return RunFolderBusy(f"run folder {folder} is being written by process {pid}; wait for it to end "
                         f"(or stop it: kill {pid}), then resume it")


def _lock(folder: Path) -> int:
    """Create the folder if needed and lock its lock file; the descriptor. A lock file removed while we
    waited for it (its folder was dropped by a run that failed before writing) is locked again anew."""
    if folder.exists() and not folder.is_dir():
        raise UserError(f"run folder {folder} is a file, not a folder")
    for _ in range(5):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd = os.open(folder / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise UserError(f"run folder {folder}: cannot write there ({exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            holder = os.pread(fd, 32, 0)
            os.close(fd)
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise UserError(f"run folder {folder}: cannot lock it ({exc.strerror})") from None
            raise _busy(folder, holder) from None
        if _still_there(fd, folder / LOCK_FILE):
            return fd
        os.close(fd)  # we locked a file that is gone from the folder: another process may lock the new one
    raise UserError(f"run folder {folder}: its lock file keeps being removed; is another program deleting it?")


def _still_there(fd: int, path: Path) -> bool:
    try:
        here, there = os.fstat(fd), os.stat(path)
    except OSError:
        return False
    return (here.st_dev, here.st_ino) == (there.st_dev, there.st_ino)


def _drop_if_unwritten(folder: Path) -> None:
    """Remove a folder this process created for a run, when the lock file is all it holds."""
    try:
        if [p.name for p in folder.iterdir()] == [LOCK_FILE]:
            (folder / LOCK_FILE).unlink()
            folder.rmdir()
    except OSError:
        pass  # something else appeared in it, or it went: leave it as it is
