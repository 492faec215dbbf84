"""A run's critic read back from metrics.csv (rlcore/critic_trace.py): the running median against a direct
computation, episodes without gradient steps left out, runs without a critic's Q, and what `report` writes
of a sweep whose one critic diverged."""
import json

import numpy as np
import pytest

from rlcore.critic_trace import critic_cell, critic_trace, running_median
from tests.test_cli import run

HEADER = "episode,total_points,av_latest_points,target_ave_scores,env_steps,wall_seconds,critic_loss,q_mean\n"


def _metrics(run_dir, returns, qs):
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / "metrics.csv").write_text(HEADER + "".join(
        f"{i + 1},{r},{r},15.0,{100 * (i + 1)},1.0,0.1,{q}\n" for i, (r, q) in enumerate(zip(returns, qs))))
    return run_dir


def test_the_running_median_is_the_median_of_each_window():
    values = np.random.default_rng(0).normal(size=57)
    for window in (1, 5, 20):
        got = running_median(values, window)
        assert got == pytest.approx([np.median(values[max(0, i - window + 1):i + 1]) for i in range(57)])


def test_episodes_before_the_first_gradient_step_are_left_out_and_the_largest_return_is_any_episodes(tmp_path):
    rng = np.random.default_rng(1)
    qs = ["nan", ""] + list(rng.uniform(0, 3, 40))
    returns = [-1.0, 9.5] + list(rng.uniform(-1, 4, 40))
    trace = critic_trace(_metrics(tmp_path / "run", returns, qs))
    assert trace.env_steps.tolist() == [100.0 * i for i in range(3, 43)]
    assert trace.q_end == pytest.approx(np.median(np.array(qs[-20:], dtype=float)))
    assert trace.largest_return == 9.5  # an episode before learning started still paid its return
    assert critic_cell(trace) == f"{trace.q_end:.2f} (largest return 9.50)"


def test_runs_that_log_no_q_have_no_trace(tmp_path):
    a2c = tmp_path / "a2c"
    a2c.mkdir()
    (a2c / "metrics.csv").write_text("episode,total_points,env_steps,critic_loss\n1,5.0,100,0.3\n")
    assert critic_trace(a2c) is None and critic_trace(tmp_path / "missing") is None
    assert critic_trace(_metrics(tmp_path / "early", [1.0, 2.0], ["nan", "nan"])) is None
    assert critic_cell(None) == "–"


def test_a_report_sets_a_diverged_critic_beside_the_returns_it_was_paid(tmp_path, capsys):
    sweep = tmp_path / "toy__sac"
    for seed, q_end in enumerate((1.2, 1.1, 3000.0)):
        run_dir = _metrics(sweep / f"seed={seed}", [0.5, 4.0, 6.25] * 10, np.geomspace(0.2, q_end, 30))
        (run_dir / "model").mkdir()
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 3000, "wall_seconds": 2.0, "evaluation": {"episodes": 30, "mean": 10.0 - seed}}))
    code, out, err = run(capsys, "report", str(sweep), "--reps", "200")
    assert code == 0, err
    report = (sweep / "report.md").read_text()
    ends = [np.median(np.geomspace(0.2, q, 30)[-20:]) for q in (1.2, 1.1, 3000.0)]
    assert f"- seed=0: {ends[0]:.2f} (largest return 6.25)" in report
    assert f"- seed=2: {ends[2]:,.0f} (largest return 6.25)" in report
    assert (sweep / "report_critic.png").stat().st_size > 0


def test_a_report_of_runs_without_a_critics_q_says_nothing_of_it(tmp_path, capsys):
    sweep = tmp_path / "toy__a2c"
    for seed in range(2):
        run_dir = sweep / f"seed={seed}"
        (run_dir / "model").mkdir(parents=True)
        (run_dir / "metrics.csv").write_text("episode,total_points,av_latest_points,env_steps\n1,1.0,1.0,10\n"
                                             "2,3.0,2.0,1000\n")
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 1000, "wall_seconds": 2.0, "evaluation": {"episodes": 5, "mean": 3.0 + seed}}))
    code, _, err = run(capsys, "report", str(sweep), "--reps", "200")
    assert code == 0, err
    assert "Critic" not in (sweep / "report.md").read_text() and not (sweep / "report_critic.png").exists()
