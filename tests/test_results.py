"""The README's "IQM [95% CI] over 5 seeds" figures are recomputed from the sweep results git keeps
(`results/sweeps/NAME`, written by `main.py report SWEEP --keep`), so a figure cannot drift from its
runs, and the runs cannot go missing from a clone."""
import pytest

from rlcore.report import load_runs, summarize
from tests.test_cli import ROOT

KEPT = ROOT / "results" / "sweeps"
SWEPT = sorted(p.parent.name for p in KEPT.glob("*/sweep.json"))


def test_the_kept_sweeps_are_in_the_clone():
    assert {"cartpole__dqn", "cartpole__a2c", "lunar_lander__dqn"} <= set(SWEPT)


@pytest.mark.parametrize("name", SWEPT)
def test_the_readme_quotes_each_kept_sweeps_iqm_and_interval(name):
    runs = load_runs(KEPT / name)
    assert sorted(r["seed"] for r in runs) == [0, 1, 2, 3, 4]
    iqm, lo, hi = summarize([KEPT / name], reps=5000)["sweeps"][0]["aggregates"]["iqm"]  # as `report`
    readme = (ROOT / "README.md").read_text()
    assert f"{iqm:.1f} [{lo:.1f}, {hi:.1f}]" in readme, f"{name}: IQM {iqm:.1f} [{lo:.1f}, {hi:.1f}]"
