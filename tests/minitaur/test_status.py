"""`main.py status` of a run without a goal (Minitaur SAC): length, metres walked, evaluations."""
import pandas as pd
import pytest

from rlcore.files.checkpoint import save_checkpoint
from tests.test_cli import status_lines


def test_status_of_a_minitaur_run_shows_length_distance_and_the_last_evaluations(capsys, tmp_path):
    rows = ["episode,total_points,av_latest_points,target_ave_scores,env_steps,episode_steps,x,grad_steps,q_mean"]
    rows += [f"{i},{0.1 * i},0,15,{300 * i},{(i * 37) % 1000 + 1},{0.05 * i},{300 * i},{(i * 7) % 5 / 4}"
             for i in range(1, 31)]
    (tmp_path / "metrics.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "evals.csv").write_text(
        "env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
        "2000,7,0.5,0.25,0.0\n4000,14,1.25,0.5,0.1\n6000,20,2.0,1.0,0.3\n8000,27,3.5,1.5,0.6\n")
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {
        "experiment": "minitaur", "algo": "sac", "preset": "default", "seed": 0, "config": {"window": 10},
        "env_steps": 9000, "returns": [0.0] * 30, "wall_seconds": 3600.0})
    lines = status_lines(capsys, tmp_path, "--block", "10", "--blocks", "2")
    assert lines[0] == ("minitaur sac (default preset, seed 0): checkpoint at 9,000 env steps, 30 episodes, "
                        "1.0 h of training")
    df = pd.read_csv(tmp_path / "metrics.csv")
    for line, part in zip(lines[1:3], (df.iloc[10:20], df.iloc[20:30])):
        assert line == (f"episodes {part.episode.iloc[0]}-{part.episode.iloc[-1]} (to env step "
                        f"{part.env_steps.iloc[-1]:,}): mean return {part.total_points.mean():.1f} "
                        f"mean length {part.episode_steps.mean():,.0f} steps median Q {part.q_mean.median():.2f} "
                        f"mean x {part.x.mean():,.2f}")
    assert lines[3:] == ["evaluation at env step 4,000: mean 1.25 +- 0.50, 10% of its episodes to the time limit",
                         "evaluation at env step 6,000: mean 2.00 +- 1.00, 30% of its episodes to the time limit",
                         "evaluation at env step 8,000: mean 3.50 +- 1.50, 60% of its episodes to the time limit"]


def test_status_says_where_a_run_was_resumed_and_what_each_resume_changed(capsys, tmp_path):
    """A run meant to follow one recipe shows whether it did (meta.json's or the checkpoint's command_starts)."""
    from rlcore.records.status import resumes_lines

    first = {"env_steps": 0, "episodes": 0}
    assert resumes_lines({"command_starts": [first]}) == [] and resumes_lines({}) == []
    assert resumes_lines({"command_starts": [first, {"env_steps": 5000, "episodes": 9, "changed": {}}]}) == [
        "resumed 1 time (at env step 5,000): no setting changed"]
    starts = [first, {"env_steps": 5000, "episodes": 9, "changed": {"max_env_steps": [10000, 20000]}},
              {"env_steps": 12000, "episodes": 20, "changed": {"lr": [0.0003, 0.00015], "tau": [0.005, 0.01]}},
              None, {"env_steps": 15000, "episodes": 30}]  # None / no "changed": records from before they were kept
    assert resumes_lines({"command_starts": starts}) == [
        "resumed 4 times (at env step 5,000, 12,000, ?, 15,000): changed max_env_steps 10,000 -> 20,000 at 5,000; "
        "lr 0.0003 -> 0.00015 at 12,000; tau 0.005 -> 0.01 at 12,000; what 2 of them changed is not recorded "
        "(resumes recorded it from 2026-11-27 on)"]
    # and the command prints it under the headline
    (tmp_path / "metrics.csv").write_text("episode,total_points,env_steps\n1,0.5,100\n")
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {
        "experiment": "minitaur", "algo": "sac", "preset": "default", "seed": 0, "config": {"window": 10},
        "env_steps": 100, "returns": [0.5], "command_starts": starts[:2]})
    assert status_lines(capsys, tmp_path)[1] == ("resumed 1 time (at env step 5,000): changed max_env_steps "
                                                 "10,000 -> 20,000 at 5,000")


def test_status_of_a_run_in_progress_gives_its_pace_and_the_hours_left_to_its_budget(capsys, tmp_path):
    # 1,000 env steps a second for the last half hour of its clock (the row before it, slower, is older)
    (tmp_path / "metrics.csv").write_text("episode,total_points,env_steps,wall_seconds\n1,0.5,100,100\n"
                                          "2,0.5,200000,1800\n3,0.5,2000000,3600\n")
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {
        "experiment": "minitaur", "algo": "sac", "preset": "default", "seed": 0,
        "config": {"window": 10, "max_env_steps": 9_200_000}, "env_steps": 2_000_000, "returns": [0.5] * 3,
        "wall_seconds": 3600.0})
    assert status_lines(capsys, tmp_path)[0].endswith(
        "1.0 h of training; 1,000 env steps/s lately, about 2.0 h to its budget of 9,200,000 env steps")


def test_status_of_a_run_resumed_many_times_names_the_first_and_latest_resumes():
    from rlcore.records.status import resumes_lines

    starts = [{"env_steps": 0, "episodes": 0}] + [
        {"env_steps": 1000 * i, "episodes": i, "changed": {"lr": [1.0 / i, 1.0 / (i + 1)]}} for i in range(1, 21)]
    line, = resumes_lines({"command_starts": starts}, most=3)
    assert line.startswith("resumed 20 times (at env step 1,000, ..., 19,000, 20,000): changed 17 settings earlier, "
                           "then lr 0.0556 -> 0.0526 at 18,000; lr 0.0526 -> 0.05 at 19,000; lr 0.05 -> 0.0476 at 20,000")


def test_pace_reads_only_the_rows_since_a_counter_went_back_and_never_says_nan(tmp_path):
    from rlcore.records.pace import pace

    about = {"env_steps": 3000, "config": {"max_env_steps": 6000}}
    table = tmp_path / "metrics.csv"
    # an older run's rows, then a clock that starts again: 100 env steps a second since, not 1,700
    table.write_text("episode,env_steps,wall_seconds\n1,1000,10\n2,2000,20\n3,2100,1\n4,3000,10\n")
    assert pace(table, about)[:2] == pytest.approx((100.0, 30.0))  # floats read back and divided: not held to the bit
    table.write_text("episode,env_steps,wall_seconds\n1,1000,10\n2,2000,\n")  # the last clock reading missing
    assert pace(table, about) is None
    table.write_text("episode,env_steps,wall_seconds\n1,1000,10\n2,1000,20\n")  # no step taken
    assert pace(table, about) is None


def test_the_hours_left_are_read_from_the_pace_of_learning_not_of_the_random_first_steps(tmp_path):
    from rlcore.records.pace import pace

    about = {"env_steps": 4000, "config": {"max_env_steps": 10_000}}
    table = tmp_path / "metrics.csv"
    # 200 env steps a second before the first gradient step, 100 since: 6,000 left at 100 a second
    table.write_text("episode,env_steps,wall_seconds,grad_steps\n1,1000,5,0\n2,2000,10,0\n3,3000,20,1000\n"
                     "4,4000,30,2000\n")
    assert pace(table, about)[:2] == pytest.approx((100.0, 60.0))
    table.write_text("episode,env_steps,wall_seconds,grad_steps\n1,1000,5,0\n2,2000,10,0\n")  # none yet
    assert pace(table, about)[:2] == pytest.approx((200.0, None))
    table.write_text("episode,env_steps,wall_seconds,grad_steps\n1,1000,10,5\n2,2000,20,10\n")  # from the start
    assert pace(table, about)[:2] == pytest.approx((100.0, 60.0))
    # a resume that refills an empty memory (no gradient step, the count stays) and learns again
    table.write_text("episode,env_steps,wall_seconds,grad_steps\n1,1000,10,5\n2,2000,20,10\n3,3000,25,10\n"
                     "4,4000,35,20\n")
    assert pace(table, about)[:2] == pytest.approx((100.0, 60.0))
    table.write_text("episode,env_steps,wall_seconds,grad_steps\n1,1000,10,5\n2,2000,20,10\n3,3000,25,10\n")
    assert pace(table, about)[1] is None  # refilling now: no hours told from it


def test_a_finished_run_resumed_past_its_model_is_read_from_its_checkpoint(tmp_path):
    import json

    from rlcore.records.status import run_record

    assert run_record(tmp_path) is None
    (tmp_path / "model").mkdir()
    (tmp_path / "model" / "meta.json").write_text(json.dumps({"env_steps": 100}))
    assert run_record(tmp_path) == {"env_steps": 100}
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {"env_steps": 100, "returns": []})  # the model's own
    assert run_record(tmp_path) == {"env_steps": 100}
    save_checkpoint(tmp_path / "checkpoint.npz", {}, {}, {"env_steps": 150, "returns": []})  # training on
    assert run_record(tmp_path)["env_steps"] == 150


def test_the_sweeps_hours_left_are_never_fewer_than_its_longest_trials():
    from rlcore.sweeps.status import NOT_STARTED, NotLearning, time_left

    assert time_left([3600.0], [], None, 4) == ["about 1.0 h of training left, 4 trials at a time, at the "
                                                "paces seen"]
    # two running (1 h, 2 h) and two waiting (1,000 env steps at 1 a second), two at a time: 1.8 h shared
    # out, but the 2-hour trial alone takes 2 h
    assert time_left([3600.0, 7200.0, NOT_STARTED, NOT_STARTED], [0.5, 1.5], 1000, 2)[0].startswith(
        "about 2.0 h of training left, 2 trials at a time")
    # four trials of an hour each, two at a time: 2 h
    assert time_left([3600.0, 3600.0, NOT_STARTED, NOT_STARTED], [1.0], 3600, 2)[0].startswith(
        "about 2.0 h of training left, 2 trials at a time, at the paces seen (2 trials not started")
    # a trial still taking its random first steps: its 7,200 steps left at the finished trials' 2 a second
    assert time_left([NotLearning(7200), NOT_STARTED], [2.0], 3600, 1) == [
        "about 1.5 h of training left, 1 trial at a time, at the paces seen (1 trial not started, 1 not "
        "learning yet, at the finished trials' mean pace)"]
    assert time_left([NotLearning(7200)], [], 3600, 1) == []  # no finished trial to take a pace from
    assert time_left([None, 3600.0], [], None, 1) == []  # a trial whose pace cannot be told
    assert time_left([NOT_STARTED], [], 1000, 1) == []  # no finished trial to take a pace from


def test_an_episode_budget_gives_the_hours_left_too(tmp_path):
    """Issue 65: status gave the hours left only for an env-step budget. 10 episodes of 100 steps in 100 s
    (0.1 episode/s): 90 of a 100-episode budget left is 900 s; with both budgets, the one met first."""
    from rlcore.records.pace import pace, pace_text

    table = tmp_path / "metrics.csv"
    table.write_text("episode,env_steps,wall_seconds\n" + "".join(f"{i},{100 * i},{10 * i}\n" for i in range(1, 11)))
    about = {"env_steps": 1000, "returns": [0.0] * 10, "config": {"max_episodes": 100, "max_env_steps": 0}}
    rate, left, budget = pace(table, about)
    assert (rate, budget) == (pytest.approx(10.0), "100 episodes") and left == pytest.approx(900.0)
    assert pace_text(table, about).endswith("about 0.2 h to its budget of 100 episodes")
    about["config"]["max_env_steps"] = 2000  # 1,000 steps left at 10/s: 100 s, before the episodes
    assert pace(table, about)[1:] == (pytest.approx(100.0), "2,000 env steps")
