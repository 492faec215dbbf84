#!/usr/bin/env python3
"""Replay memories for Atari frames, one JSON line per measurement (numpy only, no TensorFlow, ~1 min).

  python benchmarks/replay.py                    # 100,000 transitions of 84 x 84 x 4 frames
  python benchmarks/replay.py --capacity 20000   # smaller, for a machine with less free memory

Measurements, for the frame memory (each frame kept once) and the full one (two stacks per transition):
  bytes        what the memory's arrays take, allocated in full
  add_us       microseconds per transition added (episodes of 800 steps)
  sample_ms    milliseconds per minibatch of 32 x 4 (DQN's updates_per_call), the memory full
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from common import emit  # noqa: E402

from rlcore.algorithms.replay import FrameStackReplay, ReplayMemory  # noqa: E402

SHAPE, EPISODE = (84, 84, 4), 800


def fill(memory, transitions: int) -> float:
    """Seconds to add ``transitions`` stacked observations in episodes of :data:`EPISODE` steps."""
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 256, (64, *SHAPE[:2]), dtype=np.uint8)  # reused: speed, not content, is measured
    start = time.perf_counter()
    obs = np.stack([frames[0]] * 4, axis=-1)
    for step in range(transitions):
        if step % EPISODE == 0:
            obs = np.stack([frames[step % 64]] * 4, axis=-1)
        next_obs = np.concatenate([obs[..., 1:], frames[(step + 1) % 64][..., None]], axis=-1)
        memory.add(obs, step % 6, 0.0, next_obs, 0.0)
        obs = next_obs
    return time.perf_counter() - start


def sample_ms(memory, repeats: int = 50) -> float:
    rng = np.random.default_rng(1)
    start = time.perf_counter()
    for _ in range(repeats):
        memory.sample_stacked(4, 32, rng)
    return (time.perf_counter() - start) / repeats * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--capacity", type=int, default=100_000)
    capacity = parser.parse_args().capacity
    for name, memory in (("frames", FrameStackReplay(capacity, SHAPE)),
                         ("full", ReplayMemory(capacity, SHAPE, np.uint8))):
        seconds = fill(memory, capacity + capacity // 10)  # past full: the ring has wrapped
        emit(memory=name, capacity=capacity, bytes=memory.nbytes, add_us=round(seconds / (capacity * 1.1) * 1e6, 1),
             sample_ms=round(sample_ms(memory), 2))
        del memory


if __name__ == "__main__":
    main()
