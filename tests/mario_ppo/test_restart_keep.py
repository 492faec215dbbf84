"""Which state a restart point keeps (``--restart-keep``), on the real emulator (1-1, walking right)."""
import dataclasses

import pytest

from mario_ppo.env import make_env
from mario_ppo.experiment import EXPERIMENT
from mario_ppo.restarts import Restarts

RIGHT, NOOP = 1, 0  # SIMPLE_MOVEMENT
EVERY = 80  # walking right alone on 1-1 passes x 240 before the first Goomba


def _walk(env, x, wait=0):
    """Stand still for ``wait`` steps, then walk right until x; the episode's route differs by wait."""
    for _ in range(wait):
        env.step(NOOP)
    while True:
        _, _, terminated, truncated, info = env.step(RIGHT)
        assert not (terminated or truncated)
        if info["x_pos"] >= x:
            return info


def _routes(env):
    return {int(k): bytes(r) for k, r in env.get_wrapper_attr("restart_routes").items()}


def _kept_after_a_far_then_a_near_episode(keep):
    """Episode 1 walks past points 1-3; episode 2 waits first, then walks past points 1-2 only. The
    kept routes after each episode ends."""
    env = make_env(restart_every=EVERY, restart_share=0.0001, restart_keep=keep)  # restarts ~never drawn
    try:
        env.reset(seed=0)
        _walk(env, 3 * EVERY)
        info = env.reset(seed=1)[1]
        assert not info["restarted"]
        far = _routes(env)
        assert sorted(far) == [1, 2, 3]
        _walk(env, 2 * EVERY, wait=10)
        env.reset(seed=2)  # episode 2 ends having reached point 2
        return far, _routes(env)
    finally:
        env.close()


def test_latest_keeps_the_last_episode_that_passed_a_point():
    far, kept = _kept_after_a_far_then_a_near_episode("latest")
    assert kept[3] == far[3]
    assert kept[1] != far[1] and kept[2] != far[2]  # episode 2's own (it stood still first)
    assert kept[1][:10] == bytes([NOOP] * 10)


def test_furthest_keeps_the_episode_that_went_furthest_past_a_point():
    far, kept = _kept_after_a_far_then_a_near_episode("furthest")
    assert kept == far  # episode 2 reached point 2, episode 1 point 3: points 1 and 2 stay episode 1's


def test_furthest_keeps_a_later_episode_that_goes_further_and_holds_states_until_it_ends():
    env = make_env(restart_every=EVERY, restart_share=0.0001, restart_keep="furthest")
    try:
        env.reset(seed=0)
        _walk(env, 2 * EVERY)
        assert _routes(env) == {}  # an episode's states are weighed when it ends
        env.reset(seed=1)
        _walk(env, 2 * EVERY + 30, wait=10)  # further, past the same two points
        env.reset(seed=2)
        kept = _routes(env)
        assert sorted(kept) == [1, 2] and all(route[:10] == bytes([NOOP] * 10) for route in kept.values())
    finally:
        env.close()


def test_furthest_restores_every_point_of_a_route_even_on_another_spacing():
    first = make_env(restart_every=EVERY, restart_share=0.0001)
    first.reset(seed=0)
    _walk(first, 3 * EVERY)
    route = first.get_wrapper_attr("restart_routes")["3"]  # latest: the route to point 3
    first.close()
    same = make_env(restart_every=EVERY, restart_share=1.0, restart_keep="furthest")
    finer = make_env(restart_every=EVERY // 2, restart_share=1.0, restart_keep="furthest")
    latest = make_env(restart_every=EVERY // 2, restart_share=1.0)
    try:
        same.set_wrapper_attr("restart_routes", {"3": route})
        assert _routes(same) == {1: route.tobytes(), 2: route.tobytes(), 3: route.tobytes()}
        finer.set_wrapper_attr("restart_routes", {"3": route})
        assert sorted(_routes(finer)) == [1, 2, 3, 4, 5, 6]  # x 240+ is point 6 of a 40 spacing
        starts = {finer.reset(seed=s)[1]["x_pos"] // (EVERY // 2) for s in range(20)}
        assert starts <= {1, 2, 3, 4, 5, 6} and len(starts) > 2
        latest.set_wrapper_attr("restart_routes", {"3": route})  # latest: point 3 is x 120 there
        assert _routes(latest) == {}
    finally:
        for env in (same, finer, latest):
            env.close()


def test_a_checkpoint_keeps_each_points_reach_for_furthest():
    """The route kept for a point runs to its episode's reach, so a resumed run (here with one
    restart x in place of a spacing) still prefers that episode's state to a shorter one's."""
    env = make_env(restart_every=EVERY, restart_share=0.0001, restart_keep="furthest")
    env.reset(seed=0)
    _walk(env, 3 * EVERY + 40)
    env.reset(seed=1)
    routes = env.get_wrapper_attr("restart_routes")
    env.close()
    assert len({r.tobytes() for r in routes.values()}) == 1  # one episode: one route, to its reach
    resumed = make_env(restart_x=2 * EVERY, restart_share=0.0001, restart_keep="furthest")
    try:
        resumed.set_wrapper_attr("restart_routes", routes)
        far = _routes(resumed)
        resumed.reset(seed=2)
        _walk(resumed, 2 * EVERY + 20, wait=10)  # passes x 160 too, but stops short of the first's reach
        resumed.reset(seed=3)
        assert _routes(resumed) == far == {1: routes["3"].tobytes()}
    finally:
        resumed.close()


def test_an_unknown_keep_rule_is_refused():
    from rlcore.errors import UserError

    with pytest.raises(UserError, match="restart.keep"):
        dataclasses.replace(EXPERIMENT.preset("ppo", "default"), restart_keep="best")
    with pytest.raises(ValueError, match="unknown restart keep rule"):
        Restarts(make_env().unwrapped, 0.5, every=EVERY, keep="best")


def test_the_keep_rule_reaches_the_training_envs():
    cfg = dataclasses.replace(EXPERIMENT.preset("ppo", "default"), restart_every=EVERY, restart_share=0.5,
                              restart_keep="furthest")
    env = EXPERIMENT.training_env_factory(cfg)()
    try:
        assert env.get_wrapper_attr("keep") == "furthest"
    finally:
        env.close()
