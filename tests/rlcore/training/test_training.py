"""The real training loops on a tiny env: they learn, mark episode ends right, start from another
model, stop on NaN, reproduce a seed and write their outputs (evaluation during training:
test_periodic_eval.py; resuming: test_resume.py)."""
import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from rlcore.algorithms.a2c import train as a2c_trainer
from rlcore.algorithms.ppo import train as ppo_trainer
from rlcore.algorithms.sac import train as sac_trainer
from rlcore.errors import UserError
from rlcore.host.cpu import cpu_description
from rlcore.models.policies import load_policy
from rlcore.training.evaluation import evaluate
from tests import toy
from tests.toy import TRAINERS

pytestmark = pytest.mark.usefixtures("toy_experiments", "sac_without_xla")


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_learns_the_toy_task(algo, tmp_path):
    model_dir = TRAINERS[algo].train(toy.spec(algo, tmp_path))
    exp, meta, policy = load_policy(model_dir)
    returns = evaluate(exp, policy, episodes=20, progress=False)
    assert returns.mean() >= 9.0, f"{algo} greedy return {returns.mean()} after {meta['episodes']} episodes"
    assert meta["command"] == "pytest" and meta["env_steps"] > 0 and meta["seed"] == 0
    assert meta["cpu"] == cpu_description()  # where the seed's numbers came from (parsing: test_model_folder)
    assert (model_dir / meta["plot"]).stat().st_size > 1000
    csv_lines = (model_dir / "metrics.csv").read_text().splitlines()
    assert csv_lines[0].startswith("episode,total_points,av_latest_points,target_ave_scores")
    assert len(csv_lines) == meta["episodes"] + 1


def test_ppo_learns_the_picture_task_and_stops_on_the_success_share(tmp_path):
    from rlcore.training.evaluation import evaluate_success, summarize_success

    model_dir = ppo_trainer.train(toy.spec("ppo", tmp_path))
    meta = json.loads((model_dir / "meta.json").read_text())
    assert meta["episodes"] < 600, "stopped by the budget, not by the success share"
    assert meta["stopped_by"].startswith("stop_success_share")
    rollouts = (tmp_path / "ppo" / "rollouts.csv").read_text().splitlines()
    assert rollouts[0].startswith("rollout,env_steps,episodes_ended,successes,max_score,loss,policy_loss")
    timing = pd.read_csv(tmp_path / "ppo" / "rollouts.csv")[["collect_seconds", "update_seconds"]]
    assert (timing.collect_seconds > 0).all() and (timing.update_seconds >= 0).all()  # a toy update: ~ms
    rounding = 0.05 + 0.0005 * timing.size  # meta keeps 0.1 s, the table 1 ms per cell
    assert timing.update_seconds.sum() > 0 and timing.to_numpy().sum() <= meta["wall_seconds"] + rounding
    metrics = (model_dir / "metrics.csv").read_text().splitlines()
    assert "success_share" in metrics[0] and len(metrics) == meta["episodes"] + 1
    assert (model_dir / "toy_image_Progress_ppo.png").stat().st_size > 1000  # progress + success share
    exp, _, policy = load_policy(model_dir)
    records = evaluate_success(policy.make_env, policy.sample, 10, 10_000, "won", "score", progress=False)
    assert summarize_success(records, "score")["success_share"] >= 0.8
    env = policy.make_env().unwrapped  # the greedy action is right for both pictures: 1 when s > 0
    pictures = []
    for sign in (-1.0, 1.0):
        env.sign = sign
        pictures.append(env._obs())
    assert policy(np.asarray(pictures)).tolist() == [0, 1]


def test_sac_learns_the_reach_task(tmp_path):
    model_dir = sac_trainer.train(toy.spec("sac", tmp_path))
    exp, meta, policy = load_policy(model_dir)
    returns = evaluate(exp, policy, episodes=20, progress=False)
    assert returns.mean() >= -1.0, f"SAC mean-action return {returns.mean():.2f}; random is about -5"
    assert meta["env_steps"] == 2500
    # each episode's length is logged (Minitaur's falls show there); the run ends with a whole episode
    steps = pd.read_csv(model_dir / "metrics.csv")["episode_steps"]
    assert steps.sum() == 2500 and steps.min() >= 1


def _end_by_termination(monkeypatch, env_class):
    """Make a toy env end its episodes by termination where its time limit would truncate them."""
    step = env_class.step

    def terminating_step(self, action):
        obs, reward, terminated, truncated, info = step(self, action)
        return obs, reward, terminated or truncated, False, info
    monkeypatch.setattr(env_class, "step", terminating_step)


@pytest.mark.parametrize("ending", ["time limit", "termination"])
@pytest.mark.parametrize("algo", ["dqn", "sac"])
def test_replay_marks_terminations_only_so_a_time_limit_still_bootstraps(algo, ending, tmp_path, monkeypatch):
    """The toy envs end every 10 steps by their time limit; made to end by termination instead,
    the replay must store terminated = 1 at exactly those steps, and 0 everywhere else."""
    from rlcore.algorithms.replay import ReplayMemory

    env_class = {"dqn": toy.SignEnv, "sac": toy.ReachEnv}[algo]
    add, stored = ReplayMemory.add, []
    if ending == "termination":
        _end_by_termination(monkeypatch, env_class)

    def recording_add(self, obs, action, reward, next_obs, terminated):
        stored.append(float(terminated))
        return add(self, obs, action, reward, next_obs, terminated)
    monkeypatch.setattr(ReplayMemory, "add", recording_add)
    extra = {"sac": {"max_env_steps": 0, "learning_starts": 20}}.get(algo, {})
    TRAINERS[algo].train(toy.spec(algo, tmp_path, stop_score=99.0, max_episodes=5, **extra))
    assert len(stored) == 50
    want = [float(ending == "termination" and (i + 1) % 10 == 0) for i in range(50)]
    assert stored == want


@pytest.mark.parametrize("ending", ["time limit", "termination"])
def test_a2c_rollouts_mark_terminations_apart_from_episode_ends(ending, tmp_path, monkeypatch):
    """What A2C's update gets: ``dones`` at every episode end, ``terminated`` only at terminations
    (a time limit bootstraps); swapped, the GAE would bootstrap through real ends."""
    from rlcore.algorithms.a2c.agent import A2CAgent

    update, seen = A2CAgent.update, []
    if ending == "termination":
        _end_by_termination(monkeypatch, toy.SignEnv)

    def recording_update(self, obs, actions, rewards, next_obs, terminated, dones):
        seen.append((terminated.copy(), dones.copy()))
        return update(self, obs, actions, rewards, next_obs, terminated, dones)
    monkeypatch.setattr(A2CAgent, "update", recording_update)
    spec = toy.spec("a2c", tmp_path, stop_score=99.0, max_episodes=8)
    TRAINERS["a2c"].train(spec)
    terminated = np.concatenate([t for t, _ in seen])  # [steps, envs], steps counted from the start
    dones = np.concatenate([d for _, d in seen])
    ends = ((np.arange(len(dones)) + 1) % 10 == 0)[:, None] & np.ones(dones.shape[1], bool)
    np.testing.assert_array_equal(dones, ends)
    np.testing.assert_array_equal(terminated, ends if ending == "termination" else np.zeros_like(ends))


def test_ppo_starts_from_another_models_weights_and_records_it(tmp_path):
    from rlcore.algorithms.ppo.agent import PPOAgent
    from rlcore.networks.saving import load_keras_model

    first = ppo_trainer.train(toy.spec("ppo", tmp_path / "a", max_env_steps=64, stop_success_share=0.0))
    parent = load_keras_model(first / "actor_critic.h5").get_weights()
    spec = toy.spec("ppo", tmp_path / "b", max_env_steps=64, stop_success_share=0.0, init_from=str(first))
    agent = PPOAgent((8, 8, 2), 2, spec.config)
    record = ppo_trainer.init_weights(agent, str(first), "toy_image", "ppo")
    for got, want in zip(agent.get_weights(), parent):
        np.testing.assert_array_equal(got, want)
    assert record["path"] == str(first) and record["env_steps"] == 64
    meta = json.loads((ppo_trainer.train(spec) / "meta.json").read_text())
    assert meta["config"]["init_from"] == str(first)
    assert meta["init_from"]["commands"] == ["pytest"] and meta["init_from"]["env_steps"] == 64


def test_init_from_a_model_of_another_experiment_is_refused(tmp_path):
    first = a2c_trainer.train(toy.spec("a2c", tmp_path / "a", max_episodes=3, stop_score=99.0))
    spec = toy.spec("ppo", tmp_path / "b", init_from=str(first))
    with pytest.raises(UserError, match="holds a toy a2c model, not toy_image ppo"):
        ppo_trainer.train(spec)
    with pytest.raises(UserError, match="no meta.json"):
        ppo_trainer.train(toy.spec("ppo", tmp_path / "c", init_from=str(tmp_path)))


NAN_ENVS = {"dqn": toy.SignEnv, "a2c": toy.SignEnv, "ppo": toy.ImageSignEnv, "sac": toy.ReachEnv}


@pytest.mark.parametrize("algo", sorted(TRAINERS))
def test_a_nan_reward_ends_the_run_with_one_clear_error(algo, tmp_path, monkeypatch):
    """NaN rewards make the loss NaN: the run stops with a UserError naming the env step, not a
    TensorFlow traceback."""
    env_class = NAN_ENVS[algo]
    honest_step = env_class.step

    def nan_step(self, action):
        obs, _, terminated, truncated, info = honest_step(self, action)
        return obs, float("nan"), terminated, truncated, info
    monkeypatch.setattr(env_class, "step", nan_step)
    with pytest.raises(UserError, match=r"training diverged: .*NaN.* at env step \d+; "):
        TRAINERS[algo].train(toy.spec(algo, tmp_path))


SHORT = {"dqn": {"max_episodes": 20}, "a2c": {"max_episodes": 40}, "ppo": {"max_episodes": 30},
         "sac": {"max_env_steps": 400}}


@pytest.mark.parametrize("algo", sorted(TRAINERS))
def test_a_seed_reproduces_its_run_and_another_seed_does_not(algo, tmp_path):
    """Same seed, same episodes, returns and losses (all but the wall clock); seed 1 differs."""
    def metrics(name, seed):
        spec = dataclasses.replace(toy.spec(algo, tmp_path / name, **SHORT[algo]), seed=seed)
        TRAINERS[algo].train(spec)
        return pd.read_csv(spec.run_dir / "metrics.csv").drop(columns=["wall_seconds"])
    first, again, other = metrics("a", 0), metrics("b", 0), metrics("c", 1)
    pd.testing.assert_frame_equal(first, again)
    assert not first["total_points"].equals(other["total_points"])


def test_ppo_logs_the_experiments_info_keys(tmp_path):
    spec = toy.spec("ppo", tmp_path, max_episodes=30, stop_success_share=0.0)
    spec.experiment = dataclasses.replace(spec.experiment, info_keys=("won", "absent"))
    ppo_trainer.train(spec)
    rows = pd.read_csv(spec.run_dir / "metrics.csv")
    # an episode's final info value (won: 8 of 10 right) beside the trainer's own success column
    assert len(rows) >= 30 and (rows["won"] == rows["success"]).all() and rows["won"].nunique() == 2
    assert rows["absent"].isna().all()  # a key the env never reports stays empty


def test_sac_logs_the_experiments_info_keys(tmp_path):
    spec = toy.spec("sac", tmp_path, max_env_steps=300, learning_starts=100)
    spec.experiment = dataclasses.replace(spec.experiment, info_keys=("t", "absent"))
    sac_trainer.train(spec)
    rows = pd.read_csv(spec.run_dir / "metrics.csv")
    assert len(rows) == 30
    assert (rows["t"] == 10).all()  # the final step's info value (Minitaur logs its metres walked so)
    assert rows["absent"].isna().all()  # declared, not reported by the env: empty


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_training_envs_are_seeded_below_the_evaluation_seeds(algo, tmp_path, monkeypatch):
    """The seeds the trainers hand their envs, also after a resume and at the largest run seed, stay
    below every experiment's evaluation and selection seeds."""
    from rlcore.environments.registry import experiment_names, get_experiment
    from rlcore.environments.seeding import MAX_RUN_SEED, TRAINING_SEED_SPAN, training_env_seed

    seeds, reset = [], toy.SignEnv.reset

    def spy(self, *, seed=None, options=None):
        if seed is not None:
            seeds.append(seed)
        return reset(self, seed=seed, options=options)

    monkeypatch.setattr(toy.SignEnv, "reset", spy)
    spec = toy.spec(algo, tmp_path, max_episodes=6, stop_score=99.0)
    spec.seed = MAX_RUN_SEED
    TRAINERS[algo].train(spec)
    first = len(seeds)
    spec.resume, spec.config = True, dataclasses.replace(spec.config, max_episodes=12)
    TRAINERS[algo].train(spec)
    assert first > 0 and len(seeds) > first  # the resume reseeded its envs
    assert seeds[0] == training_env_seed(MAX_RUN_SEED, 0) and seeds[first] >= training_env_seed(MAX_RUN_SEED, 6)
    lowest = min(min(get_experiment(n).eval_seed_base, get_experiment(n).selection_seed_base)
                 for n in experiment_names() if not n.startswith("toy"))  # the package's, not this test's
    assert max(seeds) < TRAINING_SEED_SPAN <= lowest, (max(seeds), lowest)
