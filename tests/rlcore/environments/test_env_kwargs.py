"""``--env-kwargs`` and ``env_kwargs=`` (issue 65): a Gymnasium env's constructor arguments, checked against
the env's parameters before any run folder exists, recorded in meta.json, and used again by evaluate,
export, a resume and api.load. LunarLander-v3 with continuous=True is SAC's env."""
import json

import pytest

from rlcore import api
from rlcore.environments.env_kwargs import parse_env_kwargs
from rlcore.errors import UserError
from tests.test_cli import run as cli

SAC_SMALL = ["--episodes", "1", "--learning-starts", "100", "--batch-size", "32", "--buffer-size", "1000",
             "--actor-hidden", "16,16", "--critic-hidden", "16,16", "--max-episode-steps", "150"]
QUIET = ["--wandb", "off", "--no-progress", "--final-eval-episodes", "1"]


def test_key_value_pairs_and_json_give_the_same_arguments():
    expected = {"continuous": True, "wind_power": 5.5, "name": "x", "gravity": -9}
    assert parse_env_kwargs("continuous=True wind_power=5.5 name=x gravity=-9") == expected
    assert parse_env_kwargs("continuous=true,wind_power=5.5,name=x,gravity=-9") == expected
    assert parse_env_kwargs(json.dumps(expected)) == expected
    for bad in ("continuous", "[1, 2]", "{not json", "2x=1"):
        with pytest.raises(UserError):
            parse_env_kwargs(bad)


def test_continuous_lunar_lander_trains_sac_evaluates_exports_and_resumes(tmp_path, capsys):
    run_dir = tmp_path / "run"
    code, out, err = cli(capsys, "train", "LunarLander-v3", "sac", "--env-kwargs", "continuous=True", *SAC_SMALL,
                         *QUIET, "--run-dir", str(run_dir))
    assert code == 0, err
    meta = json.loads((run_dir / "model" / "meta.json").read_text())
    assert meta["env"]["env_kwargs"] == {"continuous": True}
    code, out, err = cli(capsys, "evaluate", "LunarLander-v3", "sac", "--model", str(run_dir), "--episodes", "1")
    assert code == 0 and "return" in out, err
    code, out, err = cli(capsys, "export", "LunarLander-v3", "sac", "--model", str(run_dir), "--format", "onnx",
                         "--out", str(tmp_path / "onnx"))
    assert code == 0, err
    assert json.loads((tmp_path / "onnx" / "export.json").read_text())["network"]["output"]["shape"] == [None, 2]
    code, out, err = cli(capsys, "train", "LunarLander-v3", "sac", "--resume", str(run_dir), "--episodes", "2", *QUIET)
    assert code == 0, err
    assert json.loads((run_dir / "model" / "meta.json").read_text())["env"]["env_kwargs"] == {"continuous": True}
    code, out, err = cli(capsys, "train", "LunarLander-v3", "sac", "--resume", str(run_dir), "--episodes", "3",
                         "--env-kwargs", "continuous=False", *QUIET)
    assert code != 0 and "--env-kwargs cannot change on a resume" in err
    env = api.load(run_dir).make_env()
    assert env.action_space.shape == (2,)  # continuous, as trained
    env.close()


@pytest.mark.parametrize("given, words", [
    ("gravity_well=3", "LunarLander-v3 takes no 'gravity_well'; its env takes"),
    ("render_mode=human", "render_mode is set by the command"),
])
def test_an_argument_the_env_does_not_take_is_one_line_before_any_folder(tmp_path, capsys, given, words):
    run_dir = tmp_path / "run"
    code, out, err = cli(capsys, "train", "LunarLander-v3", "dqn", "--env-kwargs", given, "--episodes", "1",
                         *QUIET, "--run-dir", str(run_dir))
    assert code == 2 and words in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not run_dir.exists()


def test_an_experiment_package_takes_no_env_kwargs(tmp_path, capsys):
    code, out, err = cli(capsys, "train", "lunar_lander", "dqn", "--env-kwargs", "continuous=True", *QUIET,
                         "--run-dir", str(tmp_path / "run"))
    assert code == 2 and "--env-kwargs is for a Gymnasium id" in err, err


def test_the_api_takes_and_records_them(tmp_path):
    run = api.train("LunarLander-v3", "sac", env_kwargs={"continuous": True}, run_dir=tmp_path / "run",
                    episodes=1, learning_starts=100, batch_size=32, buffer_size=1000, actor_hidden=(16, 16),
                    critic_hidden=(16, 16), max_episode_steps=100, final_eval_episodes=0, progress=False)
    assert run.meta["env"]["env_kwargs"] == {"continuous": True}
    assert "env_kwargs={'continuous': True}" in run.meta["command"]


def test_a_sweep_records_its_env_kwargs_and_checks_its_trials_with_them(tmp_path):
    from rlcore.sweeps.sweep import Sweep, check

    sweep = Sweep("LunarLander-v3", "sac", "s", str(tmp_path), [0, 1], env_kwargs={"continuous": True})
    check(sweep)  # SAC fits the continuous lander
    sweep.save()
    assert Sweep.load(tmp_path).env_kwargs == {"continuous": True}
    with pytest.raises(UserError, match="sac does not fit LunarLander-v3"):
        check(Sweep("LunarLander-v3", "sac", "s", str(tmp_path), [0]))


def test_the_sweep_command_takes_them(capsys):
    from rlcore.cli.parser import build_parser

    argv = ["sweep", "LunarLander-v3", "sac", "--env-kwargs", '{"continuous": true}', "--seeds", "0-1"]
    assert build_parser(argv).parse_args(argv).env_kwargs == {"continuous": True}
