"""The one exception type that reaches the user as a single clear line."""


class UserError(Exception):
    """A mistake the user can fix (bad name, missing file, wrong shape ...).

    ``main.py`` prints ``error: <message>`` and exits with status 2, without a traceback.
    """
