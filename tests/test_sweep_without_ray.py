"""Sweeps without a Ray of this module's own: the report's statistics against direct computations and
known answers, its grouping and `--keep`, the sweep command's bad values, a sweep moved to another
folder, a trial killed before its first checkpoint, and SIGTERM to a command-line sweep's whole process
group (that sweep starts its own local Ray). Apart from tests/test_sweep.py so that `make test` can run
them on another worker beside the Ray trials."""
import json
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rlcore.records.bootstrap import aggregates, probability_of_improvement, stratified_bootstrap_ci
from rlcore.records.report import load_runs, summarize
from rlcore.sweeps.sweep import Sweep, parse_grid, parse_seeds
from tests.processes import group_pids, listening, outside_loopback
from tests.test_cli import run
from tests.test_sweep import ROOT, _sweep, _wait_for


def test_bootstrap_ci_on_known_answers():
    constant = np.full((8, 1), 3.0)
    point, ci = stratified_bootstrap_ci(aggregates, constant, reps=200)
    np.testing.assert_allclose(point, 3.0)
    np.testing.assert_allclose(ci, 3.0)
    scores = np.arange(1.0, 101.0)[:, None]
    point, ci = stratified_bootstrap_ci(aggregates, scores, reps=2000)
    np.testing.assert_allclose(point, [50.5, 50.5, 50.5])
    # the mean of 1..100 has standard error 29.01 / 10: the 95% interval is about 50.5 +- 5.7
    assert ci[0][0] == pytest.approx(50.5 - 5.7, abs=0.8) and ci[1][0] == pytest.approx(50.5 + 5.7, abs=0.8)
    # skewed scores, as a 5-seed sweep gives: the median is the middle run, not the mean again
    skewed = np.array([[500.0], [137.0], [500.0], [487.0], [278.0]])
    # the IQM of 5 runs drops one at each end (scipy's trim_mean, as rliable)
    np.testing.assert_allclose(aggregates(skewed), [380.4, 487.0, (278 + 487 + 500) / 3])
    assert probability_of_improvement(scores + 1000, scores) == 1.0
    assert probability_of_improvement(scores, scores) == pytest.approx(0.5)


def test_a_sweep_moved_to_another_folder_resumes_where_it_now_is(tmp_path):
    """A sweep kept in git (long_runs/sweeps/) resumes from a clone in another place."""
    first = _sweep(tmp_path, "here")
    Path(first.folder).mkdir()
    first.save()
    assert "folder" not in json.loads((tmp_path / "here" / "sweep.json").read_text())  # no machine's path kept
    (tmp_path / "here").rename(tmp_path / "there")
    assert Sweep.load(tmp_path / "there").folder == str((tmp_path / "there").resolve())


def test_seeds_and_grid_parsing():
    from rlcore.algorithms.dqn.config import DQNConfig

    assert parse_seeds("0-4") == [0, 1, 2, 3, 4] and parse_seeds("0,3,7") == [0, 3, 7]
    assert parse_grid(["lr=1e-4,3e-4", "hidden=64,64;128"], DQNConfig()) == {
        "lr": [1e-4, 3e-4], "hidden": [(64, 64), (128,)]}


@pytest.mark.parametrize("argv, message", [
    (["sweep", "lunar_lander", "dqn", "--grid", "learning_rate=1e-3"], "'learning_rate' is not a hyperparameter"),
    (["sweep", "lunar_lander", "dqn", "--grid", "gamma=0.9,1.5"], "--gamma 1.5 is invalid"),
    (["sweep", "lunar_lander", "dqn", "--grid", "lr=fast"], "--grid 'lr=fast' is invalid: lr takes a number above 0"),
    (["sweep", "lunar_lander", "dqn", "--grid", "batch_size=1.5"], "batch_size takes a whole number of at least 1"),
    (["sweep", "lunar_lander", "dqn", "--grid", "keep_best=maybe"], "--grid 'keep_best=maybe' is invalid: 'maybe'"),
    (["sweep", "lunar_lander", "dqn", "--seeds", "4-x"], "--seeds '4-x' is invalid"),
    (["sweep", "mario_ppo", "ppo", "--grid", "init_from=saved_networks/mario_ppo/1-1"],
     "a sweep cannot set init_from"),
    (["sweep", "lunar_lander", "dqn", "--seeds", "4-0"], "the range 4-0 runs downward; write 0-4"),
    (["report", "/nonexistent/sweep"], "no sweep folder /nonexistent/sweep"),
    (["sweep", "lunar_lander", "dqn", "--name", "../x"], "argument --name: '../x' is invalid: give a folder name"),
    (["sweep", "lunar_lander", "dqn", "--name", ".."], "argument --name: '..' is invalid"),
])
def test_bad_sweep_values_are_one_line_and_exit_2(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    named = argv[0] == "sweep" and "--name" not in argv
    code, out, err = run(capsys, *argv, "--name", "x") if named else run(capsys, *argv)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "sweeps").exists() and not (tmp_path / "x").exists()


def test_report_groups_a_grid_sweep_by_setting(tmp_path):
    from rlcore.records.report import markdown

    # skewed scores, so mean, median and IQM differ and a mix-up of their names would show
    for lr, scores in (("0.001", (137.0, 278.0, 487.0, 500.0, 500.0)), ("0.01", (600.0, 601.0, 650.0))):
        for seed, score in enumerate(scores):
            model = tmp_path / "grid" / f"lr={lr}__seed={seed}" / "model"
            model.mkdir(parents=True)
            (model / "meta.json").write_text(json.dumps({
                "seed": seed, "env_steps": 100, "wall_seconds": 1.0,
                "evaluation": {"episodes": 5, "mean": score}}))
    result = summarize([tmp_path / "grid"], reps=200)
    labels = [g["label"] for g in result["sweeps"]]
    assert labels == ["grid [lr=0.001]", "grid [lr=0.01]"]
    first = result["sweeps"][0]["aggregates"]
    assert [first[k][0] for k in ("mean", "median", "iqm")] == pytest.approx([380.4, 487.0, 1265 / 3])
    assert all(lo <= point <= hi and lo < hi for point, lo, hi in first.values())
    assert result["sweeps"][1]["aggregates"]["median"][0] == 601.0
    assert result["probability_of_improvement"][0] == 0.0  # every lr=0.001 run below every lr=0.01 run
    text = markdown(result)
    assert "P(grid [lr=0.001] > grid [lr=0.01]) = 0.000" in text
    lo, hi = first["median"][1:]
    assert f"| median | 487.000 | [{lo:.3f}, {hi:.3f}] |" in text and "| mean | 380.400 |" in text


def test_report_keep_copies_what_the_report_reads_and_the_model_and_nothing_else(tmp_path, capsys):
    sweep, kept = tmp_path / "sweeps" / "toy__dqn", tmp_path / "results" / "toy__dqn"
    (sweep).mkdir(parents=True)
    (sweep / "sweep.json").write_text(json.dumps({"experiment": "toy"}))
    for seed, score in enumerate((100.0, 250.0, 300.0)):
        run_dir = sweep / f"seed={seed}"
        (run_dir / "model").mkdir(parents=True)
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 1000 * (seed + 1), "wall_seconds": 2.0, "evaluation": {"episodes": 5, "mean": score}}))
        (run_dir / "metrics.csv").write_text("episode,env_steps,av_latest_points\n1,10,1.0\n2,1000,%s\n" % score)
        (run_dir / "evals.csv").write_text("env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
                                           "1000,2,%s,1.0,0.0\n" % score)
        (run_dir / "checkpoint.npz").write_bytes(b"large")
        (run_dir / "model" / "q_network.h5").write_bytes(b"weights")
        (run_dir / "model" / "toy_Train_dqn.png").write_bytes(b"plot")
    code, out, err = run(capsys, "report", str(sweep), "--keep", str(kept), "--reps", "200")
    assert code == 0, err
    copied = sorted(str(p.relative_to(kept)) for p in kept.rglob("*") if p.is_file())
    per_run = ["evals.csv", "metrics.csv", "model/meta.json", "model/q_network.h5"]
    assert copied == sorted(["report.md", "report_curves.png", "report_evals.png", "sweep.json"]
                            + [f"seed={s}/{name}" for s in range(3) for name in per_run])
    assert not (sweep / "report.md").exists()  # the report is written where the copies are
    again = summarize([kept], reps=200)
    assert again["sweeps"][0]["aggregates"]["mean"][0] == pytest.approx(650.0 / 3)
    assert [r["env_steps"] for r in load_runs(kept)] == [1000, 2000, 3000]
    code, _, err = run(capsys, "report", str(sweep), str(kept), "--keep", str(tmp_path / "other"))
    assert code == 2 and "--keep copies one sweep" in err and not (tmp_path / "other").exists()


def _toy_sweep(folder: Path, scores) -> Path:
    folder.mkdir(parents=True)
    (folder / "sweep.json").write_text(json.dumps({"experiment": "toy"}))
    for seed, score in enumerate(scores):
        (folder / f"seed={seed}" / "model").mkdir(parents=True)
        (folder / f"seed={seed}" / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 100, "wall_seconds": 1.0, "evaluation": {"episodes": 5, "mean": score}}))
        (folder / f"seed={seed}" / "metrics.csv").write_text("episode,env_steps,av_latest_points\n1,100,%s\n" % score)
    return folder


def test_a_report_of_two_sweeps_leaves_each_sweeps_own_report_alone(tmp_path, capsys):
    first, second = _toy_sweep(tmp_path / "a", (1.0, 2.0, 3.0)), _toy_sweep(tmp_path / "b", (4.0, 5.0, 6.0))
    (first / "report.md").write_text("a's own report")
    code, out, err = run(capsys, "report", str(first), str(second), "--reps", "100")
    assert code == 0, err
    assert "P(" in out and "written: nothing" in out and (first / "report.md").read_text() == "a's own report"
    code, out, err = run(capsys, "report", str(first), str(second), "--reps", "100", "--out", str(tmp_path / "both"))
    assert code == 0 and (tmp_path / "both" / "report.md").is_file() and (first / "report.md").read_text() == "a's own report"
    code, _, err = run(capsys, "report", str(first), str(second), "--out", str(second))
    assert code == 2 and "--out" in err and "is one of the sweeps reported" in err and not (second / "report.md").exists()
    assert run(capsys, "report", str(second), "--reps", "100")[0] == 0 and (second / "report.md").is_file()  # one: its own


def test_report_tells_each_runs_collapses_and_which_weights_its_model_holds(tmp_path):
    from rlcore.records.report import markdown

    header = "env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
    for seed, (means, weights) in enumerate((((0.0, 15.0, 0.5, 16.0, 12.0), "best periodic evaluation"),
                                             ((0.0, 8.0, 17.0, 17.5), "best periodic evaluation"),
                                             ((0.0, 10.0, 1.0), "last"))):
        run_dir = tmp_path / "sweep" / f"seed={seed}"
        (run_dir / "model").mkdir(parents=True)
        (run_dir / "model" / "meta.json").write_text(json.dumps({
            "seed": seed, "env_steps": 4000, "wall_seconds": 2.0, "weights": weights,
            "evaluation": {"episodes": 30, "mean": 10.0 + seed, "time_limit_share": 0.9}}))
        (run_dir / "evals.csv").write_text(header + "".join(f"{1000 * (i + 1)},{i},{m},1.0,0.5\n"
                                                            for i, m in enumerate(means)))
    text = markdown(summarize([tmp_path / "sweep"], reps=200))
    assert "| seed=0 | 0 | 10.000 | 90% | 4,000 |" in text
    assert ("2 of 3 runs collapsed at least once (2 collapses, 1 not recovered); in 1 run keep-best mattered: the "
            "model holds an earlier evaluation's weights, which scored above the run's last evaluation.") in text
    assert ("- seed=0: 1 collapse (3,000: 0.50 after 15.00, back by 4,000); model: weights of the best evaluation "
            "(16.00 at 4,000), the last scored 12.00") in text
    assert "- seed=1: 0 collapses; model: weights of the best evaluation (17.50 at 4,000), also the last" in text
    assert "- seed=2: 1 collapse (3,000: 1.00 after 10.00, not recovered); model: the last weights" in text


def _mario_run(folder: Path, seed: int, flags: int, further: int | None = None, resumes: tuple = (),
               init_from: dict | None = None, **config) -> Path:
    """A finished Mario 1-1 run folder as `main.py train mario_ppo ppo --seed S` leaves it, written by hand;
    ``resumes``: what each resume changed (meta.json's ``command_starts[i]["changed"]``, None: not recorded)."""
    (folder / "model").mkdir(parents=True)
    starts = [{"env_steps": 0, "episodes": 0}] + [
        {"env_steps": 500 * i, "episodes": 3 * i, **({} if changed is None else {"changed": changed})}
        for i, changed in enumerate(resumes, 1)]
    meta = {"experiment": "mario_ppo", "algo": "ppo", "preset": "default", "seed": seed, "env_steps": 1000 * (seed + 1),
            "wall_seconds": 10.0, "config": {"world": 1, "stage": 1, "lr": 1e-4, **config},
            "evaluation": {"episodes": 10, "success_share": flags / 10, "seeds": "1000000..1000009"},
            "commands": ["python main.py train mario_ppo ppo"] + ["python main.py train mario_ppo ppo --resume"] * len(resumes),
            "command_starts": starts, "init_from": init_from}
    if further is not None:
        meta["further_evaluations"] = [{"episodes": 30, "success_share": further / 30, "seeds": "1000010..1000039"}]
    (folder / "model" / "meta.json").write_text(json.dumps(meta))
    (folder / "model" / "actor.h5").write_bytes(b"weights")
    (folder / "metrics.csv").write_text("episode,env_steps,av_latest_points,success,success_share\n"
                                        "1,10,1.0,0,0.0\n2,1000,%s,1,0.5\n" % flags)
    (folder / "rollouts.csv").write_text("rollout,env_steps\n1,1000\n")
    (folder / "checkpoint.npz").write_bytes(b"large")
    return folder


def test_single_runs_over_seeds_are_kept_and_reported_as_a_sweep_of_their_level(tmp_path, capsys, monkeypatch):
    """Mario 1-1's seeds are three `train` runs: `report RUN... --keep DIR` keeps them like a sweep (a budget
    given again on a resume may differ), and the docs generator finds them as the sweep of level 1-1."""
    # imported before docgen_data.REPO points at tmp_path below: a module imported while it does would keep it
    from tools.docgen import data as docgen_data
    from tools.docgen import main as docgen

    budget_again = ({"max_env_steps": [10**7, 2 * 10**7]}, {})  # seed 1 resumed twice: a new budget, then nothing
    runs = [str(_mario_run(tmp_path / "long_runs" / f"1-1-seed-{s}", s, flags, further, resumes, max_env_steps=budget))
            for s, flags, further, budget, resumes in ((0, 9, 27, 10**7, ()), (1, 10, None, 2 * 10**7, budget_again),
                                                       (2, 6, 20, 10**7, ()))]
    kept = tmp_path / "results" / "sweeps" / "mario_ppo__1-1"
    code, out, err = run(capsys, "report", *runs, "--keep", str(kept), "--reps", "200")
    assert code == 0, err
    copied = sorted(str(p.relative_to(kept)) for p in kept.rglob("*") if p.is_file())
    assert copied == sorted(["report.md", "report_curves.png", "report_success.png", "sweep.json"]
                            + [f"seed={s}/{name}" for s in range(3)
                               for name in ("metrics.csv", "rollouts.csv", "model/meta.json", "model/actor.h5")])
    sweep = json.loads((kept / "sweep.json").read_text())
    assert (sweep["seeds"], sweep["overrides"], sweep["preset"]) == ([0, 1, 2], {"world": 1, "stage": 1}, "default")
    report = (kept / "report.md").read_text()
    # scored by the flag: the share and the episodes behind it
    assert "| run | seed | flag share (unseen seeds) |" in report
    assert "| seed=2 | 2 | 0.600 (6 of 10) |" in report and "| median | 0.900 |" in report
    assert "- seed=0: 0.900 (27 of 30 episodes)" in report and "- seed=1: none" in report
    monkeypatch.setattr(docgen_data, "REPO", tmp_path)
    found = docgen_data.kept_sweeps()
    assert list(found) == [("mario_ppo", "1-1")] and found[("mario_ppo", "1-1")].seeds == [(0, 0.9), (1, 1.0), (2, 0.6)]
    # the docs' regions for it, beside a shipped 1-1 (flag in 8 of 10); PPO has no periodic evaluations
    from rlcore.environments.registry import get_experiment

    shipped = docgen_data.Model("mario_ppo", "1-1", "saved_networks/mario_ppo/1-1",
                                {"algo": "ppo", "seed": 0, "evaluation": {"episodes": 10, "success_share": 0.8}},
                                get_experiment("mario_ppo").bar("1-1"), found[("mario_ppo", "1-1")])
    monkeypatch.setattr(docgen_data, "shipped_models", lambda: [shipped])
    summary = docgen.render("regions/seed-summary.md", page="README.md", arg="mario_ppo")
    assert ("per seed 0: flag in 9 of 10 after 1,000 env steps, 10 s; 1: flag in 10 of 10 after 2,000 env steps, 10 s; "
            "2: flag in 6 of 10 after 3,000 env steps, 10 s; the shipped model (seed 0, a run of its own) flag in 8 of "
            "10.") in summary and "During training" not in summary
    assert "Bar over seeds: median over 3 seeds >= 80%, every seed >= 50% (" in summary and summary.endswith("): **met**.")
    stability = docgen.render("regions/sweep-stability.md", page="docs/x.md", arg="mario_ppo")
    assert "its runs made no periodic evaluations" in stability
    rows = docgen.render("regions/seed-runs.md", page="docs/x.md", arg="mario_ppo")
    assert "| 0 | flag in 9 of 10 | flag in 27 of 30 (1000010..1000039) | 1,000 | 10 s | 100 | not recorded | – |" in rows
    assert "| 1 | flag in 10 of 10 | – |" in rows
    for seed in range(3):  # one rule ended every run: said once below the table, not in every row
        meta_path = kept / f"seed={seed}" / "model" / "meta.json"
        meta_path.write_text(json.dumps({**json.loads(meta_path.read_text()), "stopped_by": "stop_success_share 0.9"}))
    rows = docgen.render("regions/seed-runs.md", page="docs/x.md", arg="mario_ppo")
    assert "| 0 | flag in 9 of 10 | flag in 27 of 30 (1000010..1000039) | 1,000 | 10 s | 100 | not recorded |\n" in rows
    assert "stopped by" not in rows.split("Every run")[0] and ("Every run was stopped by the flag reached in 90% or "
                                                               "more of the last 100") in rows
    curves = docgen.render("regions/curves.md", page="docs/experiments/mario_ppo.md", arg="mario_ppo")
    assert ("1-1, 3 seeds: the share of the last 100 episodes that reached the flag, as the stop rule reads it"
            in curves and "results/sweeps/mario_ppo__1-1/report_success.png)" in curves)


def test_a_goal_tasks_report_draws_the_success_share_the_stop_rule_reads(tmp_path):
    """Mario's seeds are scored by the flag: report_success.png draws metrics.csv's success_share (the share of
    the last 100 episodes from the start, what --stop-success-share reads), with the runs' stop share; a level
    x-4 ends at the axe."""
    from rlcore.records.report_plots import SUCCESS_SHARE, _goal, run_curve

    for s in range(2):
        _mario_run(tmp_path / "runs" / f"seed={s}", s, 8, stop_success_share=0.9)
    runs = load_runs(tmp_path / "runs")  # the rows the report draws from
    steps, shares = run_curve(runs[0]["run_dir"], SUCCESS_SHARE)
    assert steps.tolist() == [10.0, 1000.0] and shares.tolist() == [0.0, 0.5]
    assert _goal([{"runs": runs}]) == ("flag", 0.9)
    _mario_run(tmp_path / "castles" / "seed=2", 2, 8, stage=4, stop_success_share=0.8)
    [castle] = load_runs(tmp_path / "castles")
    assert _goal([{"runs": [castle]}]) == ("axe", 0.8)
    assert _goal([{"runs": runs + [castle]}]) == ("goal", None)  # unlike runs: no one word, no one stop share


def test_keeping_again_replaces_the_kept_folder_whole_and_never_another_folder(tmp_path, capsys):
    runs = [str(_mario_run(tmp_path / f"run{s}", s, 8)) for s in range(3)]
    kept = tmp_path / "kept"
    assert run(capsys, "report", *runs, "--keep", str(kept), "--reps", "100")[0] == 0
    assert run(capsys, "report", *runs[:2], "--keep", str(kept), "--reps", "100")[0] == 0
    assert sorted(p.name for p in kept.glob("seed=*")) == ["seed=0", "seed=1"]  # seed 2's files went
    assert json.loads((kept / "sweep.json").read_text())["seeds"] == [0, 1]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".kept.")]  # no build folder left
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "mine.txt").write_text("a user's file")
    (tmp_path / "afile").write_text("x")
    for dest, message in ((tmp_path / "notes", "that folder holds other files and no kept sweep"),
                          (tmp_path / "afile", "a file is there; give a folder")):
        code, _, err = run(capsys, "report", *runs, "--keep", str(dest))
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert (tmp_path / "notes" / "mine.txt").read_text() == "a user's file"


@pytest.mark.parametrize("case, message", [
    ("no keep", "is a finished run, not a sweep: to report single runs of one recipe over seeds, keep them"),
    ("other config", "differ in entropy_coef: kept runs are one recipe over seeds"),
    ("same seed", "two of the runs have the same seed (0, 0)"),
    ("with a sweep", "--keep takes one sweep folder, or finished run folders only, not both"),
    # the same final settings, but not one recipe from start to end
    ("init from", "started from the weights of saved_networks/mario_ppo/1-1 (--init-from): kept runs train from random"),
    ("changed on a resume", "was resumed at env step 1,000 with entropy_coef 0.01 -> 0.003: kept runs follow one recipe"),
    ("unrecorded resume", "does not say what its command 2 (a resume) changed")])
def test_single_runs_that_are_not_one_recipe_over_seeds_are_refused(tmp_path, capsys, case, message):
    first = str(_mario_run(tmp_path / "a", 0, 9))
    other = {"other config": lambda: _mario_run(tmp_path / "b", 1, 9, entropy_coef=0.003),
             "same seed": lambda: _mario_run(tmp_path / "b", 0, 9),
             "init from": lambda: _mario_run(tmp_path / "b", 1, 9, init_from={"path": "saved_networks/mario_ppo/1-1"}),
             # changed and changed back: the final settings agree, the record does not
             "changed on a resume": lambda: _mario_run(tmp_path / "b", 1, 9, resumes=(
                 {}, {"entropy_coef": [0.01, 0.003]}, {"entropy_coef": [0.003, 0.01]})),
             "unrecorded resume": lambda: _mario_run(tmp_path / "b", 1, 9, resumes=(None,)),
             }.get(case, lambda: _mario_run(tmp_path / "b", 1, 9))()
    argv = ["report", first, str(other), "--keep", str(tmp_path / "kept")]
    if case == "no keep":
        argv = argv[:-2]
    if case == "with a sweep":
        (tmp_path / "sweep").mkdir()
        argv.insert(1, str(tmp_path / "sweep"))
    code, _, err = run(capsys, *argv)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "kept").exists()


def test_report_refuses_a_folder_that_mixes_experiments_or_algorithms(tmp_path, capsys):
    """`report runs/` over a user's runs of unlike tasks would average unlike scores: one line, exit 2."""
    for name, experiment, algo, score in (("a", "lunar_lander", "dqn", 200.0), ("b", "cartpole", "a2c", 500.0),
                                          ("c", "lunar_lander", "dqn", 250.0)):
        (tmp_path / "runs" / name / "model").mkdir(parents=True)
        (tmp_path / "runs" / name / "model" / "meta.json").write_text(json.dumps({
            "experiment": experiment, "algo": algo, "seed": 0, "env_steps": 10, "wall_seconds": 1.0,
            "evaluation": {"episodes": 5, "mean": score}}))
    code, out, err = run(capsys, "report", str(tmp_path / "runs"))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "holds runs of cartpole a2c and lunar_lander dqn" in err
    assert not (tmp_path / "runs" / "report.md").exists()
    (tmp_path / "runs" / "b" / "model" / "meta.json").unlink()  # the rest: one experiment and algorithm
    assert [r["score"] for r in load_runs(tmp_path / "runs")] == [200.0, 250.0]


def test_a_trial_killed_before_its_first_checkpoint_starts_over_without_its_old_rows(tmp_path):
    """No checkpoint means the trial starts from episode 1 again: rows logged by the killed start are
    not kept under the new run's (they would repeat episode numbers and mix two runs' curves)."""
    import dataclasses

    from rlcore.sweeps.trial import run_trial
    sweep = _sweep(tmp_path, "early", seeds=(0,))
    trial = tmp_path / "early" / "seed=0"
    trial.mkdir(parents=True)
    header = "episode,total_points,av_latest_points,target_ave_scores,env_steps,wall_seconds\n"
    (trial / "metrics.csv").write_text(header + "1,-12345.0,-12345.0,,7,0.1\n2,-12345.0,-12345.0,,9,0.2\n")
    reported = []
    run_trial({"seed": 0}, dataclasses.asdict(sweep), {"toy": "tests.toy"}, reported.append)
    # Tune gets finite numbers only (a NaN loss before the first update printed a TensorBoard warning)
    assert "nan" in (trial / "metrics.csv").read_text()
    assert reported and all(math.isfinite(v) for metrics in reported for v in metrics.values())
    rows = (trial / "metrics.csv").read_text().splitlines()[1:]
    episodes = [int(line.split(",")[0]) for line in rows]
    assert episodes == list(range(1, len(episodes) + 1)) and len(episodes) >= 2
    assert not any("-12345" in line for line in rows)


def test_sigterm_to_the_sweeps_process_group_stops_its_trials_at_a_checkpoint(tmp_path):
    """As `timeout` or a scheduler sends it: to the driver and every process it started. Ray's services
    must not die under the trials (they started with the signal blocked); the driver stops the trials."""
    from tests.test_stop_signals import group_is_gone

    folder = tmp_path / "group"
    proc = subprocess.Popen([sys.executable, "main.py", "sweep", "cartpole", "dqn", "--seeds", "0",
                             "--episodes", "5000", "--dir", str(tmp_path), "--name", "group", "--num-cpus", "1"],
                            cwd=ROOT, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    _wait_for(folder / "seed=0" / "checkpoint.npz", timeout=240)
    # the command imports ray.tune (its check for the sweep extra) before it starts Ray: still loopback only
    sockets = listening(group_pids(proc.pid))
    outside = outside_loopback(sockets)
    os.killpg(proc.pid, signal.SIGTERM)
    out, err = proc.communicate(timeout=180)
    assert proc.returncode == 130, err[-2000:]
    assert sockets and not outside, outside or "no socket of the sweep's Ray found"
    assert "seed=0: stopped at a checkpoint" in out, out
    assert group_is_gone(proc.pid, timeout=30)
    log = (folder / "trials.log").read_text()
    assert log.count("started") == 1 and "failed" not in log
    assert log.splitlines()[-1].endswith(" seed=0 pid " + log.split()[3] + " stopped at a checkpoint"), log


def test_status_of_a_sweep_folder_is_a_line_per_trial(tmp_path, capsys):
    sweep = _sweep(tmp_path, "st", seeds=(0, 1, 2), max_env_steps=4300)
    sweep.max_concurrent = 1
    Path(sweep.folder).mkdir()
    sweep.save()
    done = tmp_path / "st" / "seed=0" / "model"
    done.mkdir(parents=True)
    (done / "meta.json").write_text(json.dumps({"env_steps": 1200, "wall_seconds": 60.0, "evaluation": {"mean": 9.5}}))
    running = tmp_path / "st" / "seed=1"
    running.mkdir()
    state = {"env_steps": 700, "wall_seconds": 7200.0, "checkpoint_version": 2, "config": {"max_env_steps": 4300},
             "returns": [0.0] * 4}
    np.savez(running / "checkpoint.npz", state_json=np.frombuffer(json.dumps(state).encode(), np.uint8))
    # its pace over the last half hour of its clock (rows past the checkpoint count): 720 env steps in 1,800 s,
    # 0.4 env steps/s; the first row, slower, is older; 3,600 env steps to go from the checkpoint: 2.5 h
    (running / "metrics.csv").write_text("episode,total_points,env_steps,wall_seconds,q_mean\n1,0,10,1000,\n"
                                         "2,0,100,5400,1.5\n3,0.5,400,6500,2.5\n4,0,820,7200,3.5\n")
    (running / "evals.csv").write_text("env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
                                       "500,9,3.25,0.5,0.4\n")
    code, out, err = run(capsys, "status", str(tmp_path / "st"))
    assert code == 0, err
    assert out.splitlines() == [
        "sweep st: toy dqn, 3 trials",
        "  seed=0: finished at 1,200 env steps, final score 9.50 on unseen seeds",
        "  seed=1: checkpoint at 700 env steps, 2.0 h, 0.4 env steps/s lately, about 2.5 h to its budget of 4,300 "
        "env steps; last evaluation at env step 500: mean 3.25 +- 0.50, 40% of its episodes to the time limit; "
        "critic: mean Q 2.50 (largest return 0.50)",  # the median of the episodes that made gradient steps
        "  seed=2: not started",
        # seed 1: 3,600 env steps at 0.4/s = 2.5 h; seed 2: 4,300 at seed 0's 20 env steps/s = 0.06 h
        "about 2.6 h of training left, 1 trial at a time, at the paces seen (1 trial not started, at the "
        "finished trials' mean pace)"]
    (running / "metrics.csv").write_bytes(b"\x00\xff damaged")  # one trial's damaged table: its line says less
    code, out, err = run(capsys, "status", str(tmp_path / "st"))
    assert code == 0, err
    assert out.splitlines()[2] == "  seed=1: checkpoint at 700 env steps, 2.0 h" and len(out.splitlines()) == 4


def test_tune_warns_of_no_slow_report_even_when_imported_before_the_sweep(monkeypatch):
    """The sweep command imports ray.tune (its check for the sweep extra) before run_sweep sets Tune's
    threshold for "may be a performance bottleneck" lines: the threshold Tune derived then is set too."""
    from ray.tune.utils import util

    from rlcore.sweeps.on_ray import quiet_tune

    monkeypatch.setattr(util.warn_if_slow, "DEFAULT_THRESHOLD", 0.5)  # as Tune reads it without the variable
    monkeypatch.setenv("TUNE_WARN_THRESHOLD_S", "")
    monkeypatch.delenv("TUNE_WARN_THRESHOLD_S")
    quiet_tune()
    assert util.warn_if_slow("process_trial_result").threshold == 600


def test_a_run_resumed_before_resumes_recorded_their_changes_is_not_kept():
    """Records from before 2026-11-27 list the commands but no command_starts: the resumes are there, what
    they changed is not, so the keep cannot show that they changed budgets only."""
    from rlcore.errors import UserError
    from rlcore.records.commands import command_starts
    from rlcore.records.keeping import check_one_recipe_throughout

    old = {"commands": ["python main.py train mario_ppo ppo --seed 0", "python main.py train mario_ppo ppo --resume R"]}
    assert command_starts(old) == [None, None]
    with pytest.raises(UserError, match="does not say what its command 2 \\(a resume\\) changed"):
        check_one_recipe_throughout(Path("R"), old)
    check_one_recipe_throughout(Path("R"), {"commands": ["python main.py train mario_ppo ppo --seed 0"]})  # never resumed


def test_a_trial_trained_but_not_evaluated_is_evaluated_on_resume_and_never_left_out_of_a_report(tmp_path, capsys):
    """A process that ends between the training and the evaluation on unseen seeds (as a trial did on
    2026-11-27) leaves model/meta.json without an evaluation: the sweep's resume evaluates it rather than
    skip it as finished, the status says so, and a report refuses the folder until then rather than
    aggregate the other seeds as if they were all."""
    import dataclasses

    from rlcore.errors import UserError
    from rlcore.sweeps.trial import run_trial
    sweep = _sweep(tmp_path, "late", seeds=(0,))
    Path(sweep.folder).mkdir()
    sweep.save()
    args = ({"seed": 0}, dataclasses.asdict(sweep), {"toy": "tests.toy"}, lambda metrics: None)
    first = run_trial(*args)
    meta_path = tmp_path / "late" / "seed=0" / "model" / "meta.json"
    meta = json.loads(meta_path.read_text())
    evaluation = meta.pop("evaluation")
    meta_path.write_text(json.dumps(meta))
    code, out, err = run(capsys, "status", str(tmp_path / "late"))
    assert "seed=0: finished at" in out and "not evaluated on unseen seeds yet (the sweep's --resume evaluates it)" in out
    other = tmp_path / "late" / "seed=1" / "model"  # a second seed, evaluated
    other.mkdir(parents=True)
    (other / "meta.json").write_text(json.dumps({**meta, "seed": 1, "evaluation": evaluation}))
    with pytest.raises(UserError, match="seed=0 trained but has no evaluation on unseen seeds"):
        load_runs(tmp_path / "late")
    again = run_trial(*args)
    # the same model on the same seeds: close to the first evaluation (compared with a tolerance, as floats
    # read back from a file are, though here both ran in this process)
    assert again["skipped"] == 0 and again["final_score"] == pytest.approx(first["final_score"])
    redone = json.loads(meta_path.read_text())["evaluation"]["per_episode"]
    assert [r["seed"] for r in redone] == [r["seed"] for r in evaluation["per_episode"]]
    assert [r["return"] for r in redone] == pytest.approx([r["return"] for r in evaluation["per_episode"]])
    assert "seed=0 pid" in (log := (tmp_path / "late" / "trials.log").read_text())
    assert "trained but not evaluated: evaluating" in log and log.rstrip().endswith("finished")
    assert run_trial(*args)["skipped"] == 1  # evaluated now: finished
    assert [r["seed"] for r in load_runs(tmp_path / "late")] == [0, 1]
    meta_path.write_text(json.dumps(meta))  # without its evaluation again
    (tmp_path / "late" / "STOP").touch()  # a stopping sweep begins no evaluation either
    assert run_trial(*args) == {"interrupted": 1, "not_started": 1}
    (tmp_path / "late" / "STOP").unlink()
    no_evaluations = dataclasses.asdict(dataclasses.replace(sweep, final_eval_episodes=0))
    assert run_trial({"seed": 0}, no_evaluations, {"toy": "tests.toy"}, lambda metrics: None)["skipped"] == 1


def test_the_end_of_a_run_is_imported_at_its_start():
    """Every rlcore module that the end-of-run modules import inside their functions is loaded by
    `_import_the_end_of_a_run`, so an edit made while a run trains cannot meet older modules there."""
    script = """
import ast, importlib, sys
from pathlib import Path
import rlcore.training.run as run
run._import_the_end_of_a_run()
missing = set()
for name in run.END_OF_RUN_MODULES:
    tree = ast.parse(Path(sys.modules[name].__file__).read_text())
    for fn in (n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))):
        for node in ast.walk(fn):
            if isinstance(node, ast.ImportFrom) and node.module == "rlcore":  # from rlcore import x
                missing |= {f"rlcore.{a.name}" for a in node.names} - set(sys.modules)
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("rlcore."):
                missing |= {node.module} - set(sys.modules)
            elif isinstance(node, ast.Import):
                missing |= {a.name for a in node.names if a.name.startswith("rlcore.")} - set(sys.modules)
# api.export's module, which no run calls at its end; the agents snapshot.py builds by kind: a run's own
# agent module is loaded by its trainer before it trains
print(sorted(m for m in missing if m != "rlcore.models.export" and not m.startswith("rlcore.algorithms.")))
"""
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"


def test_run_training_imports_the_end_of_the_run_before_it_trains(monkeypatch, tmp_path):
    from rlcore.training import run

    class Imported(Exception):
        pass

    def imported():
        raise Imported

    monkeypatch.setattr(run, "_import_the_end_of_a_run", imported)
    spec = run.build_spec("cartpole", "dqn", run_dir=tmp_path / "run", overrides={"max_episodes": 1})
    with pytest.raises(Imported):
        run.run_training(spec)
    assert not (tmp_path / "run").exists()  # before anything is written
