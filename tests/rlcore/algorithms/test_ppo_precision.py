"""PPO's ``precision="bfloat16"``: the feature layers compute in bfloat16, everything else stays float32,
and an update lands where the float32 update lands, much closer than the update itself moves."""
import dataclasses
import json

import numpy as np
import pytest
import tensorflow as tf

from rlcore.algorithms.ppo.agent import PPOAgent
from rlcore.files.checkpoint import load_checkpoint, save_checkpoint
from rlcore.networks.saving import load_keras_model
from tests.cpu_support import needs_bfloat16
from tests.rlcore.algorithms.test_ppo import CFG, OBS, _rollout

BF16 = dataclasses.replace(CFG, precision="bfloat16")


def _kl(p, q):
    return float(np.mean(np.sum(p * (np.log(p) - np.log(q)), axis=1)))


def _pair():
    tf.keras.utils.set_random_seed(7)
    full, half = PPOAgent(OBS, 5, CFG), PPOAgent(OBS, 5, BF16)
    half.model.set_weights(full.model.get_weights())
    return full, half


@needs_bfloat16
def test_only_the_feature_layers_compute_in_bfloat16():
    _, half = _pair()
    computes = {layer.name: layer.compute_dtype for layer in half.model.layers[1:]}
    assert computes.pop("policy_logits") == computes.pop("value") == "float32"
    assert set(computes.values()) == {"bfloat16"}, computes
    assert {w.dtype for w in half.model.get_weights()} == {np.dtype("float32")}  # Adam steps float32 weights
    logits, values = half._forward(np.zeros((2, *OBS), np.uint8))
    assert logits.dtype == values.dtype == tf.float32


@needs_bfloat16
def test_bfloat16_policy_and_update_track_float32():
    full, half = _pair()
    rollout = list(_rollout(np.random.default_rng(4)))
    obs = rollout[0].reshape(-1, *OBS)
    before, _ = full.policy_and_values(obs)
    rounded, _ = half.policy_and_values(obs)
    assert 0 < _kl(before, rounded) < 1e-4  # rounded (not the float32 path by mistake), and barely
    rollout[2] = np.log(before[np.arange(len(obs)), rollout[1].ravel()]).reshape(rollout[1].shape).astype(np.float32)
    report_full = full.update(*rollout, np.random.default_rng(5))
    report_half = half.update(*rollout, np.random.default_rng(5))
    after_full, _ = full.policy_and_values(obs)
    after_half, _ = half.policy_and_values(obs)
    moved = _kl(before, after_full)
    assert moved > 1e-3  # the update did move the policy, so the comparison below means something
    assert _kl(after_full, after_half) < 0.1 * moved, (_kl(after_full, after_half), moved)
    for name in ("policy_loss", "entropy", "approx_kl"):
        assert abs(report_full[name] - report_half[name]) < 0.1 * abs(report_full[name]) + 1e-3, name


@needs_bfloat16
def test_a_float32_checkpoint_resumes_in_bfloat16(tmp_path):
    """``--resume ... --precision bfloat16`` on a run trained in float32: the same weights and Adam state."""
    full, half = _pair()
    full.update(*_rollout(np.random.default_rng(0)), np.random.default_rng(0))
    save_checkpoint(tmp_path / "c.npz", full.models(), full.optimizers(), {})
    load_checkpoint(tmp_path / "c.npz", half.models(), half.optimizers())
    for a, b in zip(full.model.get_weights(), half.model.get_weights()):
        np.testing.assert_array_equal(a, b)
    assert int(half.opt.iterations) == int(full.opt.iterations) > 0


@needs_bfloat16
def test_a_bfloat16_model_saves_and_loads_as_trained(tmp_path):
    _, half = _pair()
    path = half.save(tmp_path)[0]
    loaded = load_keras_model(path, OBS, 5)
    assert loaded.get_layer("feature").compute_dtype == "bfloat16"
    obs = np.random.default_rng(1).integers(0, 256, (3, *OBS), dtype=np.uint8)
    for got, want in zip(loaded(obs), half.model(obs)):
        np.testing.assert_array_equal(np.asarray(got), np.asarray(want))


@pytest.mark.usefixtures("toy_experiments")
@needs_bfloat16
def test_a_bfloat16_run_trains_and_notes_a_cpu_without_bfloat16_units(tmp_path, monkeypatch, capsys):
    from rlcore.algorithms.ppo import train as ppo_trainer
    from tests import toy

    for flags, noted in (({"avx2"}, True), ({"avx2", "amx_bf16"}, False), ({"avx512f", "avx512_bf16"}, False)):
        monkeypatch.setattr(ppo_trainer, "cpu_flags", lambda flags=flags: flags)
        folder = tmp_path / "-".join(sorted(flags))
        meta = json.loads((ppo_trainer.train(toy.spec("ppo", folder, max_env_steps=64, stop_success_share=0.0,
                                                      precision="bfloat16")) / "meta.json").read_text())
        assert meta["config"]["precision"] == "bfloat16"
        out = capsys.readouterr().out
        note = "note: --precision bfloat16 was measured faster only on CPUs with amx_bf16 or avx512_bf16"
        assert (note in out) is noted


def test_a_capped_onednn_refuses_bfloat16_in_one_line_only_where_it_would_fail():
    from rlcore.host.cpu import bfloat16_refusal

    avx512 = {"avx2", "avx512f"}
    capped = {"ONEDNN_MAX_CPU_ISA": "avx2"}
    assert "ONEDNN_MAX_CPU_ISA=AVX2" in bfloat16_refusal("bfloat16", avx512, capped)
    assert "DNNL_MAX_CPU_ISA=AVX" in bfloat16_refusal("bfloat16", avx512, {"DNNL_MAX_CPU_ISA": "AVX"})
    assert bfloat16_refusal("float32", avx512, capped) is None
    assert bfloat16_refusal("bfloat16", {"avx2"}, capped) is None  # no AVX-512F: TensorFlow's own kernels
    assert bfloat16_refusal("bfloat16", {"avx2", "avx_ne_convert"}, capped) is not None
    assert bfloat16_refusal("bfloat16", None, capped) is None  # flags unknown: no claim
    assert bfloat16_refusal("bfloat16", avx512, {**capped, "TF_ENABLE_ONEDNN_OPTS": "0"}) is None
    for cap in ("AVX512_CORE", "avx512_core_bf16", "AVX10_1_512", "DEFAULT", "ALL", "NO_SUCH_ISA", ""):
        assert bfloat16_refusal("bfloat16", avx512, {"ONEDNN_MAX_CPU_ISA": cap}) is None, cap
    # AVX2_VNNI_2 has bfloat16 conversions, where the CPU has them
    assert bfloat16_refusal("bfloat16", {"avx2", "avx_ne_convert"}, {"ONEDNN_MAX_CPU_ISA": "AVX2_VNNI_2"}) is None
    assert bfloat16_refusal("bfloat16", avx512, {"ONEDNN_MAX_CPU_ISA": "AVX2_VNNI_2"}) is not None
    # oneDNN reads the new name first
    assert bfloat16_refusal("bfloat16", avx512, {"ONEDNN_MAX_CPU_ISA": "AVX512_CORE", "DNNL_MAX_CPU_ISA": "AVX2"}) is None


def test_a_bfloat16_network_is_not_built_nor_loaded_under_a_capped_onednn(monkeypatch, capsys):
    from pathlib import Path

    import main
    from rlcore.algorithms.ppo import agent as ppo
    from rlcore.errors import UserError
    from rlcore.models import policies

    # oneDNN reads its cap once, at its first kernel: run one before the cap is set, so that this process
    # (a test worker that goes on to other files) keeps the kernels it had whatever order the tests run in
    tf.nn.conv2d(tf.ones((1, 8, 8, 4)), tf.ones((3, 3, 4, 8)), 1, "SAME")
    monkeypatch.setenv("ONEDNN_MAX_CPU_ISA", "AVX2")
    monkeypatch.delenv("TF_ENABLE_ONEDNN_OPTS", raising=False)
    for module in (ppo, policies):  # as on an AVX-512 CPU, wherever these tests run
        monkeypatch.setattr(module, "cpu_flags", lambda: {"avx2", "avx512f"})
    with pytest.raises(UserError, match="ONEDNN_MAX_CPU_ISA=AVX2"):
        PPOAgent(OBS, 5, BF16)
    PPOAgent(OBS, 5, CFG)  # float32 is not affected
    shipped = Path(__file__).resolve().parents[3] / "saved_networks" / "mario_ppo"
    assert json.loads((shipped / "1-3" / "meta.json").read_text())["config"]["precision"] == "bfloat16"
    assert main.main(["evaluate", "mario_ppo", "ppo", "--world", "1", "--stage", "3", "--episodes", "1"]) == 2
    err = capsys.readouterr().err
    assert "ONEDNN_MAX_CPU_ISA=AVX2" in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
