"""A restart x that steps itself back (``--restart-back-step``), on the real emulator (1-1, running right).

Running right alone on 1-1 passes x 240 before the first Goomba, so every episode here gets past
GOAL unless it is cut short.
"""
import dataclasses
from collections import deque

import numpy as np
import pytest

from mario_ppo.curriculum import X_KEY, StepBack, lend_routes
from mario_ppo.env import make_env
from mario_ppo.experiment import EXPERIMENT
from rlcore.errors import UserError
from rlcore.training import checkpoints
from tests.mario_ppo.test_restarts import _restarts, _run_right_past

X, GOAL, STEP, WINDOW = 160, 230, 40, 3


def _stepping_env(x=X, keep="furthest"):
    env = make_env(restart_x=x, restart_share=1.0, restart_keep=keep, restart_back_step=STEP,
                   restart_goal_x=GOAL)
    _restarts(env).stepper.outcomes = deque(maxlen=WINDOW)  # decide on 3 restarted episodes, not 40
    return env


def _restarted_episodes(env, reach_x, count):
    """A first episode from the start that passes x and the goal, then ``count`` restarted episodes,
    each running right until ``reach_x``; the start x of each, and the info of the reset after the last."""
    env.reset(seed=0)
    _run_right_past(env, GOAL + 5)
    info, starts = env.reset(seed=1)[1], []
    for _ in range(count):
        assert info["restarted"]
        starts.append(info["start_x"])
        _run_right_past(env, reach_x)
        info = env.reset()[1]
    return starts, info


@pytest.mark.parametrize("keep", ["furthest", "latest"])
def test_the_x_steps_back_once_the_window_of_restarts_got_past_the_goal(keep):
    env = _stepping_env(keep=keep)
    try:
        starts, info = _restarted_episodes(env, GOAL, WINDOW)
        assert all(X <= s < X + 10 for s in starts)  # three restarts from x 160, all past the goal
        assert _restarts(env).x == X - STEP
        assert info["restarted"] and X - STEP <= info["start_x"] < X - STEP + 10
        assert len(_restarts(env).stepper.outcomes) == 0  # the new x is judged on its own restarts
    finally:
        env.close()


def test_the_x_stays_while_the_restarts_fall_short_of_the_goal():
    env = _stepping_env()
    try:
        _, info = _restarted_episodes(env, GOAL - 40, 2 * WINDOW)
        assert _restarts(env).x == X and X <= info["start_x"] < X + 10
        assert list(_restarts(env).stepper.outcomes) == [False] * WINDOW
    finally:
        env.close()


def test_the_x_steps_forward_again_when_hardly_any_restart_gets_past_but_never_past_where_it_began():
    env = _stepping_env()
    try:
        _restarted_episodes(env, GOAL, WINDOW)  # three past the goal: back to x 120
        assert _restarts(env).x == X - STEP
        for _ in range(WINDOW):  # three from x 120 that stop short of the goal
            info = env.reset()[1]
            assert info["restarted"] and X - STEP <= info["start_x"] < X - STEP + 10
            _run_right_past(env, GOAL - 40)
        info = env.reset()[1]
        assert _restarts(env).x == X and X <= info["start_x"] < X + 10
    finally:
        env.close()


def test_a_checkpoint_keeps_each_envs_stepped_x():
    first = _stepping_env()
    try:
        _restarted_episodes(first, GOAL, WINDOW)
        routes = first.get_wrapper_attr("restart_routes")
    finally:
        first.close()
    assert int(routes[X_KEY][0]) == X - STEP
    for built_with, expected in ((X, X - STEP), (X - 2 * STEP, X - 2 * STEP)):
        second = _stepping_env(x=built_with)
        try:
            second.set_wrapper_attr("restart_routes", routes)
            info = second.reset(seed=5)[1]
            assert _restarts(second).x == expected  # never past the x the resumed run gives
            assert info["restarted"] and expected <= info["start_x"] < expected + 10
        finally:
            second.close()
    plain = make_env(restart_x=X, restart_share=1.0, restart_keep="furthest")
    try:
        plain.set_wrapper_attr("restart_routes", routes)  # without stepping, the kept x is ignored
        assert _restarts(plain).x == X and X_KEY not in plain.get_wrapper_attr("restart_routes")
    finally:
        plain.close()


def test_the_rule_steps_back_at_half_forward_at_a_tenth_and_holds_in_between():
    rule = StepBack(600, 10, 850, back_share=0.5, window=10)
    moves = [rule.judge(reach) for reach in [900] * 5 + [800] * 5]  # 5 of 10 past the goal
    assert moves == [False] * 9 + [True] and rule.x == 590 and len(rule.outcomes) == 0
    moves = [rule.judge(reach) for reach in [900] * 2 + [800] * 8]  # 2 of 10: in between, no move
    assert not any(moves) and rule.x == 590
    assert rule.judge(800) and rule.x == 600  # one more miss: 1 of the last 10, forward again
    assert not any(rule.judge(800) for _ in range(30)) and rule.x == 600  # never past where it began
    assert rule.restore(550) == 550 and rule.restore(650) == 600


def test_stepping_back_needs_one_restart_x_and_a_goal_past_it():
    default = EXPERIMENT.preset("ppo", "default")
    for fields in (dict(restart_back_step=STEP, restart_goal_x=GOAL),
                   dict(restart_back_step=STEP, restart_x=X),
                   dict(restart_back_step=STEP, restart_x=X, restart_goal_x=X)):
        with pytest.raises(UserError, match="--restart-back-step needs"):
            dataclasses.replace(default, **fields)
    dataclasses.replace(default, restart_back_step=STEP, restart_x=X, restart_goal_x=GOAL)


def test_a_resumed_pool_lends_the_routes_of_envs_that_stepped_back_to_envs_that_never_did():
    def env(x, route):
        return {"1": np.full(3, route, np.uint8), X_KEY: np.array([x])}

    run = dataclasses.replace(EXPERIMENT.preset("ppo", "levels"), restart_x=600, restart_back_step=10,
                              restart_goal_x=850)
    per_env = [env(600, 0), env(540, 1), env(600, 2), env(570, 3), env(600, 4)]
    got = lend_routes(per_env, run)
    assert [int(kept[X_KEY][0]) for kept in got] == [540, 540, 570, 570, 540]
    assert [int(kept["1"][0]) for kept in got] == [1, 1, 3, 3, 1]
    stepped = [env(510, 0), env(540, 1)]
    assert lend_routes(stepped, run) is stepped  # every env stepped back: each keeps its own
    level = [env(600, 0), env(600, 1)]
    assert lend_routes(level, run) is level  # none did: nothing to lend
    plain = [{"1": np.zeros(3, np.uint8)}, {}]
    assert lend_routes(plain, run) is plain  # no stepping x
    assert EXPERIMENT.curriculum.share_memory is lend_routes


def test_give_env_memory_hands_out_what_the_experiment_shares():
    class Pool:
        num_envs = 2

        def give_memory(self, name, values):
            self.given = (name, values)

    pool, arrays = Pool(), {"env/0/x": np.array([600]), "env/1/x": np.array([500]), "replay/other": 1}
    checkpoints.give_env_memory(pool, "routes", arrays, share=lambda per_env, config: per_env[::config])
    assert pool.given == ("routes", [{"x": arrays["env/0/x"]}, {"x": arrays["env/1/x"]}])
    checkpoints.give_env_memory(pool, "routes", arrays, lambda per_env, config: per_env[::config], -1)
    assert pool.given == ("routes", [{"x": arrays["env/1/x"]}, {"x": arrays["env/0/x"]}])
