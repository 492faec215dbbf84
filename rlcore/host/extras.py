"""Optional parts of the package: a module that an extra brings, or one clear line on how to get it.

``pip install -e .`` alone trains LunarLander, CartPole and any Gymnasium env. Mario, Minitaur,
sweeps and exports need more (setup.cfg's ``[options.extras_require]``); code that needs one of
those modules imports it through :func:`require`, so a missing extra is a :class:`UserError`
(``main.py`` prints it as one line, exit status 2) instead of a ``ModuleNotFoundError`` traceback.
"""
from __future__ import annotations

import importlib
from types import ModuleType

from rlcore.errors import UserError

#: the extra that brings each optional top-level module (setup.cfg's extras_require)
EXTRA_OF = {
    "nes_py": "mario", "gym_super_mario_bros": "mario", "cv2": "mario",
    "pybullet": "minitaur", "pybullet_data": "minitaur", "pybullet_utils": "minitaur",
    "ale_py": "atari", "mujoco": "mujoco",
    "ray": "sweep", "rliable": "sweep",
    "tf2onnx": "export", "onnx": "export", "onnxruntime": "export", "ai_edge_litert": "export",
}


def install_command(extra: str) -> str:
    """The exact command that installs ``extra`` into a checkout of this repository."""
    return f"pip install -e '.[{extra}]'"


def missing_extra_message(what: str, extra: str) -> str:
    return f"{what} needs the {extra} extra: {install_command(extra)}"


def require(module: str, what: str, extra: str | None = None) -> ModuleType:
    """Import ``module`` (e.g. ``"cv2"`` or ``"rliable.metrics"``) and return it.

    If it (or the top-level package it lives in) is not installed, raise :class:`UserError` with one
    line such as ``Mario needs the mario extra: pip install -e '.[mario]'``. ``what`` names the
    feature that needs it; ``extra`` defaults to the one :data:`EXTRA_OF` names for the module.
    An ImportError raised for another reason (a broken install) propagates unchanged.
    """
    top = module.split(".")[0]
    extra = extra or EXTRA_OF[top]
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        missing = exc.name or ""
        if missing == top or missing.startswith(top + ".") or module.startswith(missing + "."):
            raise UserError(missing_extra_message(what, extra)) from None
        raise


# ------------------------------------------------- what an experiment package needs beyond the core
_EXPERIMENT_NEEDS: dict[str, tuple[str, str, tuple[str, ...]]] = {}


def declare(experiment: str, what: str, extra: str, modules: tuple[str, ...]) -> None:
    """An experiment package says which extra its env needs (``mario_ppo``: the mario extra), so a
    command can check it before any run folder exists
    (:func:`rlcore.environments.registry.require_experiment`)."""
    _EXPERIMENT_NEEDS[experiment] = (what, extra, tuple(modules))


def experiment_needs(experiment: str) -> tuple[str, str, tuple[str, ...]]:
    """(what, extra, modules) an experiment package declared; empty for one that needs nothing more."""
    return _EXPERIMENT_NEEDS.get(experiment, ("", "", ()))
