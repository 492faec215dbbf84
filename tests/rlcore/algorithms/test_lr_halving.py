"""``--lr-halve-at``: the rate halves once per mark the best full-window success share reaches; PPO's
Adam follows it, rollouts.csv logs it, and a resume comes back at the halved rate."""
import dataclasses

import numpy as np
import pandas as pd
import pytest

from rlcore.algorithms.ppo import train as ppo_trainer
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.algorithms.ppo.halving import LearningRateHalving
from rlcore.errors import UserError
from rlcore.training.episodes import EpisodeBook
from rlcore.training.spec import CHECKPOINT_FILE
from tests import toy

pytestmark = pytest.mark.usefixtures("toy_experiments")


def test_each_mark_halves_once_and_only_with_a_full_window():
    book = EpisodeBook(window=4, solved_score=None)
    for won in (True, True, True):
        book.add(0.0, won)
    assert book.settled_success_share is None  # window not full yet
    lr = LearningRateHalving(1e-4, (0.45, 0.3))
    assert lr.observe(book.settled_success_share) is None and lr.rate() == 1e-4
    assert lr.observe(0.25) is None and lr.rate() == 1e-4
    assert "0.0001 -> 5e-05" in lr.observe(0.35)
    assert lr.observe(0.0) is None and lr.rate() == 5e-5  # a fall does not raise it back
    assert lr.observe(0.25) is None and lr.rate() == 5e-5  # nor a return
    assert "5e-05 -> 2.5e-05" in lr.observe(0.75)
    assert lr.observe(1.0) is None and lr.rate() == 2.5e-5  # no mark left
    # a resume from the kept state comes back at the same rate; --lr is the rate before halving
    again = LearningRateHalving(2e-4, (0.3, 0.45), lr.state())
    assert again.rate() == pytest.approx(5e-5)
    assert LearningRateHalving(1e-4, ()).state() == {}


@pytest.mark.parametrize("marks", [(0.0,), (1.5,), (0.3, float("nan"))])
def test_marks_outside_0_to_1_are_refused(marks):
    with pytest.raises(UserError, match="--lr-halve-at"):
        PPOConfig(lr_halve_at=marks)


def test_ppo_halves_adam_rate_as_the_share_rises_and_a_resume_keeps_it(tmp_path):
    spec = toy.spec("ppo", tmp_path, lr_halve_at=(0.3, 0.6))
    ppo_trainer.train(spec)
    rollouts = pd.read_csv(spec.run_dir / "rollouts.csv")
    metrics = pd.read_csv(spec.run_dir / "metrics.csv")
    # the reference: the share at the end of each rollout, its running best, and the marks it passed
    steps = spec.config.n_steps * spec.config.num_envs
    best, expected = 0.0, []
    for r in rollouts["rollout"]:
        expected.append(1e-3 * 0.5 ** sum(best >= mark for mark in (0.3, 0.6)))
        ended = metrics[metrics["env_steps"] <= r * steps]
        if len(ended) >= spec.config.window:
            best = max(best, ended["success_share"].iloc[-1])
    np.testing.assert_allclose(rollouts["lr"], expected)
    assert rollouts["lr"].iloc[0] == 1e-3 and rollouts["lr"].iloc[-1] == pytest.approx(2.5e-4)
    # Adam itself ran at the last rate: its learning-rate variable is in the checkpoint
    with np.load(spec.run_dir / CHECKPOINT_FILE) as data:
        assert float(data["optimizer/adam/1"]) == pytest.approx(2.5e-4)

    # a resume (after the rate was halved twice) goes on at 2.5e-4, not at --lr's 1e-3
    before = len(rollouts)
    spec.resume = True
    first_weight = spec.config.entropy_coef
    spec.config = dataclasses.replace(spec.config, max_episodes=len(metrics) + 10, stop_success_share=0.0,
                                      entropy_coef=first_weight + 0.02)  # a resume's --entropy-coef
    ppo_trainer.train(spec)
    table = pd.read_csv(spec.run_dir / "rollouts.csv")
    resumed = table.iloc[before:]
    assert len(resumed)
    np.testing.assert_allclose(resumed["lr"], 2.5e-4)
    # rollouts.csv logs the entropy weight beside the rate, so `main.py status` shows a resume's change
    np.testing.assert_allclose(table["entropy_coef"].iloc[:before], first_weight)
    np.testing.assert_allclose(resumed["entropy_coef"], first_weight + 0.02)
    with np.load(spec.run_dir / CHECKPOINT_FILE) as data:
        assert float(data["optimizer/adam/1"]) == pytest.approx(2.5e-4)


def test_the_entropy_weight_halves_by_the_same_rule_and_the_update_uses_it(tmp_path):
    """--entropy-halve-at: rollouts.csv's entropy weight follows the marks the best share passed, the
    compiled update reads the agent's variable (no retrace), and a resume comes back at the halved weight."""
    spec = toy.spec("ppo", tmp_path, entropy_coef=0.04, entropy_halve_at=(0.3, 0.6), lr_halve_at=(0.6,))
    ppo_trainer.train(spec)
    rollouts = pd.read_csv(spec.run_dir / "rollouts.csv")
    metrics = pd.read_csv(spec.run_dir / "metrics.csv")
    steps = spec.config.n_steps * spec.config.num_envs
    best, weights, rates = 0.0, [], []
    for r in rollouts["rollout"]:
        weights.append(0.04 * 0.5 ** sum(best >= mark for mark in (0.3, 0.6)))
        rates.append(1e-3 * 0.5 ** (best >= 0.6))
        ended = metrics[metrics["env_steps"] <= r * steps]
        if len(ended) >= spec.config.window:
            best = max(best, ended["success_share"].iloc[-1])
    np.testing.assert_allclose(rollouts["entropy_coef"], weights)
    np.testing.assert_allclose(rollouts["lr"], rates)
    assert rollouts["entropy_coef"].iloc[-1] == pytest.approx(0.01)  # both marks passed
    before = len(rollouts)
    spec.resume = True
    spec.config = dataclasses.replace(spec.config, max_episodes=len(metrics) + 10, stop_success_share=0.0)
    ppo_trainer.train(spec)
    resumed = pd.read_csv(spec.run_dir / "rollouts.csv").iloc[before:]
    assert len(resumed)
    np.testing.assert_allclose(resumed["entropy_coef"], 0.01)


def test_the_loss_reads_the_weight_it_is_given():
    import tensorflow as tf

    from rlcore.algorithms.ppo.agent import ppo_losses

    cfg = PPOConfig(entropy_coef=0.5)
    logits = tf.constant([[1.0, 0.0], [0.0, 2.0]])
    args = (logits, tf.constant([0.1, 0.2]), tf.constant([0, 1]), tf.constant([-0.5, -0.3]),
            tf.constant([1.0, -1.0]), tf.constant([0.0, 0.5]), cfg)
    total, _, _, entropy, _, _ = ppo_losses(*args)
    halved = ppo_losses(*args, tf.constant(0.25))[0]
    assert float(halved - total) == pytest.approx(0.25 * float(entropy), rel=1e-5)
