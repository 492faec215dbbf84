"""The greedy evaluation's per-episode records: seed order, lengths, time limit against a fall,
final info values, and the summary that goes into meta.json."""
import dataclasses

import gymnasium as gym
import numpy as np
import pytest

from rlcore.environments.experiment import Experiment, Goal, ShippedBy
from rlcore.models.shipping import run_evaluation
from rlcore.training.evaluation import evaluate, evaluate_success, play_greedy

LIMIT = 6


class FallOrWalk(gym.Env):
    """Pays 1 per step; x grows 0.5 per step. An even seed s falls (terminates) after 1 + s % 5
    steps; an odd seed walks until the time limit."""
    observation_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    action_space = gym.spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        seed = 1 if seed is None else seed  # the vector env's own auto-reset passes none
        self.t, self.fall_at = 0, (1 + seed % 5 if seed % 2 == 0 else None)
        return np.zeros(1, np.float32), {}

    def step(self, action):
        self.t += 1
        fell = self.t == self.fall_at
        return np.zeros(1, np.float32), 1.0, fell, not fell and self.t >= LIMIT, {"x": 0.5 * self.t}


def expected(seed):
    length = 1 + seed % 5 if seed % 2 == 0 else LIMIT
    return {"seed": seed, "return": float(length), "length": length, "time_limit": seed % 2 == 1,
            "x": 0.5 * length}


EXP = Experiment(name="fall", description="falls on even seeds", make_env=lambda **_: FallOrWalk(),
                 algos={}, solved_score=5.0, info_keys=("x",))
ALWAYS_ZERO = lambda obs: np.zeros(len(obs), np.int64)  # noqa: E731


def test_each_record_belongs_to_its_seed_also_when_an_env_plays_a_second_episode():
    # 25 episodes on 20 envs side by side: five envs play a second seed after a short first episode
    records = play_greedy(EXP, ALWAYS_ZERO, episodes=25, seed_base=100, progress=False, info_keys=("x", "absent"))
    assert records == [expected(s) for s in range(100, 125)]  # a key the env never reports is left out
    returns = evaluate(EXP, ALWAYS_ZERO, episodes=25, seed_base=100, progress=False)
    np.testing.assert_array_equal(returns, [r["return"] for r in records])


def test_success_records_keep_the_info_keys_the_env_reported_and_leave_out_the_others():
    records = evaluate_success(FallOrWalk, lambda obs, rng: ALWAYS_ZERO(obs), 4, 100, "won", progress=False,
                               info_keys=("x", "absent"))
    assert [r["x"] for r in records] == [expected(s)["x"] for s in range(100, 104)]
    assert not any("absent" in r for r in records)


def test_the_summary_counts_the_episodes_that_lasted_to_the_time_limit():
    class Policy:
        make_env = staticmethod(FallOrWalk)

        def __call__(self, obs):
            return ALWAYS_ZERO(obs)

    summary, line = run_evaluation(EXP, Policy(), episodes=4, seed_base=10)
    # seeds 10, 11, 12, 13: lengths 1, 6, 3, 6
    assert summary["time_limit_share"] == 0.5 and summary["mean"] == pytest.approx(4.0)
    assert summary["mean_x"] == pytest.approx(2.0)
    assert [r["seed"] for r in summary["per_episode"]] == [10, 11, 12, 13]
    assert "2/4 lasted to the time limit" in line and "x at the end: mean 2.00, max 3.00" in line


class FallWithCause(FallOrWalk):
    """FallOrWalk with a success (the time limit reached) and, at a fall, its cause: the seed % 3."""

    def step(self, action):
        obs, reward, fell, limit, info = super().step(action)
        if fell:
            info["cause"] = float(self.fall_at % 3)
        return obs, reward, fell, limit, {**info, "won": limit}


def test_a_success_evaluation_counts_its_failures_by_cause():
    class Policy:
        make_env = staticmethod(FallWithCause)

        def sample(self, obs, rng):
            return ALWAYS_ZERO(obs)

    exp = Experiment(name="cause", description="", make_env=lambda **_: FallWithCause(), algos={},
                     solved_score=None, info_keys=("cause",),
                     goal=Goal("won", cause_key="cause", cause_name=lambda code: ["rock", "hole", "bird"][int(code)]))
    # seeds 10-17: the odd ones win; 10, 12, 14, 16 fall after 1, 3, 5, 2 steps: causes 1, 0, 2, 2
    summary, line = run_evaluation(exp, Policy(), episodes=8, seed_base=10)
    assert summary["success_share"] == 0.5 and summary["causes"] == {"bird": 2, "hole": 1, "rock": 1}
    assert "won in 4 of 8 episodes (50%)" in line
    # an experiment that ships one model per level names a success by the model's level, as the README does
    castle = dataclasses.replace(exp, name="mario_ppo", shipped_by=ShippedBy(("world", "stage"), "1-1"))
    for stage, word in ((4, "axe"), (1, "flag")):
        _, line = run_evaluation(castle, Policy(), episodes=8, seed_base=10, meta={"config": {"world": 2, "stage": stage}})
        assert line.startswith(f"{word} in 4 of 8 episodes (50%)"), line and "; cause: bird 2, hole 1, rock 1 (seeds 10..17" in line
