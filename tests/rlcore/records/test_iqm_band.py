"""The report's IQM band over a curve against rliable's own IQM, one resample and one point at a time."""
import numpy as np
import pytest

from rlcore.records.report_plots import _iqm_band

metrics = pytest.importorskip("rliable.metrics")


def test_the_band_is_rliables_iqm_of_each_resample_of_whole_runs():
    curves = np.random.default_rng(7).normal(100.0, 30.0, (5, 12))  # 5 runs, 12 points
    reps = 300
    iqm, low, high = _iqm_band(curves, reps, seed=3)
    # the reference: the same resamples of runs, rliable's aggregate_iqm at each point of each
    rows = np.random.default_rng(3).integers(0, 5, (reps, 5))
    draws = np.array([[metrics.aggregate_iqm(curves[r, j:j + 1]) for j in range(12)] for r in rows])
    assert iqm == pytest.approx([metrics.aggregate_iqm(curves[:, j:j + 1]) for j in range(12)], rel=1e-12)
    assert low == pytest.approx(np.percentile(draws, 2.5, axis=0), rel=1e-12)
    assert high == pytest.approx(np.percentile(draws, 97.5, axis=0), rel=1e-12)
    assert all(lo <= mid <= hi for lo, mid, hi in zip(low, iqm, high))


def test_runs_that_agree_give_no_band_and_one_run_its_own_curve():
    same = np.tile(np.linspace(0.0, 1.0, 6), (4, 1))
    iqm, low, high = _iqm_band(same, 200)
    assert iqm == pytest.approx(same[0]) and low == pytest.approx(same[0]) and high == pytest.approx(same[0])
    one = np.array([[3.0, 1.0, 2.0]])
    assert _iqm_band(one, 50) == ([3.0, 1.0, 2.0],) * 3
