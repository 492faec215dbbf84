"""The statistics of ``main.py report``, as rliable (Agarwal et al. 2021) defines them: mean, median and
interquartile mean (IQM) of runs' final scores, each with a 95 % stratified percentile bootstrap interval,
and the probability that one group's runs beat another's.

The aggregates and the probability of improvement are rliable's own (``rliable.metrics``); the bootstrap
is written here because ``rliable.library`` calls ``arch``, and neither arch 7 (it fails to import with
pandas 3) nor arch 8 (it no longer takes rliable's ``random_state`` argument) works with it on Python 3.13
today. TensorFlow-free.
"""
from __future__ import annotations

import numpy as np

from rlcore.host.extras import require

AGGREGATES = ("mean", "median", "iqm")


def aggregates(scores: np.ndarray) -> np.ndarray:
    """[mean, median, IQM] of a (runs, tasks) score matrix.

    The mean and IQM are rliable's. The median is the median over runs of each run's mean over
    tasks: rliable's ``aggregate_median`` is the median over *tasks* of the per-task means, which
    for the single task of a sweep group is just the mean again.
    """
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return np.array([metrics.aggregate_mean(scores), float(np.median(scores.mean(axis=1))),
                     metrics.aggregate_iqm(scores)])


def stratified_bootstrap_ci(statistic, *matrices: np.ndarray, reps: int = 5000, level: float = 0.95,
                            seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval of ``statistic(*matrices)`` under rliable's stratified bootstrap.

    Each matrix is (runs, tasks); a resample draws, for every task separately, as many runs with
    replacement as there are (the strata are the tasks). Returns ``(point, [low, high])``.
    """
    rng = np.random.default_rng(seed)
    point = np.asarray(statistic(*matrices))
    draws = []
    for _ in range(reps):
        resampled = []
        for m in matrices:
            runs, tasks = m.shape
            rows = rng.integers(0, runs, (runs, tasks))
            resampled.append(np.take_along_axis(m, rows, axis=0))
        draws.append(statistic(*resampled))
    tail = (1 - level) / 2 * 100
    return point, np.percentile(np.asarray(draws), [tail, 100 - tail], axis=0)


def probability_of_improvement(x: np.ndarray, y: np.ndarray) -> float:
    """P(a run of X scores above a run of Y), ties counting half (rliable's definition)."""
    metrics = require("rliable.metrics", "A sweep report")  # the sweep extra

    return float(metrics.probability_of_improvement(x, y))
