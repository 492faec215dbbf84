"""What a run's records say of the commands that made it (meta.json's or a checkpoint's ``commands`` and
``command_starts``): where each began (env step, CPU, what a resume changed), and the CPUs the run
trained on. TensorFlow-free."""
from __future__ import annotations

from itertools import groupby


def cpus_text(meta: dict) -> str | None:
    """The CPUs a run trained on: where its commands recorded theirs (from 2026-11-29 on) and a resume moved
    the run to another CPU, each with where it took over: ``AMD EPYC (...); Intel Xeon (...) from 614,400 env
    steps``, and "not recorded" for the commands before the first that recorded one (a run begun with older
    code); where none did, meta.json's ``cpu`` (the last command's machine)."""
    cpus = [(int((start or {}).get("env_steps", 0)), (start or {}).get("cpu")) for start in command_starts(meta)]
    if not any(cpu for _, cpu in cpus):
        return meta.get("cpu")
    changes = [next(same) for _, same in groupby(cpus, key=lambda start: start[1])]  # where the CPU changed
    return "; ".join((cpu or "not recorded") + ("" if i == 0 else f" from {steps:,} env steps")
                     for i, (steps, cpu) in enumerate(changes))


def command_starts(record: dict) -> list:
    """A run's ``command_starts`` (meta.json's or a checkpoint's), one per command it records: None for
    the commands of records from before 2026-11-27, which did not keep it."""
    starts = list(record.get("command_starts") or [])
    commands = record.get("commands") or []
    return [None] * (len(commands) - len(starts)) + starts
