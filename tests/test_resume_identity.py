"""A resume cannot change what a run is (its env, its networks, its seed or preset), and no flag is
accepted and then ignored: each is one line and exit status 2, before anything is written."""
import json

import numpy as np
import pytest

from rlcore.environments.registry import get_experiment
from rlcore.hyperparams.flags import defining_fields, to_dict
from tests.test_cli import run


def fake_run(folder, experiment: str, algo: str, preset: str = "default", seed: int = 0, **changes):
    """A run folder whose checkpoint records ``experiment algo`` (the state only: enough to be refused)."""
    import dataclasses

    config = dataclasses.replace(get_experiment(experiment).preset(algo, preset), **changes)
    state = {"experiment": experiment, "algo": algo, "preset": preset, "seed": seed,
             "config": to_dict(config), "returns": [], "env_steps": 0}
    folder.mkdir(parents=True)
    payload = np.frombuffer(json.dumps(state).encode(), np.uint8)
    np.savez(folder / "checkpoint.npz", state_json=payload)
    return folder


@pytest.mark.parametrize("experiment, algo, flag, value", [
    ("mario_ppo", "ppo", "--stage", "2"),
    ("mario_ppo", "ppo", "--frames", "history"),
    ("mario_ppo", "ppo", "--actions", "complex"),
    ("mario_ppo", "ppo", "--num-envs", "4"),
    ("lunar_lander", "dqn", "--hidden", "32,32"),
    ("lunar_lander", "dueling_ddqn", "--dueling", "false"),
    ("minitaur", "sac", "--obs-norm", "false"),
    ("cartpole", "a2c", "--max-episode-steps", "100"),
])
def test_resume_refuses_a_change_of_what_the_run_is(capsys, tmp_path, experiment, algo, flag, value):
    folder = fake_run(tmp_path / "run", experiment, algo)
    field = flag[2:].replace("-", "_")
    recorded = getattr(get_experiment(experiment).preset(algo, None), field)
    recorded = ",".join(map(str, recorded)) if isinstance(recorded, tuple) else str(recorded)
    assert recorded != value.replace("false", "False")
    before = sorted(p.name for p in folder.iterdir())
    code, out, err = run(capsys, "train", experiment, algo, "--resume", str(folder), flag, value)
    assert code == 2
    line = err.strip()
    assert "\n" not in line and flag in line and f"{field} = {recorded}" in line, line
    assert sorted(p.name for p in folder.iterdir()) == before  # nothing written there


def test_every_env_field_and_network_size_is_a_defining_field():
    mario = get_experiment("mario_ppo")
    fields = defining_fields(mario.preset("ppo", None), mario.env_fields)
    for name in ("world", "stage", "actions", "frames", "num_envs", "max_episode_steps", "init_from"):
        assert name in fields
    for name in ("lr", "entropy_coef", "max_env_steps", "checkpoint_rollouts", "precision", "restart_x"):
        assert name not in fields  # budgets, rates, coefficients, logging and curricula may change
    sac = get_experiment("minitaur").preset("sac", None)
    assert {"actor_hidden", "critic_hidden", "obs_norm"} <= set(defining_fields(sac))


def test_resume_may_change_budgets_rates_and_coefficients(tmp_path):
    """Given again with a new value, or a defining field with its recorded one: accepted."""
    folder = fake_run(tmp_path / "run", "lunar_lander", "dqn")
    from rlcore.training.run import build_spec

    spec = build_spec("lunar_lander", "dqn", run_dir=folder, resume=True,
                      overrides={"lr": 1e-4, "max_episodes": 50, "tau": 0.01, "hidden": get_experiment("lunar_lander").preset("dqn", None).hidden})
    assert (spec.config.lr, spec.config.max_episodes, spec.config.tau) == (1e-4, 50, 0.01)
    # what the resume changed, for meta.json (a defining field given with its recorded value changed nothing)
    preset = get_experiment("lunar_lander").preset("dqn", None)
    assert spec.changes == {"lr": [preset.lr, 1e-4], "max_episodes": [preset.max_episodes, 50],
                            "tau": [preset.tau, 0.01]}


@pytest.mark.parametrize("argv, words", [
    (["--seed", "3"], "--seed 3 cannot change on a resume"),
    (["--preset", "article"], "--preset article cannot change on a resume"),
])
def test_resume_refuses_another_seed_or_preset(capsys, tmp_path, argv, words):
    folder = fake_run(tmp_path / "run", "lunar_lander", "dqn")
    code, _, err = run(capsys, "train", "lunar_lander", "dqn", "--resume", str(folder), *argv)
    assert code == 2 and words in err, err


def test_resume_refuses_another_init_from_and_takes_its_own_folder_written_another_way(capsys, tmp_path,
                                                                                          monkeypatch):
    """init_from is used once, at a run's start, and recorded: another folder on a resume is refused (it was
    recorded and ignored); the recorded folder in another spelling (absolute, ./, a trailing slash, a Path
    from Python) is no change at all, and none is recorded."""
    from rlcore.api.training import _overrides
    from rlcore.training.run import build_spec
    from tests.test_cli import ROOT

    monkeypatch.chdir(ROOT)
    recorded = "saved_networks/mario_ppo/1-1"
    folder = fake_run(tmp_path / "run", "mario_ppo", "ppo", init_from=recorded)
    code, _, err = run(capsys, "train", "mario_ppo", "ppo", "--resume", str(folder), "--init-from",
                       "saved_networks/mario_ppo/1-2")
    assert code == 2 and "\n" not in err.strip(), err
    assert (f"--init-from saved_networks/mario_ppo/1-2 cannot change on a resume: the run in {folder} was recorded "
            f"with init_from = {recorded}, and it defines the weights the run started from") in err
    for spelling in (str(ROOT / recorded), "./" + recorded + "/"):
        spec = build_spec("mario_ppo", "ppo", run_dir=folder, resume=True, overrides={"init_from": spelling})
        assert (spec.config.init_from, spec.changes) == (recorded, {}), spelling
    assert _overrides({"init_from": ROOT / recorded}, None, None) == {"init_from": str(ROOT / recorded)}


@pytest.mark.parametrize("argv, words", [
    (["mario_ppo", "ppo", "--restart-share", "0.3"], "--restart-share does nothing here"),
    (["mario_ppo", "ppo", "--restart-keep", "furthest"], "--restart-keep does nothing here"),
    (["mario_ppo", "ppo", "--restart-x", "500", "--restart-weights", "deaths"], "--restart-weights does nothing"),
    (["mario_ppo", "ppo", "--restart-goal-x", "900"], "--restart-goal-x does nothing here"),
    (["mario_ppo", "ppo", "--restart-x", "500", "--restart-back-share", "0.4"], "--restart-back-share does nothing"),
    (["lunar_lander", "dqn", "--episodes", "5", "--max-episodes", "9"], "--episodes and --max-episodes"),
    (["lunar_lander", "dqn", "--steps", "5", "--max-env-steps", "9"], "--steps and --max-env-steps"),
    (["lunar_lander", "dqn", "--eps-decay-steps", "500"], "--eps-decay-steps does nothing here"),
    (["cartpole", "dqn", "--eps-decay", "0.9"], "--eps-decay does nothing here"),
    (["minitaur", "sac", "--eval-every-steps", "0", "--keep-best", "true"], "--keep-best does nothing here"),
])
def test_a_flag_that_would_do_nothing_is_refused(capsys, tmp_path, argv, words):
    code, _, err = run(capsys, "train", *argv, "--run-dir", str(tmp_path / "run"))
    assert code == 2 and words in err and "\n" not in err.strip(), err
    assert not (tmp_path / "run").exists()


def test_the_same_flags_with_what_they_need_are_accepted():
    from rlcore.hyperparams.flags import apply_overrides, check_no_inert

    mario = get_experiment("mario_ppo").preset("ppo", None)
    for given in ({"restart_x": 500, "restart_share": 0.3}, {"restart_every": 400, "restart_weights": "deaths"},
                  {"restart_x": 500, "restart_back_step": 50, "restart_goal_x": 900, "restart_back_share": 0.4}):
        check_no_inert(apply_overrides(mario, given), given)


def test_a_run_ended_by_its_step_budget_names_the_budget_to_raise(capsys, tmp_path):
    """Issue 65: `--resume RUN --episodes N` of a run that ended at its --steps budget was told to give a
    larger budget (--episodes or --steps), though a larger --episodes was given; the line names --steps."""
    run_dir = tmp_path / "run"
    quiet = ["--final-eval-episodes", "0", "--wandb", "off", "--no-progress"]
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--steps", "40", *quiet, "--run-dir", str(run_dir))
    assert code == 0, err
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "500", *quiet)
    assert code == 2 and "(--max-env-steps 40," in err
    assert err.strip().endswith("give a larger --steps (a larger --episodes alone does not lift a step budget)")


def test_a_finished_run_resumed_with_nothing_left_to_train_is_refused_and_left_as_it_was(capsys, tmp_path):
    """A new user's `--resume RUN --episodes 2` of a run finished at 3 episodes trained nothing, evaluated
    again and recorded a resume that did nothing; now one line, exit 2, files untouched. A larger budget
    goes on."""
    run_dir = tmp_path / "run"
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--episodes", "3", "--final-eval-episodes", "1",
                         "--wandb", "off", "--no-progress", "--run-dir", str(run_dir))
    assert code == 0, err
    before = {p.name: p.read_bytes() for p in (run_dir / "model").iterdir()} | {
        p.name: p.read_bytes() for p in run_dir.iterdir() if p.is_file() and p.name != ".lock"}
    for budget in (["--episodes", "2"], ["--episodes", "3"], ["--lr", "0.001"]):
        code, out, err = run(capsys, "train", "cartpole", "dqn", "--resume", str(run_dir), *budget,
                             "--final-eval-episodes", "1", "--wandb", "off", "--no-progress")
        assert code == 2, (budget, out, err)
        assert err.strip().startswith(f"error: nothing to train: the run in {run_dir} is finished, and what ended it "
                                      f"still holds (--max-episodes ")
        assert err.strip().endswith("; give a larger --episodes")
    after = {p.name: p.read_bytes() for p in (run_dir / "model").iterdir()} | {
        p.name: p.read_bytes() for p in run_dir.iterdir() if p.is_file() and p.name != ".lock"}
    assert after == before
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--resume", str(run_dir), "--episodes", "4",
                         "--final-eval-episodes", "1", "--wandb", "off", "--no-progress")
    assert code == 0, err
    meta_path = run_dir / "model" / "meta.json"
    assert json.loads(meta_path.read_text())["episodes"] == 4
    # stopped between its last checkpoint and its model (the model older than the checkpoint): it goes on
    meta = json.loads(meta_path.read_text())
    meta_path.write_text(json.dumps({**meta, "episodes": 3}))
    code, out, err = run(capsys, "train", "cartpole", "dqn", "--resume", str(run_dir), "--final-eval-episodes", "1",
                         "--wandb", "off", "--no-progress")
    assert code == 0, err
    assert json.loads(meta_path.read_text())["episodes"] == 4
