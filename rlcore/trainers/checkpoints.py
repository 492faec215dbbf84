"""A run's checkpoint: weights, optimizers, RNG, the session's counters, the trainer's own counters,
kept best weights and (off-policy trainers) the whole replay memory, in one atomic file. Every
trainer saves and restores through these two functions."""
from __future__ import annotations

import numpy as np

from rlcore.checkpoint import load_checkpoint, save_checkpoint
from rlcore.replay import ReplayMemory
from rlcore.trainers.session import TrainingSession
from rlcore.trainers.spec import CHECKPOINT_FILE, RunSpec, check_resumable


def restore(spec: RunSpec, agent, rng: np.random.Generator,
            memory: ReplayMemory | None = None) -> tuple[dict | None, dict]:
    """For a resumed run: put back the agent's weights and optimizers, the RNG and the replay memory;
    return ``(state, arrays)``. For a new run: ``(None, {})``."""
    if not spec.resume:
        return None, {}
    check_resumable(spec)
    state, arrays = load_checkpoint(spec.run_dir / CHECKPOINT_FILE, agent.models(), agent.optimizers())
    if memory is not None:
        memory.load_state_dict({k[len("replay/"):]: v for k, v in arrays.items() if k.startswith("replay/")})
    rng.bit_generator.state = state["rng"]
    agent.sync_policy_weights()  # the numpy acting copy, where the agent keeps one
    return state, arrays


def save(session: TrainingSession, agent, rng: np.random.Generator, memory: ReplayMemory | None = None,
         **counters) -> None:
    """Write the checkpoint; ``counters``: the trainer's own (epsilon, grad_steps, rollouts, ...)."""
    replay = {f"replay/{k}": v for k, v in memory.state_dict().items()} if memory is not None else {}
    save_checkpoint(session.checkpoint_path, agent.models(), agent.optimizers(),
                    session.state(rng=rng.bit_generator.state, **counters), {**replay, **session.best_arrays()})
