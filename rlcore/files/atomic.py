"""Atomic file writes: write beside the target, then ``os.replace``.

A crash or Ctrl-C mid-write leaves the previous good file in place, never a half-written one.
"""
from __future__ import annotations

import contextlib
import errno
import json
import os
import tempfile
from pathlib import Path
from typing import Callable, Iterator

from rlcore.errors import UserError, WriteFailed, disk_error


def writable_folder(folder: str | os.PathLike, what: str) -> Path:
    """Create ``folder`` (with its parents) and check that a file can be written in it, before any
    work whose result would go there; otherwise one clear error naming ``what`` (e.g. ``--out``)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise UserError(f"{what} {folder} is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        reason = exc.strerror or str(exc)
        if exc.errno == errno.ENOENT and folder.is_dir():  # /proc, /sys: the folder is there, a new file is not
            reason = "the folder takes no new files"
        raise UserError(f"{what} {folder}: cannot write there ({reason})") from None
    return folder


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike, then: str = "resume the run") -> Iterator[Path]:
    """Yield a temporary path in the target's folder; on success move it onto ``target``.

    The temporary name keeps the target's suffix, so writers that pick a format from the
    extension (Keras ``.h5``, imageio ``.mp4``, numpy ``.npz``) still work.

    A full disk or an unwritable folder is a :class:`WriteFailed` naming ``target``: the previous
    file stays as it was and the temporary one is removed; ``then`` says what to do once there is room.
    """
    target = Path(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=".tmp" + target.suffix,
                                   dir=target.parent)
    except OSError as exc:
        raise WriteFailed(target, exc, then) from None
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file normal permissions
        os.replace(tmp, target)
    except OSError as exc:
        raise WriteFailed(target, exc, then) from None
    finally:
        if tmp.exists():
            tmp.unlink()


@contextlib.contextmanager
def library_writes(folder: str | os.PathLike) -> Iterator[None]:
    """A library's failed write into ``folder`` raised as the OS error behind it (:func:`rlcore.errors.disk_error`),
    for :func:`atomic_path` or the caller to name in one line; any other error passes as it is."""
    try:
        yield
    except UserError:
        raise
    except Exception as exc:  # noqa: BLE001 (a library's own error type, turned into the OS error behind it)
        reason = disk_error(exc, folder)
        if reason is None or reason is exc:
            raise
        raise reason from None


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_atomic(target: str | os.PathLike, writer: Callable[[Path], None], then: str = "resume the run") -> None:
    """Call ``writer(tmp_path)`` and move the result onto ``target``."""
    with atomic_path(target, then) as tmp:
        writer(tmp)


def write_json(target: str | os.PathLike, data: dict) -> None:
    """Write ``data`` as indented JSON, atomically."""
    write_atomic(target, lambda p: p.write_text(json.dumps(data, indent=2, default=str) + "\n"))


def replace_folder(target: str | os.PathLike, fill: Callable[[Path], None]) -> Path:
    """Make ``target`` a folder holding exactly what ``fill(new_folder)`` writes, replacing it whole.

    The new folder is built beside the target, then swapped in with two renames: a crash leaves either
    the old folder or the new one in place (plus at most a hidden ``.NAME.old-*`` / ``.NAME.new-*``
    folder to delete), never a mix; files of the old folder that the new one lacks do not survive. A
    full disk or an unwritable folder is a :class:`WriteFailed` naming ``target``."""
    import shutil

    target = Path(target)
    fresh = None
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fresh = Path(tempfile.mkdtemp(prefix=f".{target.name}.new-", dir=target.parent))
        fill(fresh)
        os.chmod(fresh, 0o755)
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.replace(target, old / target.name)
            os.replace(fresh, target)
            shutil.rmtree(old)
        else:
            os.replace(fresh, target)
    except OSError as exc:
        raise WriteFailed(target, exc, "keep them again") from None
    finally:
        if fresh is not None and fresh.exists():
            shutil.rmtree(fresh, ignore_errors=True)
    return target
