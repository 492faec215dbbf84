"""Evaluation during training on the tiny envs: the seeds it plays, one evaluation per interval in
evals.csv, the best result and its weights (keep-best), and the stop on an evaluation score."""
import json

import numpy as np
import pandas as pd
import pytest

from rlcore.algorithms.dqn import train as dqn_trainer
from rlcore.models.policies import load_policy
from rlcore.training.evaluation import evaluate
from tests import toy
from tests.toy import TRAINERS

pytestmark = pytest.mark.usefixtures("toy_experiments")


def test_evaluation_uses_the_requested_seeds():
    exp = toy.EXPERIMENT
    always_one = lambda obs: np.ones(len(obs), np.int64)  # noqa: E731
    a = evaluate(exp, always_one, episodes=7, seed_base=5, progress=False)
    b = evaluate(exp, always_one, episodes=7, seed_base=5, progress=False)
    c = evaluate(exp, always_one, episodes=7, seed_base=6, progress=False)
    assert len(a) == 7
    assert sorted(a) == sorted(b)
    assert sorted(a) != sorted(c)
    # episode i is played on seed SEED_BASE + i, in that order
    one_each = [evaluate(exp, always_one, episodes=1, seed_base=s, progress=False)[0] for s in range(5, 12)]
    assert list(a) == one_each and len(set(one_each)) > 2


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_periodic_evaluations_are_logged_and_meta_names_the_latest_of_the_best(algo, tmp_path):
    """A real run (the toy task is learned at once, so most evaluations tie at the top score): one row
    per interval, and meta.json's best is the last evaluation that reached the top score. Which
    weights are saved is the scripted test below's job."""
    spec = toy.spec(algo, tmp_path, eval_every_steps=100, eval_episodes=4, keep_best=True, stop_score=99.0,
                    max_episodes=40)
    model_dir = TRAINERS[algo].train(spec)
    meta = json.loads((model_dir / "meta.json").read_text())
    evals = pd.read_csv(model_dir / "evals.csv")
    assert evals.columns.tolist() == ["env_steps", "episode", "eval_mean", "eval_std", "eval_time_limit_share"]
    assert (evals.eval_time_limit_share == 1.0).all()  # the sign bandit only ends at its time limit
    assert evals.env_steps.tolist() == list(range(100, meta["env_steps"] + 1, 100))
    top = evals.eval_mean.max()
    latest_top = int(evals.env_steps[evals.eval_mean == top].iloc[-1])
    assert meta["weights"] == "best periodic evaluation"
    assert meta["best_eval"]["mean"] == pytest.approx(top) and meta["best_eval"]["env_steps"] == latest_top
    # the saved model scores the best evaluation again on the same seeds
    exp, _, policy = load_policy(model_dir)
    again = evaluate(exp, policy, 4, seed_base=exp.selection_seed_base, max_episode_steps=10, progress=False)
    assert again.mean() == pytest.approx(top)


@pytest.mark.parametrize("algo", ["dqn", "a2c"])
def test_keep_best_saves_the_weights_of_the_best_evaluation_not_the_last(algo, tmp_path, monkeypatch):
    """Evaluations scripted to fall after the first: the saved model must be the first one's weights,
    although training went on and changed them."""
    from rlcore.networks.saving import load_keras_model
    from rlcore.training.periodic_eval import PeriodicEvaluation

    scores, snapshots, run = iter(range(100, 0, -1)), [], PeriodicEvaluation.run

    def scripted_play(experiment, policy, episodes, **kwargs):
        mean = float(next(scores))
        return [{"seed": i, "return": mean, "length": 10, "time_limit": True} for i in range(episodes)]

    def recording_run(self, experiment, greedy_policy, snapshot, env_steps):
        def recorded():
            snapshots.append([w.copy() for w in snapshot()])
            return snapshots[-1]
        return run(self, experiment, greedy_policy, recorded, env_steps)
    monkeypatch.setattr("rlcore.training.evaluation.play_greedy", scripted_play)
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
