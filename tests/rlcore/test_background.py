"""Updates in a worker thread while the env steps: the helper, and SAC's loop with overlap_updates."""
import dataclasses
import threading

import numpy as np
import pandas as pd
import pytest

from rlcore.errors import UserError
from rlcore.evaluation import evaluate
from rlcore.policies import load_policy
from rlcore.trainers import sac as sac_trainer
from rlcore.trainers.background import BackgroundUpdate
from tests import toy

pytestmark = pytest.mark.usefixtures("toy_experiments")


def _record_thread(calls):
    def run(x):
        calls.append(threading.current_thread())
        return x * 2
    return run


@pytest.mark.parametrize("overlap", [False, True])
def test_an_update_runs_on_a_worker_thread_only_when_overlapping(overlap):
    calls = []
    with BackgroundUpdate(_record_thread(calls), overlap) as updates:
        assert updates.collect() is None  # nothing in flight yet
        updates.submit(21)
        with pytest.raises(RuntimeError, match="collect"):
            updates.submit(1)  # one update at a time
        assert updates.collect() == 42 and updates.collect() is None
    assert (calls[0] is threading.main_thread()) != overlap


def test_an_error_in_the_worker_is_raised_when_the_update_is_collected():
    def fail(_):
        raise FloatingPointError("SAC critic_loss is NaN/Inf")
    with BackgroundUpdate(fail, overlap=True) as updates:
        updates.submit(None)
        with pytest.raises(FloatingPointError, match="critic_loss"):
            updates.collect()


def test_sac_with_overlapping_updates_learns_the_reach_task_and_reproduces_its_seed(tmp_path):
    def run(name, seed, steps):
        spec = dataclasses.replace(toy.spec("sac", tmp_path / name, overlap_updates=True, max_env_steps=steps),
                                   seed=seed)
        return sac_trainer.train(spec)

    model_dir = run("long", 0, 2500)
    exp, meta, policy = load_policy(model_dir)
    assert meta["config"]["overlap_updates"] is True and meta["env_steps"] == 2500
    returns = evaluate(exp, policy, episodes=20, progress=False)
    assert returns.mean() >= -1.0, f"SAC mean-action return {returns.mean():.2f}; random is about -5"
    # the thread's timing does not reach the numbers: the same seed gives the same table
    first, again = (pd.read_csv(run(name, 0, 400) / "metrics.csv").drop(columns=["wall_seconds"])
                    for name in ("a", "b"))
    pd.testing.assert_frame_equal(first, again)
    assert first["critic_loss"].notna().any()


def test_sac_with_overlapping_updates_reports_a_nan_loss_in_one_line(tmp_path, monkeypatch):
    honest_step = toy.ReachEnv.step

    def nan_step(self, action):
        obs, _, terminated, truncated, info = honest_step(self, action)
        return obs, float("nan"), terminated, truncated, info
    monkeypatch.setattr(toy.ReachEnv, "step", nan_step)
    with pytest.raises(UserError, match=r"training diverged: .*NaN.* at env step \d+; "):
        sac_trainer.train(toy.spec("sac", tmp_path, overlap_updates=True))
    assert not [t for t in threading.enumerate() if t.name.startswith("update")]  # the worker stopped
