"""Collapses and kept weights read back from a run's periodic evaluations (rlcore.records.eval_history)."""
import pytest

from rlcore.errors import UserError
from rlcore.records.eval_history import (
    Evaluation,
    Story,
    collapses,
    far_from_solved,
    read_evals,
    stability_summary,
    steps_text,
    story,
    story_text,
)


def evals(*means, every=50_000):
    return [Evaluation(every * (i + 1), m, None) for i, m in enumerate(means)]


def story_from(rows, kept_best):
    best = max(reversed(rows), key=lambda e: e.mean)
    return Story(len(rows), best, rows[-1], collapses(rows), kept_best)


# the Minitaur sweep's seed 0, 50k ... 1M: three collapses, each recovered by a later evaluation
MINITAUR_SEED_0 = (-0.08, 0.02, 0.17, 0.48, 0.50, 4.03, 14.76, 0.19, 9.51, 12.06, 15.10, 16.76, 0.14, 18.35,
                   11.03, 17.88, 0.67, 16.46, 12.82, 14.05)


def test_a_walker_that_falls_three_times_and_gets_up_each_time():
    found = collapses(evals(*MINITAUR_SEED_0))
    assert [(c.env_steps, c.mean, c.best_before, c.recovered_at) for c in found] == [
        (400_000, 0.19, pytest.approx(14.76), 500_000),  # 9.51 at 450k is not yet three quarters of the way back
        (650_000, 0.14, pytest.approx(16.76), 700_000),
        (850_000, 0.67, pytest.approx(18.35), 900_000)]


def test_the_scale_is_the_runs_own_so_negative_returns_work():
    # LunarLander-like: from -200 up to 200 (gain 400); -150 is below a quarter of the way (-100)
    found = collapses(evals(-200, -100, 150, 200, -150, 50, 210))
    assert [(c.env_steps, c.recovered_at) for c in found] == [(250_000, 350_000)]  # 50 < 100: not yet back


def test_noise_before_the_run_has_learnt_is_not_a_collapse():
    assert collapses(evals(0, 2, 0.1, 10, 12)) == []  # at 2 the run had made a sixth of its best gain


def test_a_collapse_that_never_comes_back_is_unrecovered():
    [c] = collapses(evals(0, 10, 1, 2))
    assert (c.env_steps, c.recovered_at) == (150_000, None)
    assert "not recovered" in story_text(story_from(evals(0, 10, 1, 2), kept_best=True))


def test_runs_that_never_learn_or_have_one_evaluation_have_no_collapses():
    assert collapses(evals(5, 4, 3, 1)) == [] and collapses(evals(3)) == [] and collapses([]) == []


def test_story_reads_the_run_folder_and_says_which_weights_the_model_holds(tmp_path):
    lines = ["env_steps,episode,eval_mean,eval_std,eval_time_limit_share"]
    lines += [f"{50_000 * (i + 1)},{i},{m},0.5,1.0" for i, m in enumerate(MINITAUR_SEED_0)]
    (tmp_path / "evals.csv").write_text("\n".join(lines) + "\n")
    s = story(tmp_path, {"weights": "best periodic evaluation"})
    assert (s.evaluations, s.best.env_steps, s.last.mean, len(s.collapses)) == (20, 700_000, 14.05, 3)
    assert s.keep_best_mattered and s.best.time_limit_share == 1.0
    assert story_text(s) == ("3 collapses (400k: 0.19 after 14.76, back by 500k; 650k: 0.14 after 16.76, back by "
                             "700k; 850k: 0.67 after 18.35, back by 900k); model: weights of the best evaluation "
                             "(18.35 at 700k), the last scored 14.05")
    last = story(tmp_path, {"weights": "last"})
    assert not last.keep_best_mattered and story_text(last).endswith("model: the last weights")


def test_a_tie_goes_to_the_later_evaluation_as_in_training(tmp_path):
    (tmp_path / "evals.csv").write_text("env_steps,episode,eval_mean,eval_std,eval_time_limit_share\n"
                                        "1000,1,500.0,0,1\n2000,2,300.0,0,0\n3000,3,500.0,0,1\n")
    s = story(tmp_path, {"weights": "best periodic evaluation"})
    assert s.best.env_steps == 3000 and not s.keep_best_mattered and story_text(s).endswith("also the last")


def test_no_evals_csv_is_no_story_and_a_damaged_one_is_one_line(tmp_path):
    assert story_text(story(tmp_path, {})) == "no periodic evaluations"
    (tmp_path / "evals.csv").write_text("env_steps,mean\n1000,3.0\n")
    with pytest.raises(UserError, match=r"evals.csv is damaged or not one of ours \(KeyError\)"):
        read_evals(tmp_path)


@pytest.mark.parametrize("steps, text", [(1_000_062, "1M"), (1_950_000, "1.95M"), (650_000, "650k"),
                                         (48_000, "48k"), (1_234, "1,234")])
def test_steps_text(steps, text):
    assert steps_text(steps) == text


# the Minitaur sweep's seed 2, 50k ... 650k: it had not learnt to walk (the solved score is 15)
MINITAUR_SEED_2 = (-0.34, -0.02, 0.26, 0.86, -0.07, 0.26, -0.13, -0.15, 0.04, -0.55, 0.39, 0.11, 0.26)


def test_dips_of_a_run_that_got_nowhere_near_the_solved_score_are_not_collapses():
    rows = evals(*MINITAUR_SEED_2)
    assert len(collapses(rows)) == 1  # on its own scale alone, 0.86 -> -0.07 would count
    assert collapses(rows, solved=15.0) == []  # a quarter of the way to 15 is 3.5; its best gain was 1.2
    assert far_from_solved(rows, 15.0) and not far_from_solved(rows, None)
    assert not far_from_solved(evals(*MINITAUR_SEED_0), 15.0)
    assert len(collapses(evals(*MINITAUR_SEED_0), solved=15.0)) == 3


def test_the_solved_score_floor_is_measured_from_the_first_evaluation():
    # LunarLander-like: from -200, a quarter of the way to 200 is -100; 20 points of gain is not enough
    assert far_from_solved(evals(-200, -180, -250), 200.0)
    assert not far_from_solved(evals(-200, -90, -250), 200.0)
    assert len(collapses(evals(-200, -90, -250), solved=200.0)) == 1
    # nothing claimed: a first evaluation already at the solved score, no solved score, no evaluations
    assert not far_from_solved(evals(500, 500, 500), 500.0) and not far_from_solved(evals(0, 0), None)
    assert not far_from_solved([], 200.0)


def test_a_run_that_never_rose_is_told_as_no_collapses_not_as_far_from_solved(tmp_path):
    (tmp_path / "evals.csv").write_text("env_steps,eval_mean,eval_std,eval_time_limit_share\n"
                                        "1000,500,0,1\n2000,500,0,1\n3000,500,0,1\n")
    for solved in (500.0, None):
        s = story(tmp_path, {"weights": "last"}, solved=solved)
        assert story_text(s) == "0 collapses; model: the last weights"
        assert stability_summary([s]).startswith("0 of 1 runs collapsed at least once (0 collapses, 0 not recovered); ")


def test_the_story_and_the_summary_say_which_runs_had_nothing_to_lose(tmp_path):
    (tmp_path / "evals.csv").write_text("env_steps,eval_mean,eval_std,eval_time_limit_share\n" + "".join(
        f"{50_000 * (i + 1)},{m},0.1,0.0\n" for i, m in enumerate(MINITAUR_SEED_2)))
    s = story(tmp_path, {"weights": "best periodic evaluation"}, solved=15.0)
    assert s.far_from_solved and s.collapses == []
    assert story_text(s).startswith("no evaluation a quarter of the way to the solved score (best 0.86)")
    alone = story(tmp_path, {"weights": "best periodic evaluation"})  # no solved score: any gain counts
    assert not alone.far_from_solved and len(alone.collapses) == 1
    summary = stability_summary([s, alone])
    assert summary.startswith("1 of 2 runs collapsed at least once (1 collapse, 1 not recovered); in 1 run no evaluation")


def test_a_report_knows_the_solved_score_from_the_record_or_the_registry_and_else_claims_nothing():
    from rlcore.records.report import _solved_score

    assert _solved_score({"experiment": "minitaur"}) == 15.0
    assert _solved_score({"experiment": "Acrobot-v1", "env": {"reward_threshold": -100}}) == -100.0
    assert _solved_score({"experiment": "my_envs:Maze-v0", "env": {"reward_threshold": None}}) is None
    assert _solved_score({"experiment": "my_envs:Maze-v0"}) is None  # no record: its env is not built for this
    assert _solved_score({"experiment": "mario_ppo"}) is None  # success is the flag
