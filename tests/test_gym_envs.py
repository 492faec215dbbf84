"""Any Gymnasium id trains without an experiment package (issue 47): Acrobot-v1 (dqn, a2c, ppo),
Pendulum-v1 (sac), CartPole-v1 (ppo), FrozenLake-v1 (dqn, its Discrete observations one-hot) and a user's
own registered env, each a short run end to end
(train, final evaluation, load, evaluate; render and export on some), and a mismatch of env and
algorithm is one line and exit status 2 before any run folder exists."""
import json
import os
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from rlcore import api
from rlcore.errors import UserError
from tests.test_cli import run as cli

ROOT = Path(__file__).resolve().parents[1]


def check_run(run, env_id, algo, eval_episodes):
    """What every finished run must hold: the env recorded, the evaluation, a loadable policy."""
    meta = json.loads((run.model_dir / "meta.json").read_text())
    assert meta == run.meta
    assert (meta["experiment"], meta["algo"], meta["preset"]) == (env_id, algo, "default")
    assert meta["env"]["gymnasium_id"] == env_id.rpartition(":")[2]
    assert meta["command"].startswith(f"rlcore.api.train({env_id!r}, {algo!r}")
    assert run.evaluation["episodes"] == eval_episodes and len(run.evaluation["per_episode"]) == eval_episodes
    assert run.evaluation["seeds"].startswith("1000000..")  # unseen seeds, as main.py train
    policy = api.load(run.run_dir)  # a finished run's folder stands for its model
    env = policy.make_env()
    obs, _ = env.reset(seed=3)
    action = policy.predict(obs)
    assert env.action_space.contains(np.asarray(action, env.action_space.dtype).reshape(env.action_space.shape))
    batch = policy.predict(np.stack([obs, obs, obs]))
    assert len(batch) == 3
    env.close()
    return policy


@pytest.mark.parametrize("algo, budget", [
    ("dqn", dict(episodes=2, hidden=(32, 32))),
    ("a2c", dict(episodes=2, actor_hidden=(32,), critic_hidden=(32,))),
    ("ppo", dict(steps=1024, num_envs=2, n_steps=256, epochs=2, minibatch=256)),
])
def test_acrobot(tmp_path, algo, budget):
    run = api.train("Acrobot-v1", algo, run_dir=tmp_path / "run", final_eval_episodes=2, progress=False,
                       **budget)
    policy = check_run(run, "Acrobot-v1", algo, 2)
    assert run.meta["config"]["max_episode_steps"] == 0  # the registered limit (500)
    assert max(r["length"] for r in run.evaluation["per_episode"]) <= 500
    result = api.evaluate(policy, episodes=2, seed_base=5)
    assert result["seeds"] == "5..6" and result["episodes"] == 2 and "greedy return" in result["line"]


def test_one_hot_is_the_index_of_a_discrete_observation():
    from rlcore.environments.gym_experiment import OneHotObservation, one_hot

    assert one_hot(2, gym.spaces.Discrete(4)).tolist() == [0, 0, 1, 0]
    assert one_hot(-1, gym.spaces.Discrete(3, start=-1)).tolist() == [1, 0, 0]  # a space starting at -1
    env = OneHotObservation(gym.make("FrozenLake-v1"))
    obs, _ = env.reset(seed=0)
    assert env.observation_space == gym.spaces.Box(0.0, 1.0, (16,), np.float32) and env.observation_space.contains(obs)
    assert obs.dtype == np.float32 and obs.sum() == 1.0 and obs[0] == 1.0  # FrozenLake starts in cell 0
    env.close()


def test_frozen_lake_dqn_sees_its_cells_one_hot(tmp_path):
    """A Discrete observation space (FrozenLake's 16 cells) is given to the networks one-hot and recorded."""
    run = api.train("FrozenLake-v1", "dqn", run_dir=tmp_path / "run", episodes=5, hidden=(16,),
                    final_eval_episodes=2, progress=False)
    policy = check_run(run, "FrozenLake-v1", "dqn", 2)
    assert run.meta["env"]["observations_one_hot"] is True
    assert policy.make_env().observation_space.shape == (16,)


def test_pendulum_sac_rescales_actions(tmp_path, sac_without_xla):
    run = api.train("Pendulum-v1", "sac", run_dir=tmp_path / "run", steps=400, learning_starts=200,
                       batch_size=32, actor_hidden=(32, 32), critic_hidden=(32, 32), final_eval_episodes=2,
                       progress=False)
    policy = check_run(run, "Pendulum-v1", "sac", 2)
    assert run.meta["env"]["actions_rescaled_to"] == [-1, 1]
    env = policy.make_env()
    assert (env.action_space.low, env.action_space.high) == (-1.0, 1.0)  # the actor's range
    assert env.unwrapped.action_space.high[0] == 2.0  # Pendulum's own torque bound, reached at +1
    sampled = policy.predict(env.reset(seed=0)[0], deterministic=False, rng=np.random.default_rng(0))
    assert sampled.shape == (1,) and -1.0 <= sampled[0] <= 1.0
    env.close()


def test_cartpole_ppo_cli_evaluate_render_export(tmp_path, capsys):
    run_dir = tmp_path / "run"
    code, out, err = cli(capsys, "train", "CartPole-v1", "ppo", "--steps", "1024", "--num-envs", "4",
                         "--n-steps", "128", "--minibatch", "128", "--epochs", "2", "--hidden", "32,32",
                         "--final-eval-episodes", "3", "--run-dir", str(run_dir), "--wandb", "off",
                         "--no-progress")
    assert code == 0, err
    assert "evaluation (unseen seeds): greedy return" in out
    meta = json.loads((run_dir / "model" / "meta.json").read_text())
    assert meta["experiment"] == "CartPole-v1" and meta["config"]["hidden"] == [32, 32]
    assert meta["command"].startswith("python ") and "train CartPole-v1 ppo" in meta["command"]
    assert meta["evaluation"]["episodes"] == 3
    code, out, err = cli(capsys, "evaluate", "CartPole-v1", "ppo", "--model", str(run_dir), "--episodes", "2")
    assert code == 0, err
    assert "CartPole-v1 ppo" in out and "over 2 episodes" in out
    gif = api.render(run_dir, tmp_path / "cartpole.gif")
    assert gif.stat().st_size > 0
    record = api.export(run_dir, "savedmodel", tmp_path / "export", observations=32)
    assert record["experiment"] == "CartPole-v1" and record["kind"] == "ppo"
    assert (tmp_path / "export" / "export.json").is_file()


def test_user_env_module_trains_learns_and_loads_in_a_fresh_process(tmp_path):
    """``MODULE:ID`` imports the user's module (which registers its env); the model folder alone
    rebuilds the env later, in a process that never imported that module. PPO's MLP body learns it."""
    run = api.train("tests.user_env:Chase-v0", "ppo", run_dir=tmp_path / "run", steps=6144, num_envs=4,
                       n_steps=64, minibatch=64, epochs=4, lr=3e-3, entropy_coef=0.0, final_eval_episodes=10,
                       progress=False)
    check_run(run, "tests.user_env:Chase-v0", "ppo", 10)
    assert run.evaluation["mean"] >= 17.0, run.evaluation  # random play scores ~10 of 20
    code = ("from rlcore import api; import gymnasium; assert 'Chase-v0' not in gymnasium.registry; "
            f"print(api.evaluate({str(run.model_dir)!r}, episodes=3)['mean'])")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.strip().splitlines()[-1]) >= 17.0
    for name in ("tests.user_env:Chase-v0", "Chase-v0"):  # the CLI takes the env as trained, or by its id
        done = subprocess.run([sys.executable, str(ROOT / "main.py"), "evaluate", name, "ppo", "--model",
                               str(run.run_dir), "--episodes", "2"], cwd=tmp_path, capture_output=True, text=True,
                              timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
        assert done.returncode == 0, done.stderr[-2000:]
        assert "over 2 episodes" in done.stdout and "Overriding environment" not in done.stderr, done.stderr


def test_registered_by_id_alone_reloads_from_its_record(tmp_path, capsys):
    """An env registered in the training process (a notebook) under a string entry point: the CLI's
    evaluate finds it from the model's meta.json in a new process."""
    import tests.user_env  # noqa: F401  registers Chase-v0 here, as a notebook would

    run = api.train("Chase-v0", "dqn", run_dir=tmp_path / "run", episodes=3, final_eval_episodes=0,
                       progress=False)
    assert run.evaluation is None  # final_eval_episodes=0: none, as --final-eval-episodes 0
    done = subprocess.run([sys.executable, str(ROOT / "main.py"), "evaluate", "Chase-v0", "dqn", "--model",
                           str(run.run_dir), "--episodes", "2"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Chase-v0 dqn" in done.stdout and "over 2 episodes" in done.stdout


@pytest.mark.parametrize("env_id, algo, message", [
    ("Acrobot-v1", "sac", "error: sac does not fit Acrobot-v1: it needs continuous actions (a 1-D Box), and the "
                          "env's are Discrete(3); algorithms that fit it: dqn, ddqn, dueling_dqn, dueling_ddqn, "
                          "a2c, ppo"),
    ("Pendulum-v1", "dqn", "error: dqn does not fit Pendulum-v1: it needs discrete actions"),
    ("CarRacing-v3", "dqn", "error: dqn does not fit CarRacing-v3: it needs discrete actions"),
    ("Blackjack-v1", "ppo", "error: ppo does not fit Blackjack-v1: it needs vector observations (a 1-D Box) "
                            "or uint8 images"),
    ("NoSuchEnv-v0", "dqn", "error: NoSuchEnv-v0 is not a registered Gymnasium id"),
    ("no_such_module:Thing-v0", "dqn", "error: cannot import 'no_such_module'"),
])
def test_mismatch_is_one_line_and_exit_2(tmp_path, capsys, env_id, algo, message):
    code, out, err = cli(capsys, "train", env_id, algo, "--run-dir", str(tmp_path / "run"), "--steps", "10")
    assert code == 2
    assert err.startswith(message) and err.count("\n") == 1, err
    assert not (tmp_path / "run").exists()
    with pytest.raises(UserError, match=message.removeprefix("error: ")[:30]):
        api.train(env_id, algo, run_dir=tmp_path / "run", steps=10)
    assert not (tmp_path / "run").exists()


def test_an_image_env_fits_every_discrete_family_and_dqn_trains_on_its_frames(tmp_path):
    """An image env with discrete actions: the DQN family, A2C and PPO fit it (their CNN bodies); SAC,
    which needs continuous actions, says so. A short DQN run keeps its frames uint8 in the replay memory."""
    from rlcore.environments.registry import get_experiment

    gym.register("ImageSign-v0", entry_point="tests.toy:ImageSignEnv")
    try:
        exp = get_experiment("ImageSign-v0")
        assert list(exp.algos) == ["dqn", "ddqn", "dueling_dqn", "dueling_ddqn", "a2c", "ppo"]
        with pytest.raises(UserError, match=r"^sac does not fit ImageSign-v0: it needs continuous actions"):
            exp.algo("sac")
        run = api.train("ImageSign-v0", "dueling_ddqn", run_dir=tmp_path / "run", episodes=3, final_eval_episodes=2,
                        learning_starts=8, batch_size=8, progress=False)
        with np.load(tmp_path / "run" / "replay.npz") as replay:
            assert replay["obs"].dtype == np.uint8 and replay["obs"].shape[1:] == (8, 8, 2)
        assert np.isfinite(run.evaluation["mean"])
    finally:
        del gym.registry["ImageSign-v0"]


def test_every_hyperparameter_is_a_flag_and_checked(capsys):
    code, out, err = cli(capsys, "train", "Acrobot-v1", "ppo", "--help")
    assert code == 0
    for flag in ("--hidden", "--lr", "--n-steps", "--gae-lambda", "--clip"):
        assert flag in out
    code, out, err = cli(capsys, "train", "Acrobot-v1", "dqn", "--gamma", "1.5")
    assert code == 2 and "--gamma" in err and err.count("\n") == 1
    with pytest.raises(UserError, match="unknown hyperparameter"):
        api.train("Acrobot-v1", "dqn", learning_rate=1e-3)


def test_a_user_env_run_is_named_as_trained_or_by_its_id():
    from rlcore.environments.gym_experiment import names_the_env

    assert names_the_env("tests.user_env:Chase-v0", "tests.user_env:Chase-v0")
    assert names_the_env("Chase-v0", "tests.user_env:Chase-v0") and names_the_env(None, "lunar_lander")
    assert not names_the_env("Chase-v1", "tests.user_env:Chase-v0") and not names_the_env("Chase-v0", "Chase-v1")
    assert not names_the_env("user_env:Chase-v0", "tests.user_env:Chase-v0")


def test_an_env_without_a_time_limit_gets_one_so_no_episode_runs_forever(tmp_path):
    """Chase never ends an episode itself; registered without max_episode_steps (as CliffWalking-v1 is), a
    greedy policy would play one evaluation episode for good. Episodes end at the added limit instead,
    recorded in meta.json; --max-episode-steps still sets another."""
    from rlcore.environments.gym_experiment import ADDED_TIME_LIMIT

    gym.register("Endless-v0", entry_point="tests.user_env:ChaseEnv")
    try:
        run = api.train("Endless-v0", "dqn", run_dir=tmp_path / "run", episodes=1, final_eval_episodes=1,
                        progress=False)
        assert run.meta["env"]["time_limit_added"] == ADDED_TIME_LIMIT
        assert run.evaluation["time_limit_share"] == 1.0 and run.meta["env_steps"] == ADDED_TIME_LIMIT
        short = api.train("Endless-v0", "dqn", run_dir=tmp_path / "short", episodes=1, final_eval_episodes=1,
                          max_episode_steps=30, progress=False)
        assert short.meta["env_steps"] == 30
    finally:
        del gym.registry["Endless-v0"]
    api_page = (Path(__file__).resolve().parents[1] / "docs" / "api.md").read_text()
    assert f"gets one of {ADDED_TIME_LIMIT:,} steps" in " ".join(api_page.split())  # the page says the limit
