"""The Mario wrappers on the real NES emulator: frames, stacking, the classic reward and the shaping."""
import gymnasium as gym
import numpy as np
import pytest

from mario_ppo.deaths import KilledBy
from mario_ppo.env import FRAME_SIZE, SkipAndHistory, SkipAndStack, gray_84, make_env
from mario_ppo.episode_ends import DeadEnds, StallLimit
from mario_ppo.rewards import ClassicReward, classic_reward
from rlcore.errors import UserError
from tests.mario_ppo.scripted import ScriptedInfos

RIGHT = 1  # SIMPLE_MOVEMENT[1] == ['right']


@pytest.fixture(scope="module")
def env():
    env = make_env()
    yield env
    env.close()


def test_observation_is_four_gray_uint8_frames(env):
    obs, info = env.reset(seed=0)
    assert obs.shape == (FRAME_SIZE, FRAME_SIZE, 4) and obs.dtype == np.uint8
    assert env.observation_space.contains(obs)
    assert (obs[:, :, :1] == obs).all()  # reset shows the first frame four times
    assert info["x_pos"] == 40 and info["flag_get"] is False
    assert env.action_space.n == 7


def test_step_stacks_the_four_skipped_frames_in_order(env):
    """Replaying the same actions frame by frame on a second emulator gives the same four frames."""
    import gym_super_mario_bros  # noqa: F401
    import gymnasium as gym
    from gym_super_mario_bros.actions import SIMPLE_MOVEMENT
    from nes_py.wrappers import JoypadSpace

    raw = JoypadSpace(gym.make("SuperMarioBros-1-1-v0").unwrapped, SIMPLE_MOVEMENT)
    raw.reset(seed=0)
    env.reset(seed=0)
    for _ in range(10):  # walk right for 10 agent steps = 40 frames
        obs, *_ = env.step(RIGHT)
        frames = [gray_84(raw.step(RIGHT)[0]) for _ in range(4)]
    raw.close()
    for i in range(4):
        np.testing.assert_array_equal(obs[:, :, i], frames[i])
    assert not np.array_equal(obs[:, :, 0], obs[:, :, 3])  # Mario moved between them


def test_history_stack_keeps_one_max_pooled_frame_per_step_for_the_last_four_steps():
    """frames="history" (uvipen's): channel 3 is the max of the gray 3rd and 4th frames of this step,
    channels 0-2 are the previous observation's 1-3; replayed frame by frame on a second emulator."""
    import gym_super_mario_bros  # noqa: F401
    from gym_super_mario_bros.actions import SIMPLE_MOVEMENT
    from nes_py.wrappers import JoypadSpace

    env = make_env(frames="history")
    raw = JoypadSpace(gym.make("SuperMarioBros-1-1-v0").unwrapped, SIMPLE_MOVEMENT)
    try:
        first, _ = env.reset(seed=0)
        raw_first = gray_84(raw.reset(seed=0)[0])
        assert first.shape == (FRAME_SIZE, FRAME_SIZE, 4) and env.observation_space.contains(first)
        for i in range(4):
            np.testing.assert_array_equal(first[:, :, i], raw_first)
        previous, max_mattered = first, False
        for step in range(12):  # run right, with jumps (A) in steps 4-7
            action = 2 if 4 <= step < 8 else RIGHT  # SIMPLE_MOVEMENT[2] == ['right', 'A']
            obs, *_ = env.step(action)
            frames = [gray_84(raw.step(action)[0]) for _ in range(4)]
            np.testing.assert_array_equal(obs[:, :, 3], np.maximum(frames[2], frames[3]))
            np.testing.assert_array_equal(obs[:, :, :3], previous[:, :, 1:])
            max_mattered |= not np.array_equal(obs[:, :, 3], frames[3])
            previous = obs
        assert not np.array_equal(previous[:, :, 0], previous[:, :, 3])  # Mario moved in 4 steps
        assert max_mattered  # the channel is not simply the step's last frame
    finally:
        env.close()
        raw.close()


def test_running_right_pays_the_x_gain_over_ten(env):
    env.reset(seed=0)
    x_before = 40
    total = 0.0
    for _ in range(5):
        _, reward, terminated, _, info = env.step(RIGHT)
        total += reward
        assert not terminated
    # no death, no clock tick this early: reward = change of x / 10, summed over 4 frames each
    assert total == pytest.approx((info["x_pos"] - x_before) / 10.0, abs=0.15)
    assert total > 0


def test_death_ends_the_episode_with_the_shaped_penalty(env):
    """Walking right into the first Goomba kills Mario: -25 in the classic reward, -50 shaping, / 10."""
    env.reset(seed=0)
    rewards = []
    for _ in range(200):
        _, reward, terminated, truncated, info = env.step(RIGHT)
        rewards.append(reward)
        if terminated or truncated:
            break
    assert terminated and not truncated and not info["flag_get"]
    # the last step holds the death: at most (3 frames of +5 x) + (-25) + (-50), then / 10
    assert rewards[-1] <= (15 - 25 - 50) / 10 + 1e-6
    assert rewards[-1] >= (-15 * 4 - 50) / 10 - 1e-6
    assert max(rewards[:-1]) <= 4 * 15 / 10


def test_classic_reward_rules():
    assert classic_reward(103, 100, 400, 400, False) == 3
    assert classic_reward(200, 100, 400, 400, False) == 0  # a jump of more than 5: a warp, not running
    assert classic_reward(100, 100, 399, 400, False) == -1  # the clock ticked
    assert classic_reward(100, 100, 400, 300, False) == 0  # the clock went up: a reset
    assert classic_reward(104, 100, 399, 400, True) == -15  # 4 - 1 - 25 = -22, clipped to -15


def _classic_rewards(infos, score_reward):
    env = ClassicReward(ScriptedInfos(infos), score_reward)
    env.reset()
    return [env.step(0)[1] for _ in infos[1:]]


def test_score_reward_adds_the_change_of_the_game_score():
    infos = [(100, 400, 0, False), (103, 400, 100, False), (104, 399, 100, False), (104, 399, 300, True)]
    assert _classic_rewards(infos, 0.0) == [3, 0, -15]  # the article's reward ignores the score
    # uvipen's 1/40: +2.5 for a 100-point stomp, +5 for 200 points, added after the clip
    assert _classic_rewards(infos, 0.025) == [3 + 2.5, 0, -15 + 5]


def test_unknown_level_action_set_and_frame_stack_are_clear_errors():
    with pytest.raises(UserError, match="no level 9-1"):
        make_env(world=9)
    with pytest.raises(UserError, match="unknown action set 'fancy'"):
        make_env(actions="fancy")
    with pytest.raises(UserError, match="unknown frame stack 'pooled'"):
        make_env(frames="pooled")


def test_rgb_array_keeps_every_emulator_frame_for_video():
    env = make_env(render_mode="rgb_array")
    env.reset(seed=0)
    env.step(RIGHT)
    frames = env.get_wrapper_attr("frames")
    assert len(frames) == 4 and frames[0].shape == (240, 256, 3)
    env.close()


def test_gray_of_the_emulator_screen_view_equals_cv2_on_a_contiguous_copy(env):
    import cv2

    env.reset(seed=0)
    screen = env.unwrapped.screen  # nes-py's zero-copy view of its BGRx pixels
    assert screen.strides[1:] == (4, -1)
    rng = np.random.default_rng(0)
    for _ in range(40):
        if env.step(int(rng.integers(env.action_space.n)))[2]:
            env.reset()
        want = cv2.resize(cv2.cvtColor(np.ascontiguousarray(screen), cv2.COLOR_RGB2GRAY),
                          (FRAME_SIZE, FRAME_SIZE))
        np.testing.assert_array_equal(gray_84(screen), want)


def test_reward_and_stall_options_reach_the_env_from_the_config():
    import dataclasses

    from mario_ppo.experiment import EXPERIMENT

    cfg = dataclasses.replace(EXPERIMENT.preset("ppo", "default"), stall_steps=7, score_reward=0.025,
                              frames="history", dead_ends=True, stage=2)
    env = EXPERIMENT.env_factory(cfg)()  # what the pool's workers and a saved model's policy build
    try:
        assert isinstance(env, StallLimit) and env.steps == 7
        assert env.get_wrapper_attr("score_reward") == 0.025
        assert isinstance(env.env, DeadEnds) and env.env.rule is not None
        assert isinstance(env.env.env, KilledBy) and isinstance(env.env.env.env, SkipAndHistory)
    finally:
        env.close()
    plain = EXPERIMENT.env_factory(EXPERIMENT.preset("ppo", "default"))()
    assert not isinstance(plain, StallLimit) and plain.get_wrapper_attr("score_reward") == 0.0
    assert type(plain) is KilledBy and type(plain.env) is SkipAndStack
    plain.close()
