"""Hyperparameter dataclasses <-> command line.

Every field of a config dataclass becomes a ``--field-name VALUE`` option with the field's
``help`` metadata as its help text, so no flag is written by hand.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import typing

from rlcore.errors import UserError
from rlcore.hyperparams.allowed import field_words, flag, setting


def _parse_bool(text: str) -> bool:
    lowered = text.strip().lower()
    if lowered in ("1", "true", "yes", "on"):
        return True
    if lowered in ("0", "false", "no", "off"):
        return False
    raise argparse.ArgumentTypeError(f"{text!r} is invalid: allowed is true or false (also 1/0, yes/no, on/off)")


def _parser_for(annotation) -> typing.Callable[[str], object]:
    """Turn a field's type annotation into a function parsing its CLI text."""
    if annotation is bool:
        return _parse_bool
    if annotation in (int, float, str):
        return annotation
    if typing.get_origin(annotation) is tuple:
        (item,) = {a for a in typing.get_args(annotation) if a is not Ellipsis}
        def parse(text: str) -> tuple:
            return tuple(item(part) for part in text.split(",") if part.strip())
        parse.__name__ = f"comma-separated {item.__name__}"  # argparse's "invalid ... value: 'x'"
        return parse
    raise TypeError(f"unsupported hyperparameter type {annotation!r}")


def field_types(cls) -> dict[str, typing.Callable[[str], object]]:
    hints = typing.get_type_hints(cls)
    return {f.name: _parser_for(hints[f.name]) for f in dataclasses.fields(cls)}


def add_arguments(parser: argparse.ArgumentParser, cfg) -> None:
    """Add one ``--name`` option per field of dataclass instance ``cfg`` (default: keep the preset).

    A config class may set ``HELP_GROUPS`` (title -> field names) to list some fields apart, below the
    others: research knobs that are off by default read apart from the algorithm's hyperparameters."""
    main = parser.add_argument_group(f"hyperparameters ({type(cfg).__name__}; defaults shown are the preset's)")
    groups = {}  # field name -> its argument group, for the fields listed apart
    for title, names in getattr(type(cfg), "HELP_GROUPS", {}).items():
        group = parser.add_argument_group(title)
        groups.update(dict.fromkeys(names, group))
    types = field_types(type(cfg))
    for f in dataclasses.fields(cfg):
        value = getattr(cfg, f.name)
        shown = (",".join(map(str, value)) or "empty") if isinstance(value, tuple) else value
        groups.get(f.name, main).add_argument(
            f"--{f.name.replace('_', '-')}", dest=f"hp_{f.name}", default=None, type=types[f.name],
            metavar=type(value).__name__.upper(),
            help=f"{f.metadata.get('help', '')} (default: {shown}{_allowed_text(f)})")


def _allowed_text(f: dataclasses.Field) -> str:
    return f"; allowed: {values}" if (values := field_words(f)) else ""


def overrides_from_args(args: argparse.Namespace) -> dict:
    """The hyperparameters the user set on the command line."""
    return {k[3:]: v for k, v in vars(args).items() if k.startswith("hp_") and v is not None}


def apply_overrides(cfg, overrides: dict):
    """A copy of ``cfg`` with ``overrides`` applied; unknown names are a :class:`UserError`."""
    names = {f.name for f in dataclasses.fields(cfg)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        import difflib

        near = [match for name in unknown for match in difflib.get_close_matches(name, names, n=1)]
        guess = f"did you mean {flag(near[0])}? " if len(unknown) == 1 and near else ""
        raise UserError(f"unknown hyperparameter(s) {', '.join(unknown)} for {type(cfg).__name__}; "
                        f"{guess}known: {', '.join(sorted(names))}")
    return dataclasses.replace(cfg, **overrides)


def to_dict(cfg) -> dict:
    return {k: list(v) if isinstance(v, tuple) else v for k, v in dataclasses.asdict(cfg).items()}


def from_dict(cls, data: dict):
    """Rebuild a config from :func:`to_dict` output (e.g. from a ``meta.json``)."""
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name in data:
            value = data[f.name]
            kwargs[f.name] = tuple(value) if typing.get_origin(hints[f.name]) is tuple else value
    return cls(**kwargs)


def defining_fields(cfg, env_fields: tuple[str, ...] = ()) -> list[str]:
    """The fields that say what a run is: its env (``env_fields``, the time limit) and its networks
    (fields declared with ``defines_run``)."""
    return [f.name for f in dataclasses.fields(cfg) if f.metadata.get("defines_run") or f.name in env_fields]


def check_same_run(recorded, overrides: dict, env_fields: tuple[str, ...], run_dir) -> None:
    """A resume may change budgets, rates, coefficients and logging, not what the run is: an override
    of a defining field with another value than the recorded one is a :class:`UserError`."""
    defines = {f.name: f.metadata.get("defines_run") for f in dataclasses.fields(recorded)}
    for name in defining_fields(recorded, env_fields):
        if name in overrides and not _same_value(name, overrides[name], getattr(recorded, name)):
            what = defines[name] if isinstance(defines[name], str) else "the env or the networks"
            raise UserError(f"{setting(name, overrides[name])} cannot change on a resume: the run in {run_dir} was recorded with "
                            f"{name} = {_shown(getattr(recorded, name))}, and it defines {what}; start a new run "
                            "to change it")


def check_no_inert(cfg, given) -> None:
    """A flag given on the command line that does nothing with the others is a :class:`UserError`
    (the config's ``inert_fields()``: field -> why it does nothing)."""
    inert = getattr(cfg, "inert_fields", lambda: {})()
    for name in sorted(set(given) & set(inert)):
        raise UserError(f"{flag(name)} does nothing here: {inert[name]}")


#: fields that hold a folder: equal when both name the same folder (``./a/``, ``a``, ``/abs/a``)
PATH_FIELDS = ("init_from",)


def as_recorded(recorded, overrides: dict) -> dict:
    """``overrides`` with each folder that names the recorded one written as it was recorded, so a resume
    given ``./a/`` for ``a`` changes nothing (nor records a change)."""
    return {name: getattr(recorded, name) if name in PATH_FIELDS and _same_value(name, value, getattr(recorded, name))
            else value for name, value in overrides.items()}


def _same_value(name: str, given, recorded) -> bool:
    if given == recorded:
        return True
    return bool(name in PATH_FIELDS and given and recorded
                and os.path.realpath(given) == os.path.realpath(recorded))


def _shown(value) -> str:
    if value == "":
        return "(empty)"
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def change_text(name: str, before, after) -> str:
    """``lr 0.0005 -> 0.00025``, ``max_env_steps 1,000,000 -> 2,000,000``: one hyperparameter a resume changed."""
    def shown(value) -> str:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return str(value)
        return f"{value:,}" if isinstance(value, int) else f"{value:.3g}"
    return f"{name} {shown(before)} -> {shown(after)}"


def resuming_changes(changes: dict) -> str:
    """``; changing lr 0.0005 -> 0.00025``: what a resume changes (``RunSpec.changes``), for the line that
    announces it; "" when it changes nothing."""
    if not changes:
        return ""
    return "; changing " + ", ".join(change_text(name, *values) for name, values in changes.items())
