"""Runs that stop and go on: Ctrl-C or SIGTERM checkpoints, resume continues every counter and the
trainer's own state, a clone of what git keeps resumes on another machine, the replay memory's file,
and a run in progress turned into a model."""
import csv
import json

import numpy as np
import pandas as pd
import pytest

from rlcore.algorithms.dqn import train as dqn_trainer
from rlcore.errors import UserError
from rlcore.files.checkpoint import read_checkpoint_state
from rlcore.models.policies import load_policy
from rlcore.training.spec import check_resumable
from rlcore.training.stopping import Interrupted
from tests import toy
from tests.toy import TRAINERS

pytestmark = pytest.mark.usefixtures("toy_experiments", "sac_without_xla")


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
    steps = pd.read_csv(model_dir / "metrics.csv")["env_steps"].to_numpy()
    assert (np.diff(steps) >= 0).all() and steps[len(state["returns"])] > state["env_steps"]  # not from 0
    if algo == "ppo":  # the rollout counter goes on too: each rollout logged once, env steps at its pace
        rollouts = pd.read_csv(spec.run_dir / "rollouts.csv")
        assert rollouts["rollout"].tolist() == list(range(1, len(rollouts) + 1))
        assert rollouts["rollout"].iloc[-1] > state["rollouts"] > 0
        per_rollout = spec.config.n_steps * spec.config.num_envs
        assert (rollouts["env_steps"] == rollouts["rollout"] * per_rollout).all()



@pytest.mark.parametrize("algo", ["dqn", "sac"])
def test_a_resume_differs_from_the_run_that_never_stopped_only_in_its_envs_episodes(algo, tmp_path, monkeypatch):
    """A resume starts its next episode on a seed drawn from the run's seed and its episode count
    (rlcore/environments/seeding.py), where the run that never stopped goes on with its env's own random stream.
    With the toy env made to seed every episode that way, an interrupted and resumed run (stopped at an
    episode's end) is the uninterrupted run, row for row: weights, optimizers, RNG, replay memory, the
    temperature and every counter come back as they were. Both runs are computed here, on one machine."""
    env_class = {"dqn": toy.SignEnv, "sac": toy.ReachEnv}[algo]
    reset = env_class.reset

    def reset_seeding_each_episode(self, *, seed=None, options=None):
        if seed is None:  # the next episode: the seed a resume would draw (training_env_seed(0, i) = i)
            self.resets_since += 1
            seed = self.last_seed + self.resets_since
        else:
            self.last_seed, self.resets_since = seed, 0
        return reset(self, seed=seed, options=options)
    monkeypatch.setattr(env_class, "reset", reset_seeding_each_episode)
    kw = {"stop_score": 99.0, "max_episodes": 30,
          **({"max_env_steps": 0, "learning_starts": 100, "obs_norm": True} if algo == "sac" else {})}
    never_stopped = toy.spec(algo, tmp_path / "a", **kw)
    TRAINERS[algo].train(never_stopped)
    resumed = toy.spec(algo, tmp_path / "b", **kw)
    _interrupt_after(12, TRAINERS[algo], resumed)
    resumed.resume, resumed.command = True, "pytest --resume"
    TRAINERS[algo].train(resumed)
    a, b = (pd.read_csv(spec.run_dir / "metrics.csv").drop(columns="wall_seconds") for spec in (never_stopped, resumed))
    assert len(a) == len(b) == 30
    # equal to a tolerance far below what a different episode or an unrestored RNG moves (both runs are
    # computed here, but no float read back from a file is held to the bit)
    pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-6, atol=1e-9)


def _watch_sac_temperature(monkeypatch) -> list[float]:
    """log_alpha as each SAC update call finds it, in call order."""
    from rlcore.algorithms.sac.agent import SACAgent

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
    from rlcore.training import session as session_mod
    original = session_mod.TrainingSession.end_episode

    def end_episode(self, *args, **kwargs):
        original(self, *args, **kwargs)
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


GIT_KEEPS = {"ppo": ["checkpoint.npz", "metrics.csv", "rollouts.csv"], "sac": ["checkpoint.npz", "metrics.csv"]}



@pytest.mark.parametrize("algo", sorted(GIT_KEEPS))
def test_a_run_resumes_from_what_git_keeps_of_it(tmp_path, algo, capfd):
    """long_runs/: the checkpoint and CSV tables are committed, the wandb folder and the replay memory
    are ignored; a clone on another machine resumes the run with its counters."""
    import shutil
    import subprocess

    from tests.test_cli import ROOT

    if shutil.which("git") is None:
        pytest.skip("git is not installed (the code came without it)")

    def git(*args, cwd):  # whatever the user's own git configuration: no signing, hooks or global ignores
        subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false",
                        "-c", "core.hooksPath=/dev/null", "-c", "core.excludesFile=/dev/null", *args],
                       cwd=cwd, check=True, capture_output=True)

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



@pytest.mark.parametrize("algo", ["dqn", "sac"])
def test_the_replay_memory_resumes_from_its_own_file_only_when_it_matches(algo, tmp_path, capfd):
    """replay.npz beside checkpoint.npz: put back exactly when it is from the checkpoint's moment;
    missing or from another moment, the memory starts empty and one line says so."""
    import shutil

    from rlcore.algorithms.dqn.agent import DQNAgent
    from rlcore.algorithms.replay import ReplayMemory
    from rlcore.algorithms.sac.agent import SACAgent
    from rlcore.training import checkpoints

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
    from rlcore.models.snapshot import is_run_in_progress, model_from_checkpoint

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
