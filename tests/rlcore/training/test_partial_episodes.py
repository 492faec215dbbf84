"""Episodes that start elsewhere than evaluations do (Mario's restarts): the PPO trainer builds its envs
with the training-only fields, trains on such episodes, logs them, and leaves them out of the success
share that the stop rule reads."""
import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from rlcore.algorithms.ppo import train as ppo_trainer
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.environments.experiment import Curriculum
from rlcore.training.episodes import EpisodeBook
from tests import toy

pytestmark = pytest.mark.usefixtures("toy_experiments")


@dataclasses.dataclass(frozen=True)
class PartialConfig(PPOConfig):
    partial_every: int = 0  # a training-only env field, as Mario's restart_x


class PartlyRestartedEnv(toy.ImageSignEnv):
    """Every ``partial_every``-th episode of an env is marked partial; only those are won."""

    def __init__(self, max_episode_steps=10, render_mode=None, partial_every=0):
        super().__init__(max_episode_steps, render_mode)
        self.partial_every, self.count, self.partial = partial_every, 0, False

    def _info(self):
        return {"score": self.score, "won": self.partial, "partial": self.partial}

    def reset(self, *, seed=None, options=None):
        self.count += 1
        self.partial = bool(self.partial_every) and self.count % self.partial_every == 0
        return super().reset(seed=seed, options=options)


def test_partial_episodes_train_and_are_logged_but_not_counted_toward_the_success_share(tmp_path):
    spec = toy.spec("ppo", tmp_path, max_episodes=40, stop_success_share=0.3)
    spec.config = PartialConfig(**{f.name: getattr(spec.config, f.name)
                                   for f in dataclasses.fields(spec.config)}, partial_every=2)
    spec.experiment = dataclasses.replace(
        spec.experiment, make_env=lambda render_mode=None, max_episode_steps=10, partial_every=0:
        PartlyRestartedEnv(max_episode_steps, render_mode, partial_every),
        curriculum=Curriculum(env_fields=("partial_every",), partial_key="partial"))
    meta_dir = ppo_trainer.train(spec)
    rows = pd.read_csv(spec.run_dir / "metrics.csv")
    # half the episodes were partial (so the trainer's envs got the training-only field) and won
    assert rows["partial"].sum() == pytest.approx(len(rows) / 2, abs=2)
    assert (rows["success"] == rows["partial"]).all()
    # ... yet the share of won counted episodes stayed 0, so the 0.3 stop rule never fired
    assert (rows["success_share"] == 0).all()
    assert json.loads((meta_dir / "meta.json").read_text())["stopped_by"] == "max_episodes 40"
    rollouts = pd.read_csv(spec.run_dir / "rollouts.csv")
    assert rollouts["partial_episodes"].sum() == rows["partial"].sum()
    assert rollouts["partial_successes"].sum() == rows["partial"].sum() and rollouts["successes"].sum() == 0
    # the checkpoint keeps the counted episodes' returns apart, for the moving average of a resumed run
    from rlcore.files.checkpoint import read_checkpoint_state
    from rlcore.training.spec import CHECKPOINT_FILE
    state = read_checkpoint_state(spec.run_dir / CHECKPOINT_FILE)
    full = rows.loc[rows["partial"] == 0, "total_points"]
    assert np.allclose(state["counted_returns"], full) and len(state["returns"]) == len(rows)
    assert np.isclose(rows["av_latest_points"].iloc[-1], full.iloc[-spec.config.window:].mean())
    before = len(rows)
    spec.resume, spec.config = True, dataclasses.replace(spec.config, max_episodes=before + 4)
    ppo_trainer.train(spec)  # a resumed run's first episodes still average the counted ones only
    rows = pd.read_csv(spec.run_dir / "metrics.csv")
    first = rows.index[rows["episode"] > before][0]
    full = rows.loc[: first].query("partial == 0")["total_points"]
    assert np.isclose(rows["av_latest_points"].iloc[first], full.iloc[-spec.config.window:].mean())


def test_an_episode_not_counted_logs_its_success_but_leaves_the_share():
    book = EpisodeBook(window=4, solved_score=None)
    rows = [book.add(r, success=s, counted=c)
            for r, s, c in [(1.0, False, True), (10.0, True, False), (3.0, True, True), (20.0, True, False)]]
    assert [r["success"] for r in rows] == [0, 1, 1, 1]
    assert book.successes == [False, True] and book.success_share == 0.5
    assert [r["success_share"] for r in rows] == [0.0, 0.0, 0.5, 0.5]
    # every episode is numbered and keeps its return; the moving average is the counted ones'
    assert book.episodes == 4 and book.returns == [1.0, 10.0, 3.0, 20.0]
    assert [r["av_latest_points"] for r in rows] == [1.0, 1.0, 2.0, 2.0]
    resumed = EpisodeBook(4, None, book.returns, book.successes, book.counted_returns)
    assert resumed.average == 2.0 and EpisodeBook(4, None, [1.0, 3.0]).average == 2.0


class RememberingEnv(toy.ImageSignEnv):
    """Builds up a memory over its episodes (as Mario's restart points): the episode count."""
    given: list = []  # every memory a pool handed to one of these envs (inline pools: same process)

    def __init__(self, max_episode_steps=10, render_mode=None):
        super().__init__(max_episode_steps, render_mode)
        self.episodes = 0

    def reset(self, *, seed=None, options=None):
        self.episodes += 1
        return super().reset(seed=seed, options=options)

    @property
    def memory(self) -> dict:
        return {"episodes": np.array([self.episodes])}

    @memory.setter
    def memory(self, value: dict) -> None:
        RememberingEnv.given.append(int(value["episodes"][0]))
        self.episodes = int(value["episodes"][0])


def test_a_checkpoint_keeps_what_each_env_built_up_and_a_resume_hands_it_back(tmp_path):
    from rlcore.training.spec import CHECKPOINT_FILE

    spec = toy.spec("ppo", tmp_path, max_episodes=12, stop_success_share=0.0)
    spec.experiment = dataclasses.replace(
        spec.experiment, make_env=lambda render_mode=None, max_episode_steps=10:
        RememberingEnv(max_episode_steps, render_mode), curriculum=Curriculum(memory="memory"))
    RememberingEnv.given.clear()
    ppo_trainer.train(spec)
    with np.load(spec.run_dir / CHECKPOINT_FILE) as saved:
        kept = sorted(int(saved[f"array/env/{i}/episodes"][0]) for i in range(2))
    ended = len(pd.read_csv(spec.run_dir / "metrics.csv"))
    assert sum(kept) == ended + 2  # as the envs stood at the end: every episode (+ the one each began)
    assert RememberingEnv.given == []  # a new run starts with nothing handed over
    spec.resume = True
    spec.config = dataclasses.replace(spec.config, max_episodes=24)
    ppo_trainer.train(spec)
    assert sorted(RememberingEnv.given) == kept


def test_envs_without_the_declared_memory_keep_nothing():
    from rlcore.environments.vector import EnvPool
    from rlcore.training import checkpoints

    with EnvPool([toy.make_image_env] * 2) as envs:
        assert checkpoints.env_memory(envs, "memory") == {} and checkpoints.env_memory(envs, None) == {}
        checkpoints.give_env_memory(envs, "memory", {"env/0/episodes": np.array([3])})  # no error


@pytest.mark.parametrize("every", [1, 1000])  # a checkpoint after every rollout; only the last one
def test_every_checkpoint_keeps_the_env_memory_as_it_stood_then(tmp_path, monkeypatch, every):
    """Each checkpoint, periodic or the last, holds what the envs had built up when it was written,
    not an older reading (a run killed after a periodic checkpoint resumes from that one)."""
    from rlcore.training import checkpoints

    spec = toy.spec("ppo", tmp_path, max_episodes=12, stop_success_share=0.0, checkpoint_rollouts=every)
    spec.experiment = dataclasses.replace(
        spec.experiment, make_env=lambda render_mode=None, max_episode_steps=10:
        RememberingEnv(max_episode_steps, render_mode), curriculum=Curriculum(memory="memory"))
    seen, save = [], checkpoints.save

    def spy(session, *args, env_arrays=None, **kwargs):
        kept = sum(int(env_arrays[f"env/{i}/episodes"][0]) for i in range(2)) if env_arrays else 0
        seen.append((kept, session.book.episodes))
        return save(session, *args, env_arrays=env_arrays, **kwargs)

    monkeypatch.setattr(checkpoints, "save", spy)
    ppo_trainer.train(spec)
    assert len(seen) >= (2 if every == 1 else 1)
    # every episode that had ended by then, plus the one each of the 2 envs had begun
    assert all(kept == ended + 2 for kept, ended in seen), seen
