"""Observation standardization for SAC (``--obs-norm``): running statistics, the Standardize layer,
its numpy step, and a run that learns, saves, loads and resumes with it."""
import dataclasses

import numpy as np
import pytest

from rlcore.algorithms.running_stats import RunningMeanStd
from rlcore.algorithms.sac.agent import SACAgent
from rlcore.algorithms.sac.config import SACConfig
from rlcore.networks.layers import Standardize
from rlcore.networks.numpy_forward import _standardize
from tests import numpy_reference as ref
from tests import toy


def test_running_stats_equal_the_statistics_of_everything_seen():
    rng = np.random.default_rng(0)
    chunks = [rng.normal(3.0, 5.0, size=(n, 4)) for n in (1, 7, 1, 30, 2)]
    stats = RunningMeanStd(4)
    for i, chunk in enumerate(chunks):
        stats.update(chunk)
        if i == 2:  # a checkpoint in the middle: the restored statistics go on the same way
            stats = RunningMeanStd(4, stats.state())
    data = np.concatenate(chunks)
    assert stats.count == len(data)
    np.testing.assert_allclose(stats.mean, data.mean(axis=0), rtol=1e-12)
    np.testing.assert_allclose(stats.var, data.var(axis=0), rtol=1e-10)


def test_standardize_layer_and_its_numpy_step_match_the_reference():
    rng = np.random.default_rng(1)
    obs = (rng.normal(size=(6, 3)) * [1.0, 50.0, 0.01]).astype(np.float32)
    mean, var = np.array([0.5, -2.0, 0.0]), np.array([4.0, 9.0, 1e-6])
    layer = Standardize(clip=10.0)
    layer.build((None, 3))
    layer.mean.assign(mean.astype(np.float32))
    layer.var.assign(var.astype(np.float32))
    want = ref.standardize(obs, mean, var, 10.0)
    assert np.abs(want).max() == 10.0  # the clip is exercised
    np.testing.assert_allclose(layer(obs).numpy(), want, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(_standardize(layer)([mean, var], obs), want, rtol=1e-5, atol=1e-5)


def test_sac_pushes_the_statistics_into_all_five_networks_before_an_update():
    cfg = SACConfig(actor_hidden=(8,), critic_hidden=(8,), batch_size=4, buffer_size=8, learning_starts=8,
                    obs_norm=True)
    agent = SACAgent(3, 2, cfg)
    rng = np.random.default_rng(2)
    seen = rng.normal(5.0, 2.0, size=(50, 3))
    agent.observe(seen)
    k = cfg.updates_per_call
    batch = (rng.normal(size=(k, 4, 3)).astype(np.float32), rng.uniform(-1, 1, (k, 4, 2)).astype(np.float32),
             np.zeros((k, 4), np.float32), rng.normal(size=(k, 4, 3)).astype(np.float32), np.zeros((k, 4), np.float32))
    agent.train_steps(*batch, rng)
    assert agent.obs_stats.count == 50  # the observations were folded in by the update itself
    for model in agent.models().values():
        layer = model.get_layer("standardize")
        np.testing.assert_allclose(layer.mean.numpy(), seen.mean(axis=0), rtol=1e-5)
        np.testing.assert_allclose(layer.var.numpy(), seen.var(axis=0), rtol=1e-5)
    obs = rng.normal(5.0, 2.0, size=(5, 3)).astype(np.float32)
    np.testing.assert_allclose(agent.policy(obs), agent.actor(obs).numpy(), rtol=1e-4, atol=1e-5)


@pytest.fixture(autouse=True)
def register_toy(monkeypatch):
    from rlcore.environments import registry

    monkeypatch.setitem(registry.EXPERIMENT_MODULES, "toy_reach", "tests.toy_reach")


def test_a_standardized_sac_run_learns_and_its_saved_actor_standardizes(tmp_path, sac_without_xla):
    from rlcore.algorithms.sac import train as sac_trainer
    from rlcore.models.policies import load_policy
    from rlcore.training.evaluation import evaluate

    model_dir = sac_trainer.train(toy.spec("sac", tmp_path, obs_norm=True))
    exp, meta, policy = load_policy(model_dir)
    assert meta["config"]["obs_norm"] is True
    returns = evaluate(exp, policy, episodes=20, progress=False)
    assert returns.mean() >= -1.0, f"mean-action return {returns.mean():.2f}; random is about -5"
    saved = policy.model.get_layer("standardize")
    assert saved.var.numpy().min() < 0.9  # real statistics, not the initial ones (targets in [-0.8, 0.8])


def test_a_standardized_run_resumes_with_its_statistics(tmp_path, sac_without_xla):
    from rlcore.algorithms.sac import train as sac_trainer
    from rlcore.files.checkpoint import read_checkpoint_state
    from tests.rlcore.training.test_resume import _interrupt_after

    spec = toy.spec("sac", tmp_path, obs_norm=True, max_env_steps=0, learning_starts=100, max_episodes=30)
    _interrupt_after(12, sac_trainer, spec)
    saved = read_checkpoint_state(spec.run_dir / "checkpoint.npz")["obs_stats"]
    assert saved["count"] == 12 * 11  # 12 episodes of 10 steps, each with its first observation
    resumed = dataclasses.replace(spec, resume=True, command="pytest --resume")
    sac_trainer.train(resumed)
    final = read_checkpoint_state(spec.run_dir / "checkpoint.npz")["obs_stats"]
    assert final["count"] == 30 * 11
