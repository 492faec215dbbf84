"""A run's critic read back from metrics.csv (rlcore/records/critic_trace.py): the running median against a direct
computation, episodes without gradient steps left out, runs without a critic's Q, and what `report` writes
of a sweep whose one critic diverged."""
import json

import numpy as np
import pytest

from rlcore.records.critic_trace import critic_cell, critic_trace, running_median
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
    assert trace.largest_return == pytest.approx(9.5)  # an episode before learning started still paid its return
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


def test_rows_without_env_steps_are_skipped_and_a_run_without_returns_says_so(tmp_path):
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "metrics.csv").write_text("episode,env_steps,q_mean\n1,100,12.25\n2,,40.0\n3,300,14.75\n")
    trace = critic_trace(run_dir)
    assert trace.env_steps.tolist() == [100.0, 300.0] and trace.q_end == pytest.approx(13.5)
    assert critic_cell(trace) == "13.5 (largest return –)"  # a value from 10 to 100: one decimal


def _sweep_of_mixed_runs(folder):
    """Three finished runs with periodic evaluations; seeds 0 and 2 log Q, seed 1 does not."""
    for seed in range(3):
        run_dir = folder / f"seed={seed}"
        if seed == 1:
            run_dir.mkdir(parents=True)
            (run_dir / "metrics.csv").write_text("episode,total_points,av_latest_points,env_steps\n1,2.0,2.0,100\n"
                                                 "2,4.0,3.0,200\n")
        else:
            _metrics(run_dir, [1.0, 2.0, 7.5], [0.5, 1.0, 1.5 + 1000 * seed])
        (run_dir / "model").mkdir()
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "experiment": "cartpole", "algo": "dqn", "seed": seed, "env_steps": 300, "wall_seconds": 2.0,
            "evaluation": {"episodes": 30, "mean": 100.0 + seed}}))
        (run_dir / "evals.csv").write_text("env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
                                           "100,1,10.0,1.0,0.0\n200,2,20.0,1.0,0.0\n")
    return folder


def test_a_sweep_whose_runs_log_q_and_runs_that_do_not_shows_each_that_does(tmp_path, capsys):
    sweep = _sweep_of_mixed_runs(tmp_path / "mixed")
    (sweep / "report_critic.png").write_bytes(b"an earlier report's figure")
    code, _, err = run(capsys, "report", str(sweep), "--reps", "200")
    assert code == 0, err
    report = (sweep / "report.md").read_text()
    assert "- seed=0: 1.00 (largest return 7.50)" in report and "- seed=1: –" in report
    assert "- seed=2: 1.00 (largest return 7.50)" in report  # the median of 0.5, 1.0 and 2,001.5
    assert (sweep / "report_critic.png").read_bytes().startswith(b"\x89PNG")
    for seed in (0, 2):  # without the Q-learners, nothing to draw: the earlier figure goes
        (sweep / f"seed={seed}" / "metrics.csv").write_text("episode,total_points,av_latest_points,env_steps\n"
                                                          "1,2.0,2.0,100\n")
    code, _, err = run(capsys, "report", str(sweep), "--reps", "200")
    assert code == 0, err
    assert not (sweep / "report_critic.png").exists() and "Critic" not in (sweep / "report.md").read_text()


def test_the_docs_table_of_a_mixed_sweep_gives_each_seeds_critic_or_a_dash(tmp_path, monkeypatch):
    from rlcore.environments.registry import get_experiment
    from tools.docgen import data as docgen_data
    from tools.docgen import main as docgen  # imported before REPO moves

    _sweep_of_mixed_runs(tmp_path / "results" / "sweeps" / "cartpole__dqn")
    monkeypatch.setattr(docgen_data, "REPO", tmp_path)
    kept = docgen_data.Sweep("results/sweeps/cartpole__dqn", [(0, 100.0), (1, 101.0), (2, 102.0)], {})
    model = docgen_data.Model("cartpole", "dqn", "saved_networks/cartpole/dqn",
                              {"algo": "dqn", "seed": 0, "evaluation": {"episodes": 100, "mean": 500.0}},
                              get_experiment("cartpole").bar("dqn"), kept)
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [model])
    rows = [line for line in docgen.render("regions/sweep-stability.md", page="docs/x.md", arg="cartpole").splitlines()
            if line.startswith("| ")]
    assert rows[0].endswith("| critic at the end: mean Q |") and rows[1].count("|") == rows[0].count("|")
    cells = {row.split("|")[1].strip(): row.split("|")[-2].strip() for row in rows[2:]}
    assert cells == {"0": "1.00 (largest return 7.50)", "1": "–", "2": "1.00 (largest return 7.50)"}
