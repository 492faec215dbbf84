"""Every shipped model loads from its .h5, clears its bar, still plays, and carries its story.

Two ways to check that a model still plays, chosen by :func:`rlcore.host.machine.replays_exactly`:

- where its evaluation was recorded (the same CPU and package versions), its first seeded episodes
  must repeat the record exactly;
- anywhere else they need not: TensorFlow's oneDNN orders float sums by the CPU's vector units, so a
  greedy argmax or a sampled action can flip and an episode take another course (the shipped Minitaur
  model returned 22.86 on an Intel Xeon where an AMD EPYC recorded 22.48). There the test plays live
  episodes from the same unseen seeds and asserts what holds on every machine: the live episodes give
  no evidence, at the 0.1 % level, that the model falls short of its bar.
"""
import json
import math
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from rlcore.environments.registry import experiment_names, get_experiment
from rlcore.host import machine
from rlcore.models.policies import load_policy
from rlcore.models.video import record_video
from rlcore.training.evaluation import evaluate, evaluate_success
from tests.cpu_support import skip_where_its_precision_cannot_run

SHIPPED = Path(__file__).resolve().parents[1] / "saved_networks"
Z_ONE_SIDED = 3.09  # the standard normal's 99.9th percentile: a 0.1 % chance of failing a model at its bar
# live episodes played where a record cannot replay: enough that a model clearly below its bar fails
# (LunarLander's spread is ~20-90 points, so 20 episodes bound the mean within ~45-60 of the bar)
LIVE_EPISODES = {"lunar_lander": 20, "cartpole": 5, "cartpole_v0": 5, "minitaur": 3}
# recorded episodes replayed exactly on the recording machine (default 5): one 1,000-step Minitaur episode
# (a return that differs in its last digits shows any drift within it)
REPLAYED_EPISODES = {"minitaur": 1}
# a success-scored model (Mario) plays sampled episodes until one reaches the flag: at the lowest recorded
# share (1-2's 14 of 30), ten misses in a row have a chance of 0.2 %
SUCCESS_TRIES = 10


def read_json(path: Path) -> dict:
    return json.loads(path.read_text())


def shipped_models() -> list[tuple[str, str, str]]:
    """(experiment, algorithm, model folder name) of every model under saved_networks/."""
    found = []
    for name in experiment_names():
        exp = get_experiment(name)
        for meta in sorted((SHIPPED / name).glob("*/meta.json")):
            folder = meta.parent.name
            algos = [folder] if folder in exp.algos else list(exp.algos)  # Mario: a level, one algo
            found.append((name, algos[0], folder))
    return found


MODELS = shipped_models()


def test_every_shipped_model_has_a_bar_and_every_bar_a_model():
    shipped = {(experiment, folder) for experiment, _, folder in MODELS}
    for experiment, _, folder in MODELS:
        assert get_experiment(experiment).bar(folder) is not None, (experiment, folder)
    for name in experiment_names():
        exp = get_experiment(name)
        for folder in exp.bars:
            assert folder in exp.algos or exp.shipped_by, (name, folder)
            if folder in exp.algos:
                assert (name, folder) in shipped, (name, folder)
    assert len(MODELS) == 17


def still_plays(exp, meta: dict, policy, folder: str) -> str:
    """Check that the model plays as its record says; returns which check ran: "replay" or "bar"."""
    if machine.replays_exactly(machine.recorded_machine(meta)):
        _replay_exactly(exp, meta, policy)
        return "replay"
    _clears_bar_live(exp, meta, policy, folder)
    return "bar"


def _replay_exactly(exp, meta, policy) -> None:
    recorded = meta["evaluation"]["per_episode"]
    if goal := exp.goal:
        records = evaluate_success(policy.make_env, policy.sample, 3, exp.eval_seed_base, goal.success_key,
                                   goal.progress_key, progress=False, stop_at_success=True)
        for got, want in zip(records, recorded):
            assert (got["seed"], got["success"], got["length"]) == (want["seed"], want["success"], want["length"])
            assert got[goal.progress_key] == want[goal.progress_key]
        return
    n = REPLAYED_EPISODES.get(exp.name, 5)
    returns = evaluate(exp, policy, episodes=n, progress=False, make_env=policy.make_env)
    assert [r["seed"] for r in recorded[:n]] == list(range(exp.eval_seed_base, exp.eval_seed_base + n))
    np.testing.assert_allclose(returns, [r["return"] for r in recorded[:n]], rtol=1e-5)


def _clears_bar_live(exp, meta, policy, folder: str) -> None:
    bar = exp.bar(folder)
    if goal := exp.goal:
        records = evaluate_success(policy.make_env, policy.sample, SUCCESS_TRIES, exp.eval_seed_base,
                                   goal.success_key, goal.progress_key, progress=False, stop_at_success=True)
        assert records[-1]["success"], f"{exp.name} {folder}: no {goal.success_key} in {len(records)} episodes"
        return
    n = LIVE_EPISODES[exp.name]
    returns = evaluate(exp, policy, episodes=n, progress=False, make_env=policy.make_env)
    recorded_std = meta["evaluation"]["std"]
    # the larger of the recorded and the live spread: a cap-reaching model records 0, and a few live
    # episodes can understate a wide spread
    spread = max(recorded_std, float(returns.std(ddof=1)))
    floor = bar.value - Z_ONE_SIDED * spread / math.sqrt(n)
    assert returns.mean() >= floor, (f"{exp.name} {folder}: live mean {returns.mean():.1f} over {n} episodes "
                                     f"is below {floor:.1f} (bar {bar.value:g}): {returns.round(1)}")


@pytest.mark.parametrize("experiment, algo, folder", MODELS)
def test_shipped_model_meets_its_bar(experiment, algo, folder):
    skip_where_its_precision_cannot_run(read_json(SHIPPED / experiment / folder / "meta.json"))
    exp, meta, policy = load_policy(SHIPPED / experiment / folder, experiment, algo)
    bar = exp.bar(folder)
    # the recorded story: our own training command, seed, budget, time, an evaluation on unseen seeds
    assert meta["command"].startswith(f"python main.py train {experiment} {algo}")
    for key in ("seed", "env_steps", "episodes", "wall_seconds", "config", "versions"):
        assert key in meta, key
    evaluation = meta["evaluation"]
    assert evaluation["episodes"] == exp.eval_episodes
    # met, unless the registry says why the model ships below its bar (and then not met, or the note is stale)
    assert bar.met_by(evaluation) != (folder in exp.below_bar), (
        bar, exp.below_bar.get(folder), {k: v for k, v in evaluation.items() if k != "per_episode"})
    recorded = evaluation["per_episode"]
    assert len(recorded) == exp.eval_episodes
    if exp.goal:
        assert np.mean([r["success"] for r in recorded]) == pytest.approx(evaluation["success_share"], abs=5e-4)  # kept to 3 decimals
    else:
        assert np.mean([r["return"] for r in recorded]) == pytest.approx(evaluation["mean"], abs=0.01)
    still_plays(exp, meta, policy, folder)


@pytest.mark.parametrize("experiment, algo, folder", [("lunar_lander", "dqn", "dqn"),
                                                      ("mario_ppo", "ppo", "1-1")])
def test_on_another_cpu_a_model_is_held_to_its_bar_not_to_its_record(experiment, algo, folder, monkeypatch):
    """This machine recorded most models, so the path other CPUs take is proven by pretending to be one."""
    exp, meta, policy = load_policy(SHIPPED / experiment / folder, experiment, algo)
    other = {"cpu": "Another CPU (avx2 fma)", "versions": machine.package_versions()}
    monkeypatch.setattr(machine, "this_machine", lambda: other)
    assert still_plays(exp, meta, policy, folder) == "bar"


def test_a_record_replays_exactly_only_on_its_own_cpu_and_versions():
    here = {"cpu": "AMD EPYC (avx2 fma avx512f)", "versions": {"tensorflow": "2.21.0", "numpy": "2.5.5"}}
    assert machine.replays_exactly(here, here)
    assert not machine.replays_exactly({**here, "cpu": "Intel(R) Xeon(R) (avx2 fma avx512f amx_tile)"}, here)
    assert not machine.replays_exactly({**here, "versions": {"tensorflow": "2.20.0"}}, here)
    assert not machine.replays_exactly(None, here)  # a record that does not say where it was made
    # oneDNN off changes the numbers on one CPU too; a record without settings was made with the defaults
    assert not machine.replays_exactly(here, {**here, "settings": {"onednn": False}})
    assert machine.replays_exactly(here, {**here, "settings": {"onednn": True}})
    # the evaluation's own machine wins over the training run's
    meta = {"cpu": "A", "versions": {}, "evaluation": {"machine": {"cpu": "B", "versions": {}}}}
    assert machine.recorded_machine(meta)["cpu"] == "B"
    assert machine.recorded_machine({"evaluation": {}}) is None


def test_render_of_a_shipped_model_is_a_decodable_mp4(tmp_path):
    exp, meta, policy = load_policy(SHIPPED / "lunar_lander" / "dqn")
    out = tmp_path / "dqn.mp4"
    result = record_video(exp, policy, out, fps=30)
    frames = iio.imread(out)
    assert len(frames) == result["frames"] > 10
    assert frames.shape[1:] == (400, 600, 3)
    assert iio.immeta(out)["fps"] == pytest.approx(30)


def test_turning_onednn_off_is_part_of_what_a_record_replays_on(monkeypatch):
    for name in ("TF_ENABLE_ONEDNN_OPTS", *machine.NUMERIC_VARIABLES):
        monkeypatch.delenv(name, raising=False)
    assert machine.this_machine()["settings"] == {"onednn": True}
    for off in ("0", "false", "False"):
        monkeypatch.setenv("TF_ENABLE_ONEDNN_OPTS", off)
        assert machine.this_machine()["settings"] == {"onednn": False}
    recorded = {**machine.this_machine(), "settings": {"onednn": True}}
    assert not machine.replays_exactly(recorded)  # here oneDNN is off: the bar path, not the replay


def test_xla_flags_set_in_the_environment_are_part_of_what_a_record_replays_on(monkeypatch):
    """XLA's fast math may change what SAC's compiled update computes: a record made without it is not held to
    replay exactly with it."""
    for name in ("TF_ENABLE_ONEDNN_OPTS", *machine.NUMERIC_VARIABLES):
        monkeypatch.delenv(name, raising=False)
    recorded = machine.this_machine()
    assert recorded["settings"] == {"onednn": True} and machine.replays_exactly(recorded)
    monkeypatch.setenv("XLA_FLAGS", "--xla_cpu_enable_fast_math=true")
    assert machine.this_machine()["settings"] == {"onednn": True, "XLA_FLAGS": "--xla_cpu_enable_fast_math=true"}
    assert not machine.replays_exactly(recorded)
    monkeypatch.setenv("XLA_FLAGS", "")  # set but empty: as unset
    assert machine.replays_exactly(recorded)


def test_a_capped_onednn_instruction_set_is_part_of_what_a_record_replays_on(monkeypatch):
    """ONEDNN_MAX_CPU_ISA=AVX2 makes oneDNN pick the kernels of a CPU without AVX-512 (and refuse the
    bfloat16 convolutions TensorFlow still routes to it here): not the settings a record was made with."""
    for name in ("TF_ENABLE_ONEDNN_OPTS", *machine.NUMERIC_VARIABLES):
        monkeypatch.delenv(name, raising=False)
    recorded = machine.this_machine()
    for name, value in (("ONEDNN_MAX_CPU_ISA", "AVX2"), ("DNNL_MAX_CPU_ISA", "AVX2"),
                        ("ONEDNN_DEFAULT_FPMATH_MODE", "BF16")):
        monkeypatch.setenv(name, value)
        assert machine.this_machine()["settings"][name] == value and not machine.replays_exactly(recorded)
        monkeypatch.delenv(name)
    assert machine.replays_exactly(recorded)
