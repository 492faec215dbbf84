"""A run's checkpoint: weights, optimizers, RNG, the session's counters, the trainer's own counters and
the kept best weights in ``checkpoint.npz``; an off-policy trainer's replay memory beside it in
``replay.npz``. Every trainer saves and restores through these two functions.

The replay memory has its own file because it is large (1M Minitaur transitions: ~260 MB) and git
should not keep it: ``long_runs/`` commits ``checkpoint.npz`` only. A run resumed where its
``replay.npz`` is missing (a clone on another machine), or is from another moment than the checkpoint
(a crash between the two writes), continues with an empty memory, which refills before learning goes
on; it says so in one line.
"""
from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import numpy as np

from rlcore.algorithms.protocol import Agent
from rlcore.algorithms.replay import ReplayMemory
from rlcore.files.atomic import atomic_path
from rlcore.files.checkpoint import load_checkpoint, save_checkpoint
from rlcore.training.session import TrainingSession
from rlcore.training.spec import CHECKPOINT_FILE, RunSpec, check_resumable

REPLAY_FILE = "replay.npz"


def restore(spec: RunSpec, agent: Agent, rng: np.random.Generator,
            memory: ReplayMemory | None = None) -> tuple[dict | None, dict]:
    """For a resumed run: put back the agent's weights and optimizers, the RNG and the replay memory;
    return ``(state, arrays)``. For a new run: ``(None, {})``."""
    if not spec.resume:
        return None, {}
    check_resumable(spec)
    state, arrays = load_checkpoint(spec.run_dir / CHECKPOINT_FILE, agent.models(), agent.optimizers())
    if memory is not None:
        _restore_replay(spec.run_dir, state, arrays, memory)
    rng.bit_generator.state = state["rng"]
    agent.sync_policy_weights()  # the numpy acting copy, where the agent keeps one
    return state, arrays


def save(session: TrainingSession, agent: Agent, rng: np.random.Generator, memory: ReplayMemory | None = None,
         env_arrays: dict | None = None, **counters) -> None:
    """Write the checkpoint (and the replay memory first, stamped with the same env step count);
    ``env_arrays``: what the envs kept (:func:`env_memory`); ``counters``: the trainer's own
    (epsilon, grad_steps, rollouts, ...).

    Both files are written in full before either replaces its predecessor, so a full disk while writing
    either leaves the last good pair in place; the replay memory is moved in after the checkpoint."""
    with contextlib.ExitStack() as pending:
        if memory is not None:
            replay_tmp = pending.enter_context(atomic_path(session.run_dir / REPLAY_FILE))
            with open(replay_tmp, "wb") as f:
                np.savez(f, env_steps=np.array(session.env_steps), **memory.state_dict())
            counters["replay_env_steps"] = session.env_steps
        save_checkpoint(session.checkpoint_path, agent.models(), agent.optimizers(),
                        session.state(rng=rng.bit_generator.state, **counters),
                        {**session.best_arrays(), **(env_arrays or {})})


def env_memory(envs, name: str | None) -> dict:
    """What each env of the pool built up (``Curriculum.memory``), as checkpoint arrays
    ``env/<i>/<key>``; empty when the experiment declares none or the envs do not have it."""
    kept = envs.memory(name) if name else None
    return {f"env/{i}/{key}": np.asarray(value) for i, values in enumerate(kept or [])
            for key, value in values.items()}


def give_env_memory(envs, name: str | None, arrays: dict, share=None, config=None) -> None:
    """Hand each env of a resumed run what it had built up (:func:`env_memory`'s arrays), first
    rewritten by ``share(per_env, config)`` (``Curriculum.share_memory``) when given."""
    if not name:
        return
    per_env = [{} for _ in range(envs.num_envs)]
    for key, value in arrays.items():
        if key.startswith("env/"):
            _, i, inner = key.split("/", 2)
            if int(i) < envs.num_envs:
                per_env[int(i)][inner] = value
    if any(per_env):
        envs.give_memory(name, share(per_env, config) if share else per_env)


def _restore_replay(run_dir: Path, state: dict, arrays: dict, memory: ReplayMemory) -> None:
    inline = {k[len("replay/"):]: v for k, v in arrays.items() if k.startswith("replay/")}
    if inline:  # a checkpoint written when the replay memory was still inside it
        memory.load_state_dict(inline)
        return
    path = run_dir / REPLAY_FILE
    try:
        with np.load(path) as data:
            found = {key: data[key] for key in data.files}
    except (OSError, ValueError) as exc:
        why = "is not there" if not path.exists() else f"is damaged ({type(exc).__name__})"
    else:
        if int(found.pop("env_steps", -1)) == state.get("replay_env_steps"):
            memory.load_state_dict(found)
            return
        why = "is from another moment than the checkpoint"
    print(f"resume: the replay memory {path} {why}; training goes on with an empty one, which refills "
          "before learning resumes", file=sys.stderr)
