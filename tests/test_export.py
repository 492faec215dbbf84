"""Export: each kind of acting network in each format, loaded by its own runtime, matches Keras.

The shipped models are the small models of each kind: LunarLander's DQN Q-network, CartPole's A2C
actor, Mario 1-1's PPO actor-critic (uint8 frames), Minitaur's SAC actor with its Standardize layer.
Observations come once per model from one episode of its own env on the first evaluation seed.
"""
import json
from pathlib import Path

import numpy as np
import pytest

import main
from rlcore.algorithms.registry import family
from rlcore.errors import UserError
from rlcore.models import export
from rlcore.models.export_parity import ABS_TOLERANCE, REL_TOLERANCE, ParityError, collect_observations
from rlcore.models.policies import load_policy
from tests.cpu_support import needs_bfloat16

SHIPPED = Path(__file__).resolve().parents[1] / "saved_networks"
MODELS = {"dqn": "lunar_lander/dqn", "a2c": "cartpole/a2c", "ppo": "mario_ppo/1-1", "sac": "minitaur/sac"}


@pytest.fixture(scope="module", params=list(MODELS))
def model(request):
    """(kind, model folder, observations from its env) for each kind of acting network."""
    folder = SHIPPED / MODELS[request.param]
    exp, meta, policy = load_policy(folder)
    obs, seeds = collect_observations(exp, policy, count=64, episodes=1)
    assert seeds == f"{exp.eval_seed_base}..{exp.eval_seed_base}"
    assert len(obs) == 64 and obs.dtype == policy.dtype
    return request.param, folder, obs


@pytest.mark.parametrize("fmt", export.FORMATS)
def test_every_kind_exports_in_every_format_and_matches_keras(model, fmt, tmp_path):
    kind, folder, obs = model
    out = tmp_path / f"{kind}_{fmt}"
    record = export.export_model(folder, fmt, out, observations=obs)
    assert (out / export.FILES[fmt]).exists()
    assert json.loads((out / "export.json").read_text()) == record
    parity = record["parity"]
    assert parity["passed"] and parity["observations"] == 64
    assert parity["max_abs_diff"] <= parity["tolerance"] < 2e-3  # 1e-4 + 1e-5 x Q-values up to ~130
    if kind == "sac":
        assert parity["max_mean_action_diff"] == parity["max_abs_diff"]
        assert "greedy_action_agreement" not in parity
    else:
        assert parity["greedy_action_agreement"] == 1.0 or parity["ties"] > 0
    assert record["kind"] == kind and record["format"] == fmt and record["source_model"] == str(folder)
    assert record["runtime"]["name"].startswith({"savedmodel": "tensorflow", "tflite": "ai-edge-litert",
                                                 "onnx": "onnxruntime"}[fmt])
    assert record["versions"]["tensorflow"] and record["network"]["input"]["dtype"] == str(obs.dtype)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left


def test_sac_export_carries_its_standardize_layer():
    from rlcore.networks.layers import Standardize

    exp, meta, policy = load_policy(SHIPPED / "minitaur" / "sac")
    acting, as_trained = export.acting_network(policy.model, family("sac").acting_network)
    standardize = [layer for layer in policy.model.layers if isinstance(layer, Standardize)]
    assert standardize and as_trained is None
    assert not np.allclose(standardize[0].var.numpy(), 1.0)  # the running statistics, not the defaults
    obs = np.random.default_rng(0).normal(size=(8, *policy.model.input_shape[1:])).astype(np.float32)
    # tanh(mean), as evaluated; the two graphs may sum in another order, so within the parity tolerance (an
    # Intel Xeon without avx512_bf16 differed by 1.5e-6 where the EPYC that wrote this test matched to 1e-6)
    np.testing.assert_allclose(acting(obs).numpy(), policy(obs), atol=ABS_TOLERANCE, rtol=REL_TOLERANCE)


@needs_bfloat16
def test_a_bfloat16_network_is_exported_in_float32():
    from rlcore.algorithms.ppo.agent import build_actor_critic

    model = build_actor_critic((16, 16, 4), 3, precision="bfloat16")
    acting, as_trained = export.acting_network(model, family("ppo").acting_network)
    assert as_trained == "bfloat16"
    assert {layer.dtype_policy.name for layer in acting.layers} == {"float32"}
    frames = np.random.default_rng(0).integers(0, 256, (8, 16, 16, 4), dtype=np.uint8)
    np.testing.assert_allclose(acting(frames).numpy(), model(frames)[0].numpy(), atol=0.05)


def test_a_failed_parity_check_is_one_line_and_keeps_the_earlier_export(monkeypatch, tmp_path, capsys):
    out = tmp_path / "lander"
    folder = SHIPPED / "lunar_lander" / "dqn"
    assert main.main(["export", "lunar_lander", "dqn", "--format", "savedmodel", "--out", str(out),
                      "--observations", "32"]) == 0
    printed = capsys.readouterr().out
    assert "parity:" in printed and "passed" in printed
    before = (out / "export.json").read_text()

    from rlcore.models import export_parity
    real = export_parity._run_savedmodel
    monkeypatch.setattr(export_parity, "_run_savedmodel", lambda path, obs: real(path, obs) + 0.01)
    with pytest.raises(ParityError, match="failed its parity check"):
        export.export_model(folder, "savedmodel", out, observations=32)
    assert main.main(["export", "lunar_lander", "dqn", "--format", "savedmodel", "--out", str(out),
                      "--observations", "32"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: savedmodel export of") and "\n" not in err
    assert (out / "export.json").read_text() == before  # the earlier export, untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lander"]
    monkeypatch.undo()
    # an export that passes replaces the folder whole, and says what it replaced
    assert main.main(["export", "lunar_lander", "dqn", "--format", "savedmodel", "--out", str(out),
                      "--observations", "32"]) == 0
    assert "it replaced the earlier savedmodel (lunar_lander dqn) export there" in capsys.readouterr().out


def test_export_of_a_missing_model_folder_is_one_line(tmp_path, capsys):
    code = main.main(["export", "lunar_lander", "dqn", "--model", str(tmp_path / "nowhere"),
                      "--format", "onnx", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err == f"error: {tmp_path / 'nowhere'}: no such model folder"
    assert not (tmp_path / "out").exists()


def test_bad_formats_and_outputs_are_refused_before_any_work(tmp_path):
    folder = SHIPPED / "lunar_lander" / "dqn"
    with pytest.raises(UserError, match="unknown export format"):
        export.export_model(folder, "pt", tmp_path / "x")
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    with pytest.raises(UserError, match="not an export"):
        export.export_model(folder, "onnx", tmp_path / "busy")
    assert (tmp_path / "busy" / "notes.txt").read_text() == "mine"


def test_short_episodes_are_followed_by_more_until_the_observations_asked_for():
    """An env whose episodes end in 5 steps still gives the parity check the 64 observations asked for
    (3 such episodes gave 15 and the check said nothing), from more evaluation seeds, named."""
    import types

    import gymnasium as gym

    class Short(gym.Env):
        observation_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        action_space = gym.spaces.Discrete(2)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.t = 0
            return np.full(2, seed % 7, np.float32), {}

        def step(self, action):
            self.t += 1
            return np.full(2, self.t, np.float32), 0.0, self.t >= 5, False, {}

    exp = types.SimpleNamespace(eval_seed_base=1_000_000, goal=None)
    policy = type("P", (), {"make_env": staticmethod(Short), "dtype": np.float32,
                            "__call__": lambda self, batch: np.zeros(len(batch), int)})()
    obs, seeds = collect_observations(exp, policy, count=64, episodes=3)
    assert len(obs) == 64 and seeds == "1000000..1000012"  # 13 episodes of 5 steps: 65 observations seen
    obs, seeds = collect_observations(exp, policy, count=4, episodes=3)
    assert len(obs) == 4 and seeds == "1000000..1000002"  # never fewer episodes than asked
