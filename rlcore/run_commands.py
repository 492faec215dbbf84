"""What a run's records say of the commands that made it (meta.json's or a checkpoint's ``commands`` and
``command_starts``): where each began (env step, CPU, what a resume changed), and the CPUs the run
trained on. TensorFlow-free."""
from __future__ import annotations


def cpus_text(meta: dict) -> str | None:
    """The CPUs a run trained on: meta.json's ``cpu`` (the last command's machine), or where its commands
    recorded theirs (from 2026-11-29 on) and a resume moved the run to another CPU, each with where it
    took over: ``AMD EPYC (...); Intel Xeon (...) from 614,400 env steps``."""
    changes: list[tuple[int, str]] = []
    for start in command_starts(meta):
        cpu = (start or {}).get("cpu")
        if cpu and (not changes or changes[-1][1] != cpu):
            changes.append((int(start.get("env_steps", 0)), cpu))
    if len(changes) < 2:
        return meta.get("cpu") or (changes[0][1] if changes else None)
    return "; ".join(cpu if i == 0 and steps == 0 else f"{cpu} from {steps:,} env steps"
                     for i, (steps, cpu) in enumerate(changes))


def command_starts(record: dict) -> list:
    """A run's ``command_starts`` (meta.json's or a checkpoint's), one per command it records: None for
    the commands of records from before 2026-11-27, which did not keep it."""
    starts = list(record.get("command_starts") or [])
    commands = record.get("commands") or []
    return [None] * (len(commands) - len(starts)) + starts
