"""Restarts on the real emulator: training episodes may start where an earlier episode passed an x;
evaluation envs never do."""
import dataclasses

import numpy as np

from mario_ppo.env import make_env
from mario_ppo.experiment import EXPERIMENT
from mario_ppo.restarts import Restarts

RIGHT = 1  # SIMPLE_MOVEMENT[1] == ['right']
X = 200


def _run_right_past(env, x):
    while True:
        obs, _, terminated, truncated, info = env.step(RIGHT)
        assert not (terminated or truncated)
        if info["x_pos"] >= x:
            return obs, info


def test_after_an_episode_passed_x_a_restart_starts_there_and_keeps_that_state():
    env = make_env(restart_x=X, restart_share=1.0)
    try:
        start_obs, info = env.reset(seed=0)
        assert info["restarted"] is False and info["x_pos"] < X  # nothing kept yet: the level's start
        assert info["start_x"] == info["x_pos"]
        _, passed = _run_right_past(env, X)
        assert passed["start_x"] == info["x_pos"]  # where the episode began, on every step
        restarts = []
        for seed in (1, 2):
            obs, info = env.reset(seed=seed)
            restarts.append(info["x_pos"])
            assert info["restarted"] is True and X <= info["x_pos"] <= passed["x_pos"]
            assert not np.array_equal(obs, start_obs)  # the screen there, not the level's first frame
            assert info["start_x"] == restarts[-1]
            _, _, _, _, info = env.step(RIGHT)
            assert info["restarted"] is True and info["x_pos"] >= restarts[-1] == info["start_x"]
            for _ in range(30):  # a restarted episode plays on from there
                if any(env.step(RIGHT)[2:4]):
                    break
        assert restarts[0] == restarts[1]
    finally:
        env.close()


def test_the_share_of_restarts_follows_the_seeded_rng():
    def restarted(share):
        env = make_env(restart_x=X, restart_share=share)
        env.reset(seed=0)
        _run_right_past(env, X)
        marks = [env.reset(seed=s)[1]["restarted"] for s in range(1, 41)]
        env.close()
        return marks

    half = restarted(0.5)
    assert 10 <= sum(half) <= 30 and half == restarted(0.5)
    plain = make_env(restart_x=X, restart_share=0.0)  # share 0: no Restarts wrapper at all
    assert "restarted" not in plain.reset(seed=0)[1]
    plain.close()


def test_restarts_reach_the_training_envs_only():
    cfg = dataclasses.replace(EXPERIMENT.preset("ppo", "default"), restart_every=EVERY, restart_share=0.25,
                              restart_weights="deaths")

    def wrappers(env):
        found = []
        while hasattr(env, "env"):
            found.append(type(env))
            env = env.env
        return found

    training = EXPERIMENT.training_env_factory(cfg)()
    evaluation = EXPERIMENT.env_factory(cfg)()  # what evaluate, render and a saved model's policy build
    try:
        kept = [w for w in wrappers(training) if w is Restarts]
        assert kept and training.get_wrapper_attr("share") == 0.25
        assert training.get_wrapper_attr("weights") == "deaths"
        assert Restarts not in wrappers(evaluation)
        assert "restarted" not in evaluation.reset(seed=0)[1]
    finally:
        training.close()
        evaluation.close()


EVERY = 80  # walking right alone on 1-1 passes x 240 before the first Goomba


def test_with_a_spacing_restarts_start_at_every_kept_point_and_restarted_episodes_add_further_ones():
    env = make_env(restart_every=EVERY, restart_share=1.0)
    try:
        env.reset(seed=0)
        _run_right_past(env, 2 * EVERY)  # passes the points at 80 and 160
        starts = [env.reset(seed=s)[1]["x_pos"] for s in range(1, 13)]
        assert {x // EVERY for x in starts} == {1, 2}  # both points drawn, and nothing else
        assert all(x < 3 * EVERY for x in starts)
        seed = 20
        while env.reset(seed=seed)[1]["x_pos"] < 2 * EVERY:  # a restart at the furthest point ...
            seed += 1
        _run_right_past(env, 3 * EVERY)  # ... that gets further keeps the next point too
        later = {env.reset(seed=s)[1]["x_pos"] // EVERY for s in range(30, 50)}
        assert later == {1, 2, 3}
    finally:
        env.close()


def test_one_restart_point_or_a_spacing_not_both():
    import pytest

    from rlcore.errors import UserError

    default = EXPERIMENT.preset("ppo", "default")
    with pytest.raises(UserError, match="--restart-x and --restart-every"):
        dataclasses.replace(default, restart_x=X, restart_every=EVERY)
    with pytest.raises(ValueError):
        Restarts(make_env().unwrapped, 0.5)


def test_a_fresh_env_given_the_kept_routes_restarts_where_the_first_one_did():
    first, second = (make_env(restart_every=EVERY, restart_share=1.0) for _ in range(2))
    try:
        first.reset(seed=0)
        _run_right_past(first, 2 * EVERY)
        seed = 10
        while first.reset(seed=seed)[1]["x_pos"] < 2 * EVERY:  # a restarted episode goes further:
            seed += 1
        _run_right_past(first, 3 * EVERY)  # point 3's route runs through point 2's
        routes = first.get_wrapper_attr("restart_routes")
        assert sorted(routes) == ["1", "2", "3"] and all(r.dtype == np.uint8 for r in routes.values())
        second.set_wrapper_attr("restart_routes", routes)  # what a resumed run's pool does
        for seed in range(1, 7):  # the same seeded draws load the same places, screen for screen
            a_obs, a_info = first.reset(seed=seed)
            b_obs, b_info = second.reset(seed=seed)
            assert b_info["restarted"] and b_info["x_pos"] == a_info["x_pos"]
            assert np.array_equal(a_obs, b_obs)
        broken = {"2": routes["2"][: len(routes["2"]) // 2]}  # stops short of its point: left out
        third = make_env(restart_every=EVERY, restart_share=1.0)
        third.set_wrapper_attr("restart_routes", broken)
        assert third.get_wrapper_attr("restart_routes") == {}
        third.close()
    finally:
        first.close()
        second.close()


def test_a_pool_of_processes_hands_the_routes_out_and_back():
    from rlcore.environments.vector import EnvPool
    from rlcore.training import checkpoints

    cfg = dataclasses.replace(EXPERIMENT.preset("ppo", "default"), restart_every=EVERY, restart_share=1.0)
    factory = EXPERIMENT.training_env_factory(cfg)
    with EnvPool([factory] * 2, mode="processes") as envs:
        envs.reset(seed=[0, 1])
        for _ in range(60):  # 240 frames of `right`: both envs pass x 160 (and die nowhere)
            envs.step(np.full(2, RIGHT))
        arrays = checkpoints.env_memory(envs, EXPERIMENT.curriculum.memory)
    assert {"env/0/1", "env/0/2", "env/1/1", "env/1/2"} <= set(arrays)
    with EnvPool([factory] * 2, mode="processes") as resumed:
        checkpoints.give_env_memory(resumed, EXPERIMENT.curriculum.memory, arrays)
        _, infos = resumed.reset(seed=[5, 6])
        assert infos["restarted"].all() and (infos["x_pos"] >= EVERY).all()


def test_death_weights_add_one_to_the_failures_at_each_kept_point():
    from mario_ppo.restarts import death_weights

    # failures at 0 (before the first point) and at 5 (no state kept there) weigh nothing
    got = death_weights([1, 2, 3, 4], [2, 2, 2, 3, 0, 5])
    np.testing.assert_allclose(got, np.array([1, 4, 2, 1]) / 8)
    np.testing.assert_allclose(death_weights([3, 7], []), [0.5, 0.5])


def _restarts(env):
    while not isinstance(env, Restarts):
        env = env.env
    return env


def test_an_episode_that_dies_counts_as_a_failure_at_its_point():
    env = make_env(restart_every=EVERY, restart_share=1.0, restart_weights="deaths")
    try:
        env.reset(seed=0)
        assert list(_restarts(env).failures) == []
        while True:  # running right on 1-1 meets the first Goomba (test_deaths)
            _, _, terminated, truncated, info = env.step(RIGHT)
            if terminated or truncated:
                break
        env.reset(seed=1)
        assert list(_restarts(env).failures) == [info["x_pos"] // EVERY] and info["x_pos"] >= EVERY
        env.reset(seed=2)  # no step since the last reset: nothing to count
        assert len(_restarts(env).failures) == 1
    finally:
        env.close()


def test_restarts_weighted_by_deaths_go_where_the_failures_were():
    def starts(weights, failures):
        env = make_env(restart_every=EVERY, restart_share=1.0, restart_weights=weights)
        try:
            env.reset(seed=0)
            _run_right_past(env, 2 * EVERY)  # points 1 and 2 kept
            _restarts(env).failures.extend(failures)
            return [env.reset(seed=s)[1]["x_pos"] // EVERY for s in range(1, 31)]
        finally:
            env.close()

    weighted = starts("deaths", [2] * 40)  # point 2 drawn with probability 41/42
    assert weighted.count(2) >= 27
    uniform = starts("uniform", [2] * 40)
    assert 6 <= uniform.count(2) <= 24
    assert starts("deaths", [2] * 40) == weighted  # the seeded RNG draws the same points


def test_unknown_restart_weights_are_refused():
    import pytest

    from rlcore.errors import UserError

    with pytest.raises(UserError, match="restart.weights"):
        dataclasses.replace(EXPERIMENT.preset("ppo", "default"), restart_weights="nearest")
    with pytest.raises(ValueError, match="unknown restart weights"):
        Restarts(make_env().unwrapped, 0.5, every=EVERY, weights="nearest")
