"""The rules that end a Mario episode before the game does (mario_ppo/episode_ends.py): a stall, a
known dead end; on stand-ins and on the real emulator."""
from pathlib import Path

import numpy as np

from mario_ppo.env import make_env
from mario_ppo.episode_ends import WARP_DROP, DeadEnds, StallLimit
from tests.mario_ppo.scripted import ScriptedInfos, ScriptedPlaces

NOOP = 0
# 2-2's exit pipe: the route (buttons per frame) of a training run's restart point at x 2,900, kept
# by a checkpoint of `long_runs/mario_ppo/2-2`, then agent actions that swim into the pipe (found by
# a random search) and come out in the overworld at x 2,872
EXIT_PIPE_2_2 = Path(__file__).parent / "data" / "exit_pipe_2-2.npz"


def test_stall_limit_truncates_after_steps_without_a_new_best_x():
    xs = [100, 101, 102, 102, 90, 102, 103, 103, 103, 103]
    env = StallLimit(ScriptedInfos([(x, 400, 0, False) for x in xs]), steps=3)
    env.reset()
    steps = [env.step(0) for _ in xs[1:]]
    # best x 102 at step 2; steps 3, 4, 5 bring nothing new -> truncated at step 5; 103 resets the count
    assert [s[3] for s in steps] == [False, False, False, False, True, False, False, False, True]
    assert not any(s[2] for s in steps)  # a truncation, never a termination (PPO bootstraps it)


def test_a_stall_can_end_as_a_death_with_the_end_penalty():
    xs = [100, 101, 101, 101, 101]
    env = StallLimit(ScriptedInfos([(x, 400, 0, False) for x in xs]), steps=3, outcome="death")
    env.reset()
    steps = [env.step(0) for _ in xs[1:]]
    assert [s[2] for s in steps] == [False, False, False, True] and not any(s[3] for s in steps)
    assert steps[-1][1] == 123.0 - 5.0  # the stand-in's reward, then -50 / 10 as at any other death
    assert steps[0][1] == 123.0


def test_a_dead_end_of_the_level_ends_as_a_death():
    # 1-2: underground past x 2,750 is the ceiling route to the warp zone; the exit pipe leads
    # overworld (area 1), where x 2,872 and on is the way to the flag
    places = [(2600, 2), (2740, 2), (2872, 1), (2930, 1), (2751, 2)]
    env = DeadEnds(ScriptedPlaces(places), world=1, stage=2)
    env.reset()
    steps = [env.step(0) for _ in places[1:]]
    assert [s[2] for s in steps] == [False, False, False, True]
    assert [s[4]["dead_end"] for s in steps] == [False, False, False, True]
    assert steps[-1][1] == 123.0 - 5.0 and steps[0][1] == 123.0
    other_level = DeadEnds(ScriptedPlaces(places), world=1, stage=1)  # no rule: nothing changes
    other_level.reset()
    assert not any(other_level.step(0)[2] for _ in places[1:])


def test_a_pipe_into_another_area_starts_the_stall_count_over():
    # running back is counted as any step; a fall of x of more than WARP_DROP in one step is a pipe
    xs = [100, 101, 102, 102, 102 - WARP_DROP, 20, 20, 20, 20]
    env = StallLimit(ScriptedInfos([(x, 400, 0, False) for x in xs]), steps=3)
    env.reset()
    steps = [env.step(0) for _ in xs[1:]]
    # steps 3-4 count 2 (the fall of WARP_DROP is running back); step 5 is the pipe: 0 at x 20,
    # then 1, 2, 3 -> truncated at step 8, not at step 5
    assert [s[3] for s in steps] == [False, False, False, False, False, False, False, True]


def test_the_exit_pipe_of_2_2_does_not_end_mario_as_stalled():
    """Out of 2-2's exit pipe (x 3,010) Mario stands at x 2,872 in the overworld, behind his best:
    the stall count starts over there, so he has the whole limit to climb the staircase to the flag."""
    kept = np.load(EXIT_PIPE_2_2)
    stall = 150  # longer than the search's 144 steps at the wall before it found the pipe
    env = make_env(world=2, stage=2, frames="history", stall_steps=stall, stall_outcome="death",
                   restart_every=725, restart_share=1.0)
    try:
        env.set_wrapper_attr("restart_routes", {"4": kept["route"]})
        _, info = env.reset(seed=0)
        assert info["restarted"] and info["x_pos"] >= 2900
        best = info["x_pos"]
        for action in kept["actions"]:
            _, _, terminated, truncated, info = env.step(int(action))
            assert not (terminated or truncated)
            best = max(best, info["x_pos"])
        assert best == 3010 and info["x_pos"] == 2872 and env.unwrapped.ram[0x074E] == 1  # overworld
        xs, ended = [info["x_pos"]], False
        while not ended:  # stand still: the stall limit ends the episode, counted from the pipe
            _, _, terminated, truncated, info = env.step(NOOP)
            xs.append(info["x_pos"])
            ended = terminated or truncated
        assert info["stalled"] and terminated and max(xs) < best
        last_rise = int(np.argmax(xs))  # the first step at the highest x: the last new best
        assert len(xs) - 1 - last_rise == stall
    finally:
        env.close()
