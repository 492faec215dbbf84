"""Adding an algorithm is one folder and one registry line (docs/developer/adding-an-algorithm.md): a toy
family (tests/toy_family.py, REINFORCE with a baseline) registered and driven through the ordinary
commands: train, evaluate, resume, evaluate a run in progress, export, load from Python. A kind the
registry does not know is one line, never another family's default."""
import json
import shutil

import numpy as np
import pytest

from rlcore import api
from rlcore.algorithms import registry
from rlcore.errors import UserError
from tests import toy_family
from tests.test_cli import run as cli

ENV = "CartPole-v1"


@pytest.fixture
def toy_registered():
    registry.register(toy_family.FAMILY)
    yield toy_family.FAMILY
    registry.unregister(toy_family.KIND)


def test_the_update_follows_the_numpy_reference_of_reinforce():
    """G_t by hand for 3 rewards, and the gradient of -mean(log pi(a|s) (G - mean G)) with respect to the
    softmax layer's weights compared with its closed form."""
    np.testing.assert_allclose(toy_family.discounted_returns(np.array([1.0, 0.0, 2.0]), 0.5), [1.5, 1.0, 2.0])
    import tensorflow as tf

    cfg = toy_family.ReinforceConfig(hidden=(2,), lr=0.1)
    agent = toy_family.ReinforceAgent(2, 2, cfg)
    w = np.array([[0.5, -0.5], [0.0, 1.0]], np.float32)
    agent.model.set_weights([np.eye(2, dtype=np.float32), np.zeros(2, np.float32), w, np.zeros(2, np.float32)])
    states = np.array([[1.0, 0.0], [0.0, 1.0]], np.float32)
    actions = np.array([0, 1], np.int32)
    advantages = np.array([1.0, -1.0], np.float32)
    hidden = np.tanh(states)  # the identity first layer, then tanh
    logits = hidden @ w
    probs = np.exp(logits) / np.exp(logits).sum(axis=1, keepdims=True)
    onehot = np.eye(2)[actions]
    expected_grad = -(hidden.T @ ((onehot - probs) * advantages[:, None])) / len(states)  # d loss / d W
    with tf.GradientTape() as tape:
        p = agent.model(states)
        loss = -tf.reduce_mean(tf.math.log(tf.gather(p, actions, batch_dims=1)) * advantages)
    np.testing.assert_allclose(tape.gradient(loss, agent.model.trainable_variables[2]).numpy(), expected_grad,
                               rtol=1e-5, atol=1e-6)


def test_a_registered_family_trains_evaluates_resumes_exports_and_loads(toy_registered, tmp_path, capsys):
    run_dir = tmp_path / "run"
    code, out, err = cli(capsys, "train", ENV, "reinforce", "--episodes", "4", "--checkpoint-every", "2",
                         "--run-dir", str(run_dir), "--wandb", "off", "--no-progress", "--final-eval-episodes", "2")
    assert code == 0, err
    meta = json.loads((run_dir / "model" / "meta.json").read_text())
    assert (meta["kind"], meta["algo"], meta["episodes"]) == (toy_family.KIND, "reinforce", 4)
    assert (run_dir / "model" / toy_family.MODEL_FILE).is_file() and meta["evaluation"]["episodes"] == 2

    code, out, err = cli(capsys, "evaluate", ENV, "reinforce", "--model", str(run_dir), "--episodes", "2")
    assert code == 0 and "greedy return" in out, err

    code, out, err = cli(capsys, "train", ENV, "reinforce", "--resume", str(run_dir), "--episodes", "6",
                         "--wandb", "off", "--no-progress", "--final-eval-episodes", "0")
    assert code == 0, err
    assert json.loads((run_dir / "model" / "meta.json").read_text())["episodes"] == 6

    in_progress = tmp_path / "in_progress"  # a checkpoint and no model yet: a run still training
    in_progress.mkdir()
    for name in ("checkpoint.npz", "metrics.csv"):
        shutil.copy(run_dir / name, in_progress / name)
    code, out, err = cli(capsys, "evaluate", ENV, "reinforce", "--model", str(in_progress), "--episodes", "2")
    assert code == 0 and "greedy return" in out, err

    code, out, err = cli(capsys, "export", ENV, "reinforce", "--model", str(run_dir), "--format", "onnx",
                         "--out", str(tmp_path / "onnx"))
    assert code == 0, err
    record = json.loads((tmp_path / "onnx" / "export.json").read_text())
    assert record["kind"] == toy_family.KIND and record["parity"]["passed"]
    assert record["network"]["output"]["meaning"] == toy_family.FAMILY.export_output

    policy = api.load(run_dir)
    env = policy.make_env()
    obs, _ = env.reset(seed=0)
    assert policy.predict(obs) in (0, 1)
    assert policy.predict(obs, deterministic=False, rng=np.random.default_rng(0)) in (0, 1)
    env.close()


def test_an_unknown_kind_is_one_line_not_another_familys_default(tmp_path, capsys, toy_registered):
    run_dir = tmp_path / "run"
    code, _, err = cli(capsys, "train", ENV, "reinforce", "--episodes", "2", "--run-dir", str(run_dir),
                       "--wandb", "off", "--no-progress", "--final-eval-episodes", "0")
    assert code == 0, err
    registry.unregister(toy_family.KIND)  # a model of a family this install does not have
    with pytest.raises(UserError, match="no algorithm family 'toy_reinforce'"):
        registry.family(toy_family.KIND)
    code, out, err = cli(capsys, "evaluate", ENV, "reinforce", "--model", str(run_dir), "--episodes", "1")
    assert code != 0 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    registry.register(toy_family.FAMILY)


def test_a_kind_taken_is_refused():
    with pytest.raises(UserError, match="registered already"):
        registry.register(registry.family("dqn"))
