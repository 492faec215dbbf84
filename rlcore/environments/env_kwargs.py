"""``--env-kwargs`` / ``env_kwargs=``: arguments for a Gymnasium env's constructor (RL Zoo's
``--env-kwargs``, SB3's ``env_kwargs``), e.g. ``continuous=True`` for LunarLander-v3. Given as a JSON object
or as ``key=value`` pairs; each key is checked against the parameters the env's entry point takes before
any run folder exists, and the arguments are recorded in meta.json (``env.env_kwargs``), so ``evaluate``,
``render``, ``export`` and ``api.load`` rebuild the same env."""
from __future__ import annotations

import inspect
import json

from rlcore.errors import UserError


def parse_env_kwargs(text: str) -> dict:
    """``'{"continuous": true}'`` or ``'continuous=True enable_wind=true wind_power=5'`` (commas work too)
    -> a dict; each value read as JSON (``True``/``False``/``None`` as Python writes them), else a string."""
    text = text.strip()
    if text.startswith("{"):
        try:
            given = json.loads(text)
        except json.JSONDecodeError as exc:
            raise UserError(f"--env-kwargs {text!r} is not a JSON object ({exc.msg}); give JSON or key=value pairs") from None
        if not isinstance(given, dict):
            raise UserError(f"--env-kwargs {text!r} is not a JSON object")
        return given
    out = {}
    for pair in text.replace(",", " ").split():
        key, sep, value = pair.partition("=")
        if not sep or not key.isidentifier():
            raise UserError(f"--env-kwargs: {pair!r} is not key=value (e.g. continuous=True, or a JSON object)")
        out[key] = _value(value)
    return out


def _value(text: str):
    python = {"True": True, "False": False, "None": None}
    if text in python:
        return python[text]
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def env_creator(env_id: str):
    """What the registered id's entry point names: the env class or the function that builds it."""
    import gymnasium as gym
    from gymnasium.envs.registration import load_env_creator

    entry_point = gym.spec(env_id).entry_point
    return load_env_creator(entry_point) if isinstance(entry_point, str) else entry_point


def check_env_kwargs(env_id: str, kwargs: dict) -> None:
    """Each key a parameter the env's entry point takes (any, when it takes ``**kwargs``); one line else."""
    if "render_mode" in kwargs:
        raise UserError("--env-kwargs: render_mode is set by the command (render, video), not given")
    creator = env_creator(env_id)
    try:
        parameters = inspect.signature(creator).parameters
    except (TypeError, ValueError):  # a builtin: only trying tells
        return
    if any(p.kind is p.VAR_KEYWORD for p in parameters.values()):
        return
    takes = [name for name, p in parameters.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
             and name != "render_mode"]
    unknown = [key for key in kwargs if key not in takes]
    if unknown:
        raise UserError(f"--env-kwargs: {env_id} takes no {', '.join(map(repr, unknown))}; its env takes "
                        f"{', '.join(takes) or 'no arguments'}")
