"""The machine a number was computed on, and whether a record replays exactly here.

A seed repeats a run or an evaluation bit for bit only on the same CPU family and package versions:
TensorFlow's oneDNN kernels order float sums by the CPU's vector units, so on another CPU a greedy
argmax or a sampled action can flip and an episode take another course (seen: the shipped Minitaur
model's first episodes returned 22.86 on an Intel Xeon with AMX against 22.48 recorded on an AMD
EPYC). The same holds for one CPU with oneDNN turned off (``TF_ENABLE_ONEDNN_OPTS=0``: 22.82 here
against 22.48 with it on, 2026-11-27). A record is replayed exactly only where :func:`replays_exactly`
says so; elsewhere callers check what holds on every machine (a bar, a statistical bound).
"""
from __future__ import annotations

import os
import platform

from rlcore.host.cpu import cpu_description

# the distributions whose versions a run's or an evaluation's numbers depend on (those installed)
NUMERIC_PACKAGES = ("tensorflow", "tensorflow-cpu", "keras", "gymnasium", "numpy", "box2d", "nes-py",
                    "gym-super-mario-bros", "pybullet")


def package_versions() -> dict:
    """Versions of Python and of the packages a run's numbers depend on (those installed)."""
    from importlib.metadata import PackageNotFoundError, version

    found = {"python": platform.python_version()}
    for dist in NUMERIC_PACKAGES:
        try:
            found[dist] = version(dist)
        except PackageNotFoundError:
            pass
    return found


# the settings a record made without saying (every one before 2026-11-27) was made with: TensorFlow's
# defaults on x86-64 Linux
DEFAULT_SETTINGS = {"onednn": True}


# environment variables that change TensorFlow's or XLA's float results on one CPU when set (XLA's
# fast-math and kernel choices, which SAC's XLA-compiled update and any jit_compile model read;
# TensorFlow's deterministic ops; oneDNN's instruction-set cap, which picks other kernels, as a CPU
# without AVX-512 would, and its default float math mode, which may let f32 work run in bfloat16):
# recorded by value, and only where set, so that a record made with them unset, as every record before
# 2026-11-27 was, compares equal with a process where they are unset
NUMERIC_VARIABLES = ("XLA_FLAGS", "TF_XLA_FLAGS", "TF_DETERMINISTIC_OPS", "ONEDNN_MAX_CPU_ISA", "DNNL_MAX_CPU_ISA",
                     "ONEDNN_DEFAULT_FPMATH_MODE")


def numeric_settings() -> dict:
    """This process's environment settings that change TensorFlow's numbers on one CPU: whether its
    oneDNN kernels are on (``TF_ENABLE_ONEDNN_OPTS``, read as TensorFlow reads it), and the
    :data:`NUMERIC_VARIABLES` that are set."""
    onednn = os.environ.get("TF_ENABLE_ONEDNN_OPTS", "1").strip().lower() not in ("0", "false")
    return {"onednn": onednn, **{name: os.environ[name] for name in NUMERIC_VARIABLES if os.environ.get(name)}}


def this_machine() -> dict:
    """``{"cpu": ..., "versions": {...}, "settings": {...}}`` of this process, as meta.json records them."""
    return {"cpu": cpu_description(), "versions": package_versions(), "settings": numeric_settings()}


def recorded_machine(meta: dict) -> dict | None:
    """Where a model folder's evaluation was computed: the evaluation's own ``machine`` (written since
    2026-11-27), else the training run's ``cpu`` and ``versions`` (the final evaluation ran in the same
    process); None when the record does not say which CPU (older models)."""
    machine = (meta.get("evaluation") or {}).get("machine")
    if machine:
        return machine
    if meta.get("cpu") and meta.get("versions"):
        return {"cpu": meta["cpu"], "versions": meta["versions"]}
    return None


def replays_exactly(recorded: dict | None, here: dict | None = None) -> bool:
    """Whether a record made on ``recorded`` can be expected to repeat bit for bit on ``here`` (default
    this machine): the same CPU description (name and vector units), the same numeric settings (a record
    without them was made with the defaults) and every recorded package at the same version. Unknown
    is no."""
    if not recorded:
        return False
    here = this_machine() if here is None else here
    if recorded.get("cpu") != here.get("cpu"):
        return False
    if recorded.get("settings", DEFAULT_SETTINGS) != here.get("settings", DEFAULT_SETTINGS):
        return False
    versions = here.get("versions", {})
    return all(versions.get(name) == value for name, value in recorded.get("versions", {}).items())


def available_memory() -> int | None:
    """Bytes of memory the system can give a process without swapping (Linux's MemAvailable); None where
    it cannot be read."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None
