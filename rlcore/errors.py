"""The one exception type that reaches the user as a single clear line."""


class UserError(Exception):
    """A mistake the user can fix (bad name, missing file, wrong shape ...).

    ``main.py`` prints ``error: <message>`` and exits with status 2, without a traceback.
    """


class WriteFailed(UserError):
    """A file could not be written (a full disk, a read-only or unwritable folder). The file it would
    have replaced is untouched, and no temporary file is left behind."""

    def __init__(self, path, exc: OSError):
        import errno

        what = {errno.ENOSPC: "the disk is full: free some space (or write elsewhere), then resume the run",
                errno.EDQUOT: "the disk quota is used up: free some space, then resume the run",
                errno.EROFS: "the file system is read-only: write elsewhere",
                errno.EACCES: "no permission to write there: write elsewhere"}.get(exc.errno, "check the disk and the folder, then resume the run")
        super().__init__(f"cannot write {path}: {exc.strerror or exc}; {what}")
        self.errno = exc.errno
