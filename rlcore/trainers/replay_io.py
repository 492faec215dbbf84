"""Checkpoint and resume for the off-policy trainers (DQN family, SAC): weights, optimizers, RNG,
counters and the whole replay memory in one atomic file."""
from __future__ import annotations

import numpy as np

from rlcore.checkpoint import load_checkpoint, save_checkpoint
from rlcore.replay import ReplayMemory
from rlcore.trainers.session import TrainingSession
from rlcore.trainers.spec import RunSpec, check_resumable


def resume(spec: RunSpec, agent, memory: ReplayMemory, rng: np.random.Generator) -> tuple[dict | None, dict]:
    """For a resumed run: restore the agent, optimizers, replay and RNG; return (state, arrays)."""
    if not spec.resume:
        return None, {}
    check_resumable(spec)
    state, arrays = load_checkpoint(spec.run_dir / "checkpoint.npz", agent.models(), agent.optimizers())
    memory.load_state_dict({k[len("replay/"):]: v for k, v in arrays.items() if k.startswith("replay/")})
    rng.bit_generator.state = state["rng"]
    return state, arrays


def save(session: TrainingSession, agent, memory: ReplayMemory, rng: np.random.Generator, **counters) -> None:
    save_checkpoint(session.checkpoint_path, agent.models(), agent.optimizers(),
                    session.state(rng=rng.bit_generator.state, **counters),
                    {**{f"replay/{k}": v for k, v in memory.state_dict().items()}, **session.best_arrays()})
