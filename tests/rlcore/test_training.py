"""The real training loops on a tiny env: they learn, checkpoint, resume and write their outputs."""
import csv
import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from rlcore.checkpoint import read_checkpoint_state
from rlcore.errors import UserError
from rlcore.evaluation import evaluate
from rlcore.policies import load_policy
from rlcore.trainers import a2c as a2c_trainer
from rlcore.trainers import dqn as dqn_trainer
from rlcore.trainers import ppo as ppo_trainer
from rlcore.trainers import sac as sac_trainer
from rlcore.trainers.spec import check_resumable
from rlcore.trainers.stopping import Interrupted
from tests import toy

TRAINERS = {"dqn": dqn_trainer, "a2c": a2c_trainer, "ppo": ppo_trainer, "sac": sac_trainer}


pytestmark = pytest.mark.usefixtures("toy_experiments")


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_learns_the_toy_task(algo, tmp_path):
    model_dir = TRAINERS[algo].train(toy.spec(algo, tmp_path))
    exp, meta, policy = load_policy(model_dir)
    returns = evaluate(exp, policy, episodes=20, progress=False)
    assert returns.mean() >= 9.0, f"{algo} greedy return {returns.mean()} after {meta['episodes']} episodes"
    assert meta["command"] == "pytest" and meta["env_steps"] > 0 and meta["seed"] == 0
    assert (model_dir / meta["plot"]).stat().st_size > 1000
    csv_lines = (model_dir / "metrics.csv").read_text().splitlines()
    assert csv_lines[0].startswith("episode,total_points,av_latest_points,target_ave_scores")
    assert len(csv_lines) == meta["episodes"] + 1


def test_ppo_learns_the_picture_task_and_stops_on_the_success_share(tmp_path):
    from rlcore.evaluation import evaluate_success, summarize_success

    model_dir = ppo_trainer.train(toy.spec("ppo", tmp_path))
    meta = json.loads((model_dir / "meta.json").read_text())
    assert meta["episodes"] < 600, "stopped by the budget, not by the success share"
    assert meta["stopped_by"].startswith("stop_success_share")
    rollouts = (tmp_path / "ppo" / "rollouts.csv").read_text().splitlines()
    assert rollouts[0].startswith("rollout,env_steps,episodes_ended,successes,max_score,loss,policy_loss")
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


@pytest.mark.parametrize("ending", ["time limit", "termination"])
@pytest.mark.parametrize("algo", ["dqn", "sac"])
def test_replay_marks_terminations_only_so_a_time_limit_still_bootstraps(algo, ending, tmp_path, monkeypatch):
    """The toy envs end every 10 steps by their time limit; made to end by termination instead,
    the replay must store terminated = 1 at exactly those steps, and 0 everywhere else."""
    from rlcore.replay import ReplayMemory

    env_class = {"dqn": toy.SignEnv, "sac": toy.ReachEnv}[algo]
    step, add, stored = env_class.step, ReplayMemory.add, []
    if ending == "termination":
        def terminating_step(self, action):
            obs, reward, terminated, truncated, info = step(self, action)
            return obs, reward, terminated or truncated, False, info
        monkeypatch.setattr(env_class, "step", terminating_step)

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
    from rlcore.agents.a2c import A2CAgent

    step, update, seen = toy.SignEnv.step, A2CAgent.update, []
    if ending == "termination":
        def terminating_step(self, action):
            obs, reward, terminated, truncated, info = step(self, action)
            return obs, reward, terminated or truncated, False, info
        monkeypatch.setattr(toy.SignEnv, "step", terminating_step)

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


@pytest.mark.parametrize("algo", ["dqn", "a2c", "ppo", "sac"])
def test_interrupt_then_resume_continues_the_counters(algo, tmp_path, monkeypatch):
    extra = {"ppo": {"stop_success_share": 0.0}, "sac": {"max_env_steps": 0, "learning_starts": 100}}
    spec = toy.spec(algo, tmp_path, stop_score=99.0, max_episodes=30, **extra.get(algo, {}))
    _interrupt_after(12, TRAINERS[algo], spec)
    state = read_checkpoint_state(spec.run_dir / "checkpoint.npz")
    assert len(state["returns"]) >= 12 and state["env_steps"] > 0
    # A crash after the checkpoint leaves rows the checkpoint does not know; resume must drop them.
    _append_rows_after_checkpoint(spec.run_dir / "metrics.csv", count=2)
    spec.resume, spec.command = True, "pytest --resume"
    seen_alpha = _watch_sac_temperature(monkeypatch) if algo == "sac" else []
    model_dir = TRAINERS[algo].train(spec)
    if algo == "sac":  # the first update after the resume starts from the checkpointed temperature
        assert seen_alpha[0] == pytest.approx(state["log_alpha"], abs=1e-7)
    meta = json.loads((model_dir / "meta.json").read_text())
    assert meta["command"] == "pytest" and meta["commands"] == ["pytest", "pytest --resume"]
    assert meta["episodes"] >= 30
    assert meta["env_steps"] > state["env_steps"]
    episodes = [int(line.split(",")[0]) for line in (model_dir / "metrics.csv").read_text().splitlines()[1:]]
    assert episodes == list(range(1, len(episodes) + 1)), "episode counter restarted or skipped"
    _assert_no_jump_at_the_resume(pd.read_csv(model_dir / "metrics.csv"), len(state["returns"]), algo)


def _watch_sac_temperature(monkeypatch) -> list[float]:
    """log_alpha as each SAC update call finds it, in call order."""
    from rlcore.agents.sac import SACAgent

    seen, train_steps = [], SACAgent.train_steps

    def watched(self, *args, **kwargs):
        seen.append(float(self.log_alpha.numpy()))
        return train_steps(self, *args, **kwargs)
    monkeypatch.setattr(SACAgent, "train_steps", watched)
    return seen


def _assert_no_jump_at_the_resume(df, resumed_at, algo):
    """The first episode after the resume continues the trainer's own state (toy episodes all have
    the same length): DQN's epsilon keeps its per-episode decay and its gradient steps their pace;
    SAC's gradient steps keep their pace and its temperature moves no more than in the steps before."""
    last, first = resumed_at - 1, resumed_at  # row indices: last checkpointed episode, first resumed
    if "grad_steps" in df:
        g = df["grad_steps"].to_numpy()
        assert g[first] - g[last] == g[last] - g[last - 1] > 0, g[last - 1:first + 1]
    if algo == "dqn":
        e = df["epsilon"].to_numpy()
        assert e[first] / e[last] == pytest.approx(e[last] / e[last - 1], rel=1e-6) and e[first] < e[last]
    if algo == "sac":
        step = np.abs(np.diff(np.log(df["alpha"].to_numpy()[last - 3:first + 1])))
        assert step[-1] <= 2 * np.nanmax(step[:-1]), step  # alpha is empty (NaN) before learning starts


def _interrupt_after(episodes, trainer, spec):
    """Train until ``episodes`` have ended, then stop as Ctrl-C would (checkpoint, Interrupted)."""
    from rlcore.trainers import session as session_mod
    original = session_mod.TrainingSession.end_episode

    def end_episode(self, episode_return, extra, success=None):
        original(self, episode_return, extra, success)
        if self.book.episodes == episodes:
            self.stop.requested = True
    session_mod.TrainingSession.end_episode = end_episode
    try:
        with pytest.raises(Interrupted):
            trainer.train(spec)
    finally:
        session_mod.TrainingSession.end_episode = original


def _append_rows_after_checkpoint(csv_path, count):
    """Copy the last row ``count`` times with later episode numbers and env steps."""
    with open(csv_path, newline="") as f:
        rows = list(csv.reader(f))
    header, last = rows[0], rows[-1]
    ep, steps = header.index("episode"), header.index("env_steps")
    with open(csv_path, "a", newline="") as f:
        for k in range(1, count + 1):
            row = list(last)
            row[ep], row[steps] = str(int(last[ep]) + k), str(int(float(last[steps])) + 10 * k)
            csv.writer(f).writerow(row)


def test_resume_refuses_a_checkpoint_of_another_algorithm(tmp_path):
    spec = toy.spec("dqn", tmp_path, max_episodes=3, stop_score=99.0)
    dqn_trainer.train(spec)
    other = toy.spec("a2c", tmp_path)
    other.run_dir, other.resume = spec.run_dir, True
    with pytest.raises(UserError, match="is from toy dqn, not toy a2c"):
        check_resumable(other)


def test_evaluation_uses_the_requested_seeds():
    exp = toy.EXPERIMENT
    always_one = lambda obs: np.ones(len(obs), np.int64)  # noqa: E731
    a = evaluate(exp, always_one, episodes=7, seed_base=5, progress=False)
    b = evaluate(exp, always_one, episodes=7, seed_base=5, progress=False)
    c = evaluate(exp, always_one, episodes=7, seed_base=6, progress=False)
    assert len(a) == 7
    assert sorted(a) == sorted(b)
    assert sorted(a) != sorted(c)


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_periodic_evaluation_keeps_the_best_weights(algo, tmp_path):
    spec = toy.spec(algo, tmp_path, eval_every_steps=100, eval_episodes=4, keep_best=True, stop_score=99.0,
                    max_episodes=40)
    model_dir = TRAINERS[algo].train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    evals = (model_dir / "evals.csv").read_text().splitlines()
    assert evals[0] == "env_steps,episode,eval_mean,eval_std,eval_time_limit_share"
    assert all(line.endswith(",1.0") for line in evals[1:])  # the sign bandit only ends at its time limit
    assert len(evals) - 1 == meta["env_steps"] // 100
    best = max(float(line.split(",")[2]) for line in evals[1:])
    assert meta["weights"] == "best periodic evaluation" and meta["best_eval"]["mean"] == pytest.approx(best)
    # the saved model is the best one: it scores the best evaluation again on the same seeds
    exp, _, policy = load_policy(model_dir)
    again = evaluate(exp, policy, 4, seed_base=exp.selection_seed_base, max_episode_steps=10, progress=False)
    assert again.mean() == pytest.approx(best)


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_keep_best_saves_the_weights_of_the_best_evaluation_not_the_last(algo, tmp_path, monkeypatch):
    """Evaluations scripted to fall after the first: the saved model must be the first one's weights,
    although training went on and changed them."""
    from rlcore.models import load_keras_model
    from rlcore.trainers.periodic_eval import PeriodicEvaluation

    scores, snapshots, run = iter(range(100, 0, -1)), [], PeriodicEvaluation.run

    def scripted_play(experiment, policy, episodes, **kwargs):
        mean = float(next(scores))
        return [{"seed": i, "return": mean, "length": 10, "time_limit": True} for i in range(episodes)]

    def recording_run(self, experiment, greedy_policy, snapshot, env_steps):
        def recorded():
            snapshots.append([w.copy() for w in snapshot()])
            return snapshots[-1]
        return run(self, experiment, greedy_policy, recorded, env_steps)
    monkeypatch.setattr("rlcore.evaluation.play_greedy", scripted_play)
    monkeypatch.setattr(PeriodicEvaluation, "run", recording_run)
    spec = toy.spec(algo, tmp_path, eval_every_steps=100, eval_episodes=2, keep_best=True, stop_score=99.0,
                    max_episodes=40)
    model_dir = TRAINERS[algo].train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    assert meta["best_eval"]["mean"] == 100.0 and meta["best_eval"]["env_steps"] == 100
    assert len(snapshots) == 1  # only the first evaluation was a best
    saved = [w for path in sorted(model_dir.glob("*.h5")) for w in load_keras_model(path).get_weights()]
    assert len(saved) == len(snapshots[0])
    for got, want in zip(saved, snapshots[0]):
        np.testing.assert_array_equal(got, want)
    last = pd.read_csv(model_dir / "evals.csv")
    assert len(last) == 4 and last["eval_mean"].tolist() == [100.0, 99.0, 98.0, 97.0]


def test_training_stops_when_an_evaluation_reaches_the_stop_eval_score(tmp_path):
    spec = toy.spec("dqn", tmp_path, eval_every_steps=100, eval_episodes=4, keep_best=True,
                    stop_score=99.0, stop_eval_score=9.0, max_episodes=200)
    meta = json.loads((dqn_trainer.train(spec) / "meta.json").read_text())
    assert meta["best_eval"]["mean"] >= 9.0
    assert meta["episodes"] < 200


def test_ppo_starts_from_another_models_weights_and_records_it(tmp_path):
    from rlcore.agents.ppo import PPOAgent
    from rlcore.models import load_keras_model

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


GIT_KEEPS = {"ppo": ["checkpoint.npz", "metrics.csv", "rollouts.csv"], "sac": ["checkpoint.npz", "metrics.csv"]}


@pytest.mark.parametrize("algo", sorted(GIT_KEEPS))
def test_a_run_resumes_from_what_git_keeps_of_it(tmp_path, algo, capfd):
    """long_runs/: the checkpoint and CSV tables are committed, the wandb folder and the replay memory
    are ignored; a clone on another machine resumes the run with its counters."""
    import shutil
    import subprocess

    from tests.test_cli import ROOT

    def git(*args, cwd):
        subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=cwd, check=True,
                       capture_output=True)

    repo = tmp_path / "repo"
    run_dir = repo / "long_runs" / "toy" / algo
    extra = {"ppo": {"stop_success_share": 0.0}, "sac": {"max_env_steps": 0, "learning_starts": 100}}[algo]
    spec = toy.spec(algo, tmp_path, stop_score=99.0, max_episodes=30, **extra)
    spec.run_dir, spec.wandb_mode = run_dir, "offline"
    _interrupt_after(12, TRAINERS[algo], spec)
    assert (run_dir / "wandb").is_dir()
    shutil.copyfile(ROOT / ".gitignore", repo / ".gitignore")
    git("init", "-q", cwd=repo)
    git("add", "-A", cwd=repo)
    git("commit", "-q", "-m", "checkpoint", cwd=repo)
    git("clone", "-q", str(repo), str(tmp_path / "clone"), cwd=tmp_path)
    cloned = tmp_path / "clone" / "long_runs" / "toy" / algo
    assert sorted(p.name for p in cloned.iterdir()) == GIT_KEEPS[algo]
    before = read_checkpoint_state(cloned / "checkpoint.npz")
    spec.run_dir, spec.resume, spec.wandb_mode, spec.command = cloned, True, "off", "pytest --resume"
    capfd.readouterr()
    meta = json.loads((TRAINERS[algo].train(spec) / "meta.json").read_text())
    assert meta["commands"] == ["pytest", "pytest --resume"]
    assert meta["episodes"] >= 30 and meta["env_steps"] > before["env_steps"]
    said = capfd.readouterr().err
    assert ("replay memory" in said) == (algo == "sac"), said


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


@pytest.mark.parametrize("algo", ["dqn", "sac"])
def test_the_replay_memory_resumes_from_its_own_file_only_when_it_matches(algo, tmp_path, capfd):
    """replay.npz beside checkpoint.npz: put back exactly when it is from the checkpoint's moment;
    missing or from another moment, the memory starts empty and one line says so."""
    import shutil

    from rlcore.agents.dqn import DQNAgent
    from rlcore.agents.sac import SACAgent
    from rlcore.replay import ReplayMemory
    from rlcore.trainers import checkpoints

    extra = {"sac": {"max_env_steps": 0, "learning_starts": 100}}.get(algo, {})
    spec = toy.spec(algo, tmp_path, stop_score=99.0, max_episodes=30, **extra)
    _interrupt_after(12, TRAINERS[algo], spec)
    replay = spec.run_dir / checkpoints.REPLAY_FILE
    with np.load(spec.run_dir / "checkpoint.npz") as data:
        assert not [k for k in data.files if "replay" in k], "the replay memory is inside the checkpoint"
    state = read_checkpoint_state(spec.run_dir / "checkpoint.npz")
    shutil.copyfile(replay, tmp_path / "kept.npz")
    spec.resume = True

    def restored_size():
        """Restore into a fresh agent and memory (the toy tasks: 2-d observations, 2 actions)."""
        agent = {"dqn": DQNAgent, "sac": SACAgent}[algo](2, 2, spec.config)
        action = {"dqn": {}, "sac": {"action_shape": (2,), "action_dtype": np.float32}}[algo]
        memory = ReplayMemory(spec.config.buffer_size, (2,), **action)
        capfd.readouterr()
        checkpoints.restore(spec, agent, np.random.default_rng(0), memory)
        return len(memory), capfd.readouterr().err

    assert restored_size() == (state["env_steps"], "")
    replay.unlink()
    size, said = restored_size()
    assert size == 0 and "replay memory" in said and "is not there" in said
    with np.load(tmp_path / "kept.npz") as data:
        stale = {k: data[k] for k in data.files}
    np.savez(replay, **{**stale, "env_steps": np.array(state["env_steps"] - 1)})
    size, said = restored_size()
    assert size == 0 and "from another moment" in said
    meta = json.loads((TRAINERS[algo].train(spec) / "meta.json").read_text())  # and the run goes on
    assert meta["episodes"] >= 30


ACTING_MODEL = {"dqn": "q_network", "a2c": "actor", "ppo": "actor_critic", "sac": "actor"}


@pytest.mark.parametrize("algo", sorted(TRAINERS))
def test_a_run_in_progress_becomes_a_model_of_its_last_checkpoint(algo, tmp_path):
    """evaluate/render --model RUN_DIR on a run without a model yet: the acting network is the
    checkpoint's, and the run folder is left as it was."""
    from rlcore.snapshot import is_run_in_progress, model_from_checkpoint

    extra = {"ppo": {"stop_success_share": 0.0}, "sac": {"max_env_steps": 0, "learning_starts": 100}}
    spec = toy.spec(algo, tmp_path, stop_score=99.0, max_episodes=30, **extra.get(algo, {}))
    _interrupt_after(12, TRAINERS[algo], spec)
    assert is_run_in_progress(spec.run_dir)
    files_before = sorted(p.name for p in spec.run_dir.iterdir())
    with pytest.raises(UserError, match=f"is {spec.experiment.name} {algo}, not {spec.experiment.name} nothing"):
        model_from_checkpoint(spec.run_dir, tmp_path / "no", spec.experiment.name, "nothing")
    meta = model_from_checkpoint(spec.run_dir, tmp_path / "snap", spec.experiment.name, algo)
    state = read_checkpoint_state(spec.run_dir / "checkpoint.npz")
    assert meta["env_steps"] == state["env_steps"] and meta["episodes"] == len(state["returns"])
    _, _, policy = load_policy(tmp_path / "snap", spec.experiment.name, algo)
    with np.load(spec.run_dir / "checkpoint.npz") as data:
        name = ACTING_MODEL[algo]
        saved = [data[f"model/{name}/{i}"] for i in range(len(policy.model.get_weights()))]
    for got, want in zip(policy.model.get_weights(), saved):
        np.testing.assert_array_equal(got, want)
    assert sorted(p.name for p in spec.run_dir.iterdir()) == files_before


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
    spec.experiment = dataclasses.replace(spec.experiment, info_keys=("absent",))
    sac_trainer.train(spec)
    rows = pd.read_csv(spec.run_dir / "metrics.csv")
    assert len(rows) == 30 and rows["absent"].isna().all()  # declared, not reported by the env: empty
