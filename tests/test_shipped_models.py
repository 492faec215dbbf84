"""Every shipped model loads from its .h5, clears its bar on seeded episodes, and carries its story."""
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from rlcore.evaluation import evaluate
from rlcore.experiment import experiment_names, get_experiment
from rlcore.policies import load_policy
from rlcore.video import record_video

SHIPPED = Path(__file__).resolve().parents[1] / "saved_networks"
# SPEC.md "our bar", greedy mean return
BARS = {
    ("lunar_lander", "dqn"): 230.0, ("lunar_lander", "ddqn"): 230.0,
    ("lunar_lander", "dueling_dqn"): 230.0, ("lunar_lander", "dueling_ddqn"): 230.0,
    ("lunar_lander", "a2c"): 200.0,
    ("cartpole", "dqn"): 500.0, ("cartpole", "a2c"): 500.0, ("cartpole_v0", "a2c"): 200.0,
    ("minitaur", "sac"): 11.3,  # RL Zoo's published PPO2 result (issue 17); article 004's peak was 0.85
}
# the share of the recorded evaluation's episodes that lasted to the time limit (a walk, not a dash)
FULL_LENGTH_SHARES = {("minitaur", "sac"): 0.5}
# experiment, algo, folder under saved_networks/EXPERIMENT/ -> the success event and the least share of
# the recorded evaluation's episodes that reached it (issue 14: 5 of 10 on every level, 8 of 10 on 1-1);
# the test also replays 3 seeded episodes and wants the event in at least one
SUCCESS_BARS = {("mario_ppo", "ppo", level): ("flag_get", 0.8 if level == "1-1" else 0.5)
                for level in ("1-1", "1-2", "1-3", "1-4", "2-1", "2-2", "2-3", "2-4")}
EPISODES = {"minitaur": 3}  # seeded episodes replayed by the test (1000 physics-heavy steps each)


def test_every_bar_names_a_registered_algorithm():
    for experiment, algo in BARS:
        get_experiment(experiment).algo(algo)


def test_no_model_is_shipped_without_a_bar():
    for name in experiment_names():
        for algo in get_experiment(name).algos:
            if (SHIPPED / name / algo / "meta.json").exists():
                assert (name, algo) in BARS
            if get_experiment(name).ship_by:
                for meta in (SHIPPED / name).glob("*/meta.json"):
                    assert (name, algo, meta.parent.name) in SUCCESS_BARS, meta


@pytest.mark.parametrize("experiment, algo", sorted(BARS))
def test_shipped_model_meets_its_bar(experiment, algo):
    bar = BARS[experiment, algo]
    exp, meta, policy = load_policy(SHIPPED / experiment / algo, experiment, algo)
    # the recorded story: our own training command, seed, budget, time, a 100-episode evaluation
    assert meta["command"].startswith(f"python main.py train {experiment} {algo}")
    for key in ("seed", "env_steps", "episodes", "wall_seconds", "config", "versions"):
        assert key in meta, key
    assert meta["evaluation"]["episodes"] == exp.eval_episodes
    assert meta["evaluation"]["mean"] >= bar
    if (experiment, algo) in FULL_LENGTH_SHARES:
        assert meta["evaluation"]["time_limit_share"] >= FULL_LENGTH_SHARES[experiment, algo]
    # and it still plays: seeded episodes from the unseen-seed range, each as its record says
    returns = evaluate(exp, policy, episodes=EPISODES.get(experiment, 5), progress=False)
    assert returns.mean() >= bar, f"{experiment} {algo}: {returns.round(1)}"
    recorded = meta["evaluation"]["per_episode"]
    assert len(recorded) == exp.eval_episodes
    assert np.mean([r["return"] for r in recorded]) == pytest.approx(meta["evaluation"]["mean"], abs=0.01)
    assert [r["seed"] for r in recorded[:len(returns)]] == list(range(exp.eval_seed_base,
                                                                        exp.eval_seed_base + len(returns)))
    np.testing.assert_allclose(returns, [r["return"] for r in recorded[:len(returns)]], rtol=1e-5)


@pytest.mark.parametrize("experiment, algo, folder", sorted(SUCCESS_BARS))
def test_shipped_model_reaches_its_goal(experiment, algo, folder):
    from rlcore.evaluation import evaluate_success

    key, share = SUCCESS_BARS[experiment, algo, folder]
    exp, meta, policy = load_policy(SHIPPED / experiment / folder, experiment, algo)
    assert meta["command"].startswith(f"python main.py train {experiment} {algo}")
    assert meta["evaluation"]["episodes"] == exp.eval_episodes
    assert meta["evaluation"]["success_share"] >= share
    records = evaluate_success(policy.make_env, policy.sample, 3, exp.eval_seed_base, key,
                               exp.progress_key, progress=False, stop_at_success=True)
    assert any(r["success"] for r in records), records
    # each episode replays its record (seeded env and seeded action draws)
    recorded = meta["evaluation"]["per_episode"]
    assert np.mean([r["success"] for r in recorded]) == pytest.approx(meta["evaluation"]["success_share"])
    for got, want in zip(records, recorded):
        assert (got["seed"], got["success"], got["length"]) == (want["seed"], want["success"], want["length"])
        assert got[exp.progress_key] == want[exp.progress_key]


def test_render_of_a_shipped_model_is_a_decodable_mp4(tmp_path):
    exp, meta, policy = load_policy(SHIPPED / "lunar_lander" / "dqn")
    out = tmp_path / "dqn.mp4"
    result = record_video(exp, policy, out, fps=30)
    frames = iio.imread(out)
    assert len(frames) == result["frames"] > 10
    assert frames.shape[1:] == (400, 600, 3)
    assert iio.immeta(out)["fps"] == pytest.approx(30)
