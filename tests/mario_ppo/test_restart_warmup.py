"""A restart plays the last frames before its point, so the frame stack starts as it was."""
import gymnasium as gym
import numpy as np

from mario_ppo.emulator_states import WARMUP
from mario_ppo.env import SkipAndHistory, SkipAndStack, action_list, make_env
from mario_ppo.restarts import Restarts

RIGHT = 1  # SIMPLE_MOVEMENT[1] == ['right']
EVERY = 80


def _restarts_on_the_emulator():
    import gym_super_mario_bros  # noqa: F401  registers the ids
    from nes_py.wrappers import JoypadSpace

    base = gym.make("SuperMarioBros-1-1-v0").unwrapped
    return Restarts(JoypadSpace(base, action_list("simple")), 1.0, every=EVERY)


def test_a_restart_shows_the_frames_that_led_to_its_point():
    env = _restarts_on_the_emulator()
    try:
        env.reset(seed=0)
        screens = []
        while True:
            screen, _, _, _, info = env.step(RIGHT)
            screens.append(np.array(screen))
            if info["x_pos"] >= EVERY:
                break
        screen, info = env.reset(seed=1)
        assert info["restarted"] and len(info["warmup_frames"]) == WARMUP
        for shown, seen in zip(info["warmup_frames"], screens[-WARMUP:]):
            np.testing.assert_array_equal(shown, seen)  # the emulator is deterministic
        np.testing.assert_array_equal(screen, screens[-1])
    finally:
        env.close()


def test_the_stacks_build_their_first_observation_from_the_warmup_frames():
    frames = [np.full((240, 256, 3), 10 * i, np.uint8) for i in range(1, 17)]  # frame i is gray ~10 i
    stack = SkipAndStack.__new__(SkipAndStack)
    stack.skip = 4
    skipped = stack._first_obs(frames[-1], frames)
    assert [int(skipped[0, 0, c]) for c in range(4)] == [130, 140, 150, 160]  # the last step's frames
    history = SkipAndHistory.__new__(SkipAndHistory)
    history.skip = 4
    steps = history._first_obs(frames[-1], frames)
    assert [int(steps[0, 0, c]) for c in range(4)] == [40, 80, 120, 160]  # max of each step's 2nd half
    alone = history._first_obs(frames[-1], [])
    assert (alone == alone[:, :, :1]).all()  # no warm-up: the one frame four times
    short = history._first_obs(frames[5], frames[:6])  # 6 frames: steps of frames 1-2 and 3-6
    assert [int(short[0, 0, c]) for c in range(4)] == [20, 20, 20, 60]


def test_a_restarted_episode_starts_with_the_motion_it_had():
    env = make_env(frames="history", restart_every=EVERY, restart_share=1.0)
    try:
        first, _ = env.reset(seed=0)
        assert all((first[:, :, c] == first[:, :, 0]).all() for c in range(4))  # the level's start
        while env.step(RIGHT)[4]["x_pos"] < EVERY:
            pass
        obs, info = env.reset(seed=1)
        assert info["restarted"] and "warmup_frames" not in info  # the frames stay in the worker
        assert not (obs[:, :, 0] == obs[:, :, 3]).all()  # Mario walked (and the screen scrolled)
    finally:
        env.close()
