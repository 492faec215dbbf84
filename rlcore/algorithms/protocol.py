"""What the shared plumbing may call on any agent.

Checkpoints (``rlcore.training.checkpoints``) save and restore an agent's Keras models and optimizers
by name and then refresh its acting copy; the end of a run (``TrainingSession.conclude``) saves its
model files. Those four calls are all that is shared; each trainer also calls its own agent's
algorithm (``act``, ``train_steps``, ``update`` ...), which a reader finds in that agent's one file.
"""
from __future__ import annotations

from pathlib import Path
from typing import Protocol, runtime_checkable


@runtime_checkable
class Agent(Protocol):
    def models(self) -> dict:
        """Keras models by name: what a checkpoint stores (weights) and restores."""

    def optimizers(self) -> dict:
        """Keras optimizers by name: their slots go into the checkpoint beside the models."""

    def sync_policy_weights(self) -> None:
        """Refresh whatever acting copy the agent keeps (a numpy forward pass) after its weights were set."""

    def save(self, folder: str | Path) -> Path | list[Path]:
        """Write the ``.h5`` model files of a model folder; return their paths."""
