"""The one exception type that reaches the user as a single clear line."""


class UserError(Exception):
    """A mistake the user can fix (bad name, missing file, wrong shape ...).

    ``main.py`` prints ``error: <message>`` and exits with status 2, without a traceback.
    """


class WriteFailed(UserError):
    """A file could not be written (a full disk, a read-only or unwritable folder). The file it would
    have replaced is untouched, and no temporary file is left behind."""

    def __init__(self, path, exc: OSError, then: str = "resume the run"):
        import errno

        what = {errno.ENOSPC: f"the disk is full: free some space (or write elsewhere), then {then}",
                errno.EDQUOT: f"the disk quota is used up: free some space, then {then}",
                errno.EROFS: "the file system is read-only: write elsewhere",
                errno.EACCES: "no permission to write there: write elsewhere"}.get(exc.errno, f"check the disk and the folder, then {then}")
        reason = exc.strerror or (str(exc).strip().splitlines() or [type(exc).__name__])[0]  # a writer's log: its first line
        super().__init__(f"cannot write {path}: {reason}; {what}")
        self.errno = exc.errno


def disk_error(exc: BaseException, folder=None) -> OSError | None:
    """The OS error behind a library's failed write into ``folder`` (TensorFlow's ResourceExhaustedError on a
    full disk, a converter's message that quotes the OS, ffmpeg's broken pipe where the disk has filled), or
    None when ``exc`` is no disk error."""
    import errno
    import os
    import shutil

    if isinstance(exc, OSError) and exc.errno not in (errno.EPIPE, None):  # ffmpeg's pipe: errno None or EPIPE
        return exc
    text = f"{type(exc).__name__}: {exc}"
    for code, words in ((errno.ENOSPC, "No space left"), (errno.EROFS, "Read-only file system"),
                        (errno.EDQUOT, "Disk quota exceeded"), (errno.EACCES, "Permission denied")):
        if words in text:
            return OSError(code, os.strerror(code))
    if type(exc).__name__ == "ResourceExhaustedError":  # TensorFlow's writers on a full disk
        return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    if folder is not None and shutil.disk_usage(folder).free < 1 << 20:  # a writer process's pipe broke
        return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    return exc if isinstance(exc, OSError) else None
