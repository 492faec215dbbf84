"""A loss that turned NaN/Inf ends the run with one line that says what to do, not a traceback."""
from __future__ import annotations

import contextlib

import tensorflow as tf

from rlcore.errors import UserError


@contextlib.contextmanager
def reported_divergence(session, algo: str, advice: str):
    """Around an update: its numeric check failing becomes a :class:`UserError` at the current env
    step. The check is ``tf.debugging.check_numerics(loss, "<algo> ...")`` inside a compiled step, or
    a ``FloatingPointError`` from an agent that checks after the call (XLA drops check_numerics).
    ``advice``: what to lower, e.g. "lower --lr"."""
    try:
        yield
    except tf.errors.InvalidArgumentError as exc:
        if algo not in str(exc):
            raise
        what = f"the {algo} loss is NaN/Inf"
    except FloatingPointError as exc:
        what = str(exc)
    else:
        return
    raise UserError(f"training diverged: {what} at env step {session.env_steps}; {advice} or resume from "
                    "the last checkpoint")
