"""The README's "same recipe over seeds [95% CI]" figures are recomputed from the sweep results git keeps
(`results/sweeps/NAME`, written by `main.py report SWEEP --keep`), so a figure cannot drift from its
runs, and the runs cannot go missing from a clone."""
import json

import numpy as np
import pytest

from rlcore.records.report import load_runs, summarize
from tests.test_cli import ROOT

KEPT = ROOT / "results" / "sweeps"
SWEPT = sorted(p.parent.name for p in KEPT.glob("*/sweep.json"))


def test_the_kept_sweeps_are_in_the_clone():
    assert {"cartpole__dqn", "cartpole__a2c", "lunar_lander__dqn"} <= set(SWEPT)


@pytest.mark.parametrize("name", SWEPT)
def test_the_readme_quotes_each_kept_sweeps_iqm_and_interval(name):
    import json

    from rlcore.records.score_words import return_digits

    runs = load_runs(KEPT / name)
    experiment, model = name.split("__")
    shipped = json.loads((ROOT / "saved_networks" / experiment / model / "meta.json").read_text())["evaluation"]
    over = shipped_bar(experiment, model)
    statistic = over.statistic if over else "iqm"
    assert sorted(r["seed"] for r in runs) == list(range(over.seeds if over else 5))
    point, lo, hi = summarize([KEPT / name], reps=5000)["sweeps"][0]["aggregates"][statistic]  # as `report`
    shown = ((lambda v: f"{v:.0%}") if "success_share" in shipped
             else (lambda v: f"{v:,.{return_digits(shipped['mean'])}f}"))  # the shipped score's digits
    name_shown = "IQM" if statistic == "iqm" else statistic
    assert readme_iqm_cell(name) == f"{name_shown} over {len(runs)}: {shown(point)} [{shown(lo)}, {shown(hi)}]"


def shipped_bar(experiment: str, model: str):
    """The registry's bar over seeds for a shipped model (None where none is set)."""
    from tools.docgen.data import shipped_models

    found = [m for m in shipped_models() if m.folder == f"saved_networks/{experiment}/{model}"]
    assert len(found) == 1, f"no shipped model in saved_networks/{experiment}/{model}"
    return found[0].bar.over_seeds if found[0].bar else None


def readme_iqm_cell(name: str) -> str:
    """The "same recipe over seeds [95% CI]" cell (the last) of the README row of this sweep's shipped model (the row
    that links to its card). The generator writes it (tools.docgen); this recomputes it from the runs."""
    experiment, algo = name.split("__")
    card = f"(saved_networks/{experiment}/{algo}/README.md)"
    rows = [line for line in (ROOT / "README.md").read_text().splitlines()
            if line.startswith("|") and card in line]
    assert len(rows) == 1, f"{name}: {len(rows)} README rows link to {card}"
    return [cell.strip() for cell in rows[0].strip().strip("|").split("|")][-1]


@pytest.mark.parametrize("name", SWEPT)
def test_the_experiment_page_tells_each_kept_sweeps_collapses_as_its_evaluations_show_them(name):
    """The page's summary of collapses and keep-best (docgen's sweep-stability region) recomputed from the
    kept evals.csv files; and each seed's collapses are listed with where each fell and came back."""
    from rlcore.records.critic_trace import critic_cell, critic_trace
    from rlcore.records.eval_history import stability_summary
    from tools.docgen.main import collapses_cell

    experiment, model = name.split("__")
    page = (ROOT / "docs" / "experiments" / f"{experiment}.md").read_text()
    region = page.partition("<!-- generated:sweep-stability")[2].partition("<!-- /generated -->")[0]
    section = region.partition(f"**[{model}](../../results/sweeps/{name}/report.md)**: ")[2].partition("\n**[")[0]
    runs = load_runs(KEPT / name)
    if not any(r["story"].evaluations for r in runs):  # PPO's runs (Mario) evaluate only at their end
        assert not section or "made no periodic evaluations" in section, section
        return
    assert section.startswith(stability_summary([r["story"] for r in runs]))
    rows = {line.split("|")[1].strip(): line for line in section.splitlines() if line.startswith("| ")}
    traces = {r["seed"]: critic_trace(r["run_dir"]) for r in runs}
    for r in runs:
        assert f"| {collapses_cell(r['story'].collapses)} |" in rows[str(r["seed"])]
        if all(traces.values()):  # a Q-learner's table ends with each seed's critic at the end of its run
            assert rows[str(r["seed"])].rstrip().endswith(f"| {critic_cell(traces[r['seed']])} |")
    assert ("critic at the end" in section) == all(traces.values())


@pytest.mark.parametrize("name", SWEPT)
def test_each_kept_report_tells_the_runs_stories_as_the_code_reads_them_now(name):
    """report.md is written once by `report --keep`; when the rule that reads evals.csv changes, the kept
    reports are written again (`main.py report results/sweeps/NAME`), and this says which are stale."""
    from rlcore.records.report import critic_lines, stability_lines

    report = (KEPT / name / "report.md").read_text()
    runs = load_runs(KEPT / name)
    for line in stability_lines(runs) + critic_lines(runs):
        assert line in report, f"{name}/report.md is stale: run `python main.py report results/sweeps/{name}`"


def test_a_seed_summary_gives_the_iqm_each_seed_and_the_shipped_model_beside_them():
    """The README's paragraph per kept sweep (docgen's seed-summary region), on the CartPole DQN sweep."""
    from rlcore.records.eval_history import stability_summary
    from tools.docgen.main import render

    text = render("regions/seed-summary.md", page="README.md", arg="cartpole")
    runs = load_runs(KEPT / "cartpole__dqn")
    iqm, lo, hi = summarize([KEPT / "cartpole__dqn"], reps=5000)["sweeps"][0]["aggregates"]["iqm"]
    first = text.split("\n\n")[0]
    assert f"IQM [95% CI] **{iqm:.1f} [{lo:.1f}, {hi:.1f}]**" in first
    assert "per seed " + "; ".join(f"{r['seed']}: {r['score']:.1f} over 100 after {r['env_steps']:,} env steps, "
                                   f"{r['wall_seconds']:.0f} s" for r in runs) in first
    assert "the shipped model (seed 0, a run of its own) 500.0" in first
    assert first.endswith(stability_summary([r["story"] for r in runs]))
    assert "Not kept" in render("regions/seed-summary.md", page="README.md", arg="no_such_experiment")


def kept_models() -> list[str]:
    """The kept runs that kept their model's weights (model/*.h5), as "sweep/seed=S"."""
    return sorted(f"{p.parent.parent.parent.name}/{p.parent.parent.name}" for p in KEPT.glob("*/*/model/meta.json")
                  if any(p.parent.glob("*.h5")))


@pytest.mark.parametrize("run", kept_models())
def test_a_kept_runs_model_plays_its_recorded_first_episode_again(run):
    """Held-out checks replay a kept run's model. On the machine that recorded its evaluation the first
    recorded episode repeats exactly (rlcore.host.machine); elsewhere it plays that seed to its end (oneDNN may
    take another course on another CPU, and a seed of a sweep need not clear the shipped model's bar)."""
    from rlcore.host import machine
    from rlcore.models.policies import load_policy
    from rlcore.training.evaluation import evaluate, evaluate_success
    from tests.cpu_support import skip_where_its_precision_cannot_run

    skip_where_its_precision_cannot_run(json.loads((KEPT / run / "model" / "meta.json").read_text()))
    exp, meta, policy = load_policy(KEPT / run / "model")
    first = meta["evaluation"]["per_episode"][0]
    assert first["seed"] == exp.eval_seed_base
    exact = machine.replays_exactly(machine.recorded_machine(meta))
    if goal := exp.goal:
        [got] = evaluate_success(policy.make_env, policy.sample, 1, exp.eval_seed_base, goal.success_key,
                                 goal.progress_key, progress=False)
        if exact:
            assert (got["success"], got["length"], got[goal.progress_key]) == (
                first["success"], first["length"], first[goal.progress_key])
        return
    [got] = evaluate(exp, policy, episodes=1, progress=False, make_env=policy.make_env)
    assert np.isfinite(got)
    if exact:
        assert got == pytest.approx(first["return"], rel=1e-5)


def test_what_ended_a_run_is_said_in_words_and_an_unknown_rule_as_recorded():
    from types import SimpleNamespace

    from tools.docgen.main import stop_text

    mario = SimpleNamespace(experiment="mario_ppo", name="1-1")
    said = {"max_env_steps 1000000": "its budget of 1,000,000 env steps",
            "max_episodes 600": "its budget of 600 episodes",
            "stop_eval_score 250.0": "a periodic evaluation of 250.0 or more",
            "stop_score 230.0": "a 50-episode average of 230.0 or more",
            "stop_success_share 0.9": "the flag reached in 90% or more of the last 50 training episodes from the start",
            "stop_success_share 0.825": "the flag reached in 82.5% or more of the last 50 training episodes from the start",
            "a_new_rule 3": "a_new_rule 3", "nonsense": "nonsense"}
    for recorded, words in said.items():
        assert stop_text({"stopped_by": recorded, "config": {"window": 50}}, mario) == words
    assert stop_text({}, mario) == "–"


def test_a_seeds_score_gives_its_full_length_share_where_the_bar_asks_for_one():
    from types import SimpleNamespace

    from rlcore.environments.registry import get_experiment
    from tools.docgen.main import evaluation_cell

    minitaur = SimpleNamespace(experiment="minitaur", name="sac", bar=get_experiment("minitaur").bar("sac"),
                               evaluation={"mean": 20.45})  # the shipped model's: two decimals
    lander = SimpleNamespace(experiment="lunar_lander", name="dqn", bar=get_experiment("lunar_lander").bar("dqn"),
                             evaluation={"mean": 270.7})  # one decimal, as its shipped score
    walked = {"mean": 18.56, "episodes": 30, "time_limit_share": 0.9333}
    assert evaluation_cell(walked, minitaur) == "18.56 over 30 (93% full length)"
    assert evaluation_cell(walked, lander) == "18.6 over 30"  # its bar asks for no such share
    assert evaluation_cell({"mean": 18.56, "episodes": 30}, minitaur) == "18.56 over 30"  # not recorded


def test_a_headline_recipe_is_held_to_its_bar_over_seeds_and_the_summary_says_whether_it_met_it():
    """Issue 49's bars, declared in the registry beside each shipped model's bar: Minitaur's IQM over 5
    seeds at least 11.3; Mario 1-1's median flag share over 3 seeds at least 8 of 10 and every seed at
    least 5 of 10. The README's seed summary says met or not met from the kept sweep's report."""
    from types import SimpleNamespace

    from rlcore.environments.registry import get_experiment
    from tools.docgen.main import seeds_bar_text

    minitaur = get_experiment("minitaur").bar("sac").over_seeds
    mario = get_experiment("mario_ppo").bar("1-1").over_seeds
    assert get_experiment("mario_ppo").bar("1-2").over_seeds is None
    assert minitaur.met_by(11.3, [0.9, 30.0, 11.3, 11.3, 11.3]) and not minitaur.met_by(11.29, [20.0] * 5)
    assert minitaur.met_by(20.0, [20.0] * 4) is None  # 4 of its 5 seeds: not judged
    assert mario.met_by(0.8, [0.5, 0.8, 0.9]) and not mario.met_by(0.9, [0.4, 0.9, 1.0])  # one seed below 5 of 10
    assert mario.met_by(0.7, [0.6, 0.7, 1.0]) is False
    assert minitaur.describe(share=False) == "IQM over 5 seeds >= 11.3"
    assert mario.describe(share=True) == "median over 3 seeds >= 80%, every seed >= 50%"

    def model(bar, evaluation, aggregates, seeds):
        return SimpleNamespace(bar=bar, evaluation=evaluation,
                               sweep=SimpleNamespace(aggregates=aggregates, seeds=list(enumerate(seeds))))
    walk = model(get_experiment("minitaur").bar("sac"), {"mean": 20.45}, {"iqm": (13.4, 0.9, 20.8)},
                 [18.6, 20.8, 0.9, 11.3, 12.0])
    assert seeds_bar_text(walk) == f" Bar over seeds: IQM over 5 seeds >= 11.3 ({minitaur.reason}): **met**."
    walk.sweep.seeds = walk.sweep.seeds[:4]
    assert seeds_bar_text(walk).endswith("): not judged yet (4 of 5 seeds kept).")
    flags = model(get_experiment("mario_ppo").bar("1-1"), {"success_share": 0.8}, {"median": (0.9, 0.6, 1.0)},
                  [0.9, 1.0, 0.4])
    assert seeds_bar_text(flags).endswith("): **not met**.")
    assert seeds_bar_text(model(get_experiment("lunar_lander").bar("dqn"), {"mean": 270.7}, {"iqm": (257.4, 0, 0)},
                                [270.7] * 5)) == ""  # no bar over seeds set
