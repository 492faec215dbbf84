"""Drawing actions from a batch of categorical distributions in numpy (fast, and seeded by our RNG)."""
from __future__ import annotations

import numpy as np


def softmax(logits: np.ndarray) -> np.ndarray:
    z = np.asarray(logits, np.float64)
    z = z - z.max(axis=1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=1, keepdims=True)


def sample_categorical(probs: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One action per row of ``probs`` (rows need not be exactly normalized)."""
    cdf = np.cumsum(probs, axis=1)
    draws = rng.random((len(cdf), 1)) * cdf[:, -1:]
    return np.minimum((draws > cdf).sum(axis=1), probs.shape[1] - 1).astype(np.int32)
