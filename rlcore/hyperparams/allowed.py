"""What values a hyperparameter accepts, declared once beside its dataclass field.

    lr: float = _h(1e-3, "learning rate", POSITIVE)

``check_fields(cfg)`` runs every declaration when a config is built (its ``__post_init__``), so a
bad value from the command line, a preset or a checkpoint is refused before any run folder exists,
with one line naming the flag, the value and what is allowed. TensorFlow-free.

The line names a setting as its caller wrote it: ``--lr -1.0`` on the command line, ``lr=-1.0`` inside
:func:`python_names` (the Python API's calls).
"""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import functools
import math
import operator
from dataclasses import dataclass
from typing import Callable, Iterator, ParamSpec, TypeVar

from rlcore.errors import UserError


def _num(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


@dataclass(frozen=True)
class Allowed:
    """A range (``low``/``high``, each inclusive unless ``*_open``) or a set of ``choices``.

    Numbers must also be finite. For a tuple field the rule applies to every item, and the tuple
    must not be empty unless ``empty_ok`` (a list where empty means "off").
    """
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple = ()
    empty_ok: bool = False

    def describe(self) -> str:
        if self.choices:
            return "one of " + ", ".join(map(str, self.choices))
        if self.low is not None and self.high is not None:
            if not (self.low_open or self.high_open):
                return f"a number from {_num(self.low)} to {_num(self.high)}"
            left = f"above {_num(self.low)}" if self.low_open else f"of at least {_num(self.low)}"
            right = f"below {_num(self.high)}" if self.high_open else f"at most {_num(self.high)}"
            return f"a number {left} and {right}"
        if self.low is not None:
            return f"a number {'above' if self.low_open else 'of at least'} {_num(self.low)}"
        if self.high is not None:
            return f"a number {'below' if self.high_open else 'of at most'} {_num(self.high)}"
        return "a finite number"

    def accepts(self, value) -> bool:
        if self.choices:
            return value in self.choices
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            return False
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            return False
        if self.high is not None and (value >= self.high if self.high_open else value > self.high):
            return False
        return True


POSITIVE = Allowed(low=0, low_open=True)
NON_NEGATIVE = Allowed(low=0)
FINITE = Allowed()
UNIT = Allowed(low=0, high=1)  # probabilities, discounts, GAE lambda, shares
COUNT = Allowed(low=1)  # sizes, widths, counts, periods
OFF_OR_COUNT = NON_NEGATIVE  # budgets and periods where 0 means "off"


def choices(*values) -> Allowed:
    return Allowed(choices=tuple(values))


_PYTHON_NAMES = contextvars.ContextVar("python_names", default=False)


@contextlib.contextmanager
def python_names() -> Iterator[None]:
    """Within: errors name a setting as a Python call gives it (``lr``, ``lr=-1.0``), not as a flag."""
    token = _PYTHON_NAMES.set(True)
    try:
        yield
    finally:
        _PYTHON_NAMES.reset(token)


_P = ParamSpec("_P")
_R = TypeVar("_R")


def named_as_python(call: Callable[_P, _R]) -> Callable[_P, _R]:
    """A Python API function whose errors name settings as the call gave them (:func:`python_names`)."""
    @functools.wraps(call)
    def named(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with python_names():
            return call(*args, **kwargs)
    return named


def resume_words(run_dir) -> str:
    """How to continue the run in ``run_dir``: ``--resume DIR``, or ``api.resume('DIR')`` in Python."""
    return f"api.resume({str(run_dir)!r})" if in_python() else f"--resume {run_dir}"


def in_python() -> bool:
    """True within :func:`python_names` (a Python API call), False on the command line."""
    return _PYTHON_NAMES.get()


def flag(name: str) -> str:
    """A config field as its caller names it: ``--batch-size`` on the command line, ``batch_size`` in Python."""
    return name if in_python() else "--" + name.replace("_", "-")


def setting(name: str, value) -> str:
    """A field given a value, as its caller writes it: ``--hidden 64,64`` or ``hidden=(64, 64)``."""
    if in_python():
        return f"{name}={value!r}"
    return f"{flag(name)} {shown(value) or '(empty)'}"


def shown(value) -> str:
    """A value as the command line takes it: ``64,64``, ``3`` for 3.0, ``0.0005``."""
    if isinstance(value, tuple):
        return ",".join(map(shown, value))
    if isinstance(value, float) and math.isfinite(value) and float(f"{value:g}") == value:
        return f"{value:g}"
    return str(value)


def invalid(name: str, value, allowed: str) -> UserError:
    """The one-line error for a bad value of field ``name``."""
    if isinstance(value, float) and not math.isfinite(value):
        allowed = allowed.replace("a number", "a finite number")
    if in_python():
        allowed = allowed.replace("a comma-separated list", "a list or tuple")
    return UserError(f"{setting(name, value)} is invalid: allowed is {allowed}")


def _is_whole(value) -> bool:
    try:
        operator.index(value)  # int, numpy integers; not 64.0
    except TypeError:
        return False
    return not isinstance(value, bool)


def field_values(f: dataclasses.Field) -> str:
    """What a config field allows, in words (``a whole number of at least 1`` for an ``int``; ``""``
    without a declaration): for its error line, ``--help`` and the hyperparameters page."""
    allowed = f.metadata.get("allowed")
    if allowed is None:
        return ""
    if str(f.type) in ("int", "tuple[int, ...]") and not allowed.choices:
        return _whole_words(allowed)
    return allowed.describe()


def field_words(f: dataclasses.Field) -> str:
    """:func:`field_values` of a whole field: a list field (hidden sizes) says it takes a list of them."""
    values = field_values(f)
    if values and str(f.type).startswith("tuple"):
        empty = " (or empty)" if f.metadata["allowed"].empty_ok else ""
        return f"a comma-separated list, each item {values}{empty}"
    return values


def _whole_words(allowed: Allowed) -> str:
    return allowed.describe().replace("a number", "a whole number", 1)


def check_fields(cfg) -> None:
    """Raise :class:`UserError` for the first field of ``cfg`` outside its declared ``allowed``; a field
    declared ``int`` (or a tuple of them) takes whole numbers only (the Python API could pass 64.5)."""
    for f in dataclasses.fields(cfg):
        allowed = f.metadata.get("allowed")
        value = getattr(cfg, f.name)
        if allowed is None:
            continue
        whole = str(f.type) in ("int", "tuple[int, ...]")
        fits = (lambda item: allowed.accepts(item) and (_is_whole(item) or not whole))
        if isinstance(value, tuple) or str(f.type).startswith("tuple"):  # a list field (hidden=64 is not one)
            if not isinstance(value, tuple) or (not value and not allowed.empty_ok) or not all(map(fits, value)):
                raise invalid(f.name, value, field_words(f))
        elif not fits(value):
            raise invalid(f.name, value, field_values(f))


def whole_number(allowed: Allowed):
    """An argparse ``type``: a whole number that ``allowed`` accepts (``--episodes``, ``--seed`` ...)."""
    import argparse

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not allowed.accepts(value):
            raise argparse.ArgumentTypeError(f"{value} is invalid: allowed is {_whole_words(allowed)}")
        return value
    return parse


def check_whole(name: str, value, allowed: Allowed, none_ok: bool = False) -> None:
    """A whole-number argument of the Python API (``seed=``, ``episodes=`` ...), checked as
    :func:`whole_number` checks it on the command line: :class:`UserError` naming it otherwise.
    ``none_ok``: None (the default's stand-in) passes."""
    if value is None and none_ok:
        return
    try:
        number = None if isinstance(value, bool) else operator.index(value)  # int, numpy integers
    except TypeError:
        number = None
    if number is None or not allowed.accepts(number):
        raise UserError(f"{name}={value!r} is invalid: allowed is {_whole_words(allowed)}")


def require(condition: bool, message: str) -> None:
    """A rule between fields (e.g. the minibatch divides the rollout), checked in ``__post_init__``."""
    if not condition:
        raise UserError(message)
