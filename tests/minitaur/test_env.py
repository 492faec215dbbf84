"""Our Gymnasium Minitaur: spaces, seeding, the reward's parts, the leg model and rendering."""
import math

import gymnasium as gym
import numpy as np
import pytest

from minitaur.env import ENV_ID, SUBSTEP, MinitaurEnv, make_env
from minitaur.motor import OBSERVED_TORQUE_LIMIT, MotorModel
from minitaur.robot import leg_model_to_motor_angles


@pytest.fixture(scope="module")
def env():
    env = make_env()
    yield env
    env.close()


def test_spaces_and_registration(env):
    assert env.spec.id == ENV_ID and env.spec.max_episode_steps == 1000 and env.spec.reward_threshold == 15.0
    assert env.observation_space.shape == (28,) and env.action_space.shape == (8,)
    assert np.allclose(env.action_space.low, -1) and np.allclose(env.action_space.high, 1)
    high = env.observation_space.high
    assert high[0] == pytest.approx(math.pi + 0.01, rel=1e-6)
    assert high[8] == pytest.approx(16.0 / 0.0954 + 0.01, rel=1e-6)  # 167.72, the article's bound
    assert high[16] == pytest.approx(5.71, rel=1e-6) and high[24] == pytest.approx(1.01, rel=1e-6)
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and env.observation_space.contains(obs)
    assert np.linalg.norm(obs[24:]) == pytest.approx(1.0, abs=1e-5)  # a unit quaternion


def _trajectory(seed, steps=40):
    env = make_env()
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(123)
    out = [obs]
    for _ in range(steps):
        obs, reward, *_ = env.step(rng.uniform(-1, 1, 8))
        out += [obs, np.array([reward])]
    env.close()
    return np.concatenate(out)


def test_same_seed_same_trajectory_other_seed_other_robot():
    a, b, c = _trajectory(3), _trajectory(3), _trajectory(4)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)  # another seed draws other masses, friction, voltage


def test_reward_is_forward_progress_minus_energy():
    env = MinitaurEnv(randomize=False)
    env.reset(seed=0)
    x_before = env.robot.base_pose()[0][0]
    env._last_position = np.array(env.robot.base_pose()[0])
    _, reward, _, _, info = env.step(np.zeros(8))
    x_after = env.robot.base_pose()[0][0]
    assert info["forward"] == pytest.approx(x_after - x_before, abs=1e-12)
    _, velocities = env.robot.motor_states()
    energy = abs(np.dot(env.robot.observed_torques, velocities)) * SUBSTEP
    assert reward == pytest.approx((x_after - x_before) - 0.005 * energy, abs=1e-12)
    env.close()


def test_the_first_steps_progress_counts_from_the_origin_as_pybullets():
    """pybullet's -v0 task starts its last position at (0, 0, 0), not at the robot's start, so the
    first step's progress is the base's x after that step (our reset keeps that; later steps count
    from the step before)."""
    env = MinitaurEnv(randomize=False)
    env.reset(seed=0)
    start_x = env.robot.base_pose()[0][0]
    _, _, _, _, first = env.step(np.zeros(8))
    _, _, _, _, second = env.step(np.zeros(8))
    assert first["forward"] == pytest.approx(first["x"], abs=1e-12)
    assert abs(start_x) > 1e-6 and first["forward"] != pytest.approx(first["x"] - start_x, abs=1e-9)
    assert second["forward"] == pytest.approx(second["x"] - first["x"], abs=1e-12)
    env.close()


def test_a_forward_push_pays_and_a_backward_push_costs():
    """Push the base along +x with no motor effort: reward > 0; along -x: reward < 0."""
    rewards = {}
    for direction in (+1, -1):
        env = MinitaurEnv(randomize=False)
        env.reset(seed=0)
        env._last_position = np.array(env.robot.base_pose()[0])
        env.p.resetBaseVelocity(env.robot.body, [direction * 0.5, 0, 0], [0, 0, 0])
        _, rewards[direction], *_ = env.step(np.zeros(8))
        env.close()
    assert rewards[+1] > 0.001 and rewards[-1] < -0.001


def test_falling_over_terminates():
    env = MinitaurEnv(randomize=False)
    env.reset(seed=0)
    env.p.resetBasePositionAndOrientation(env.robot.body, [0, 0, 0.3],
                                          env.p.getQuaternionFromEuler([math.pi / 2, 0, 0]))
    _, _, terminated, truncated, _ = env.step(np.zeros(8))
    assert terminated and not truncated
    env.close()


def test_out_of_range_action_is_refused(env):
    env.reset(seed=0)
    with pytest.raises(ValueError, match="8 values in"):
        env.step(np.full(8, 1.5))


def test_leg_model_matches_pybullets_formula():
    rng = np.random.default_rng(0)
    action = rng.uniform(-1, 1, 8)
    got = leg_model_to_motor_angles(action)
    for i in range(8):  # written out as pybullet's ConvertFromLegModel loop
        swing = -math.pi / 4 * (action[i // 2 + 4] + 1.5)
        ext = (-1) ** i * math.pi / 4 * action[i // 2] * (-1 if i >= 4 else 1)
        assert got[i] == pytest.approx(math.pi + swing + ext)
    # zero action: every motor at pi - 1.5 pi/4
    np.testing.assert_allclose(leg_model_to_motor_angles(np.zeros(8)), math.pi - 1.5 * math.pi / 4)


def test_motor_model_saturates_and_opposes_motion():
    motor = MotorModel()
    actual, observed = motor.torques(np.array([1.0, 0.0]), np.array([0.0, 0.0]), np.array([0.0, 0.0]))
    # pwm = kp * 1 = 1 -> observed = 0.0954 * 16 / 0.186 clipped to 5.7; current 86 A -> table top 3.5
    assert observed[0] == pytest.approx(OBSERVED_TORQUE_LIMIT) and actual[0] == pytest.approx(3.5)
    assert actual[1] == 0 and observed[1] == 0
    # spinning at the speed limit with zero command: back-EMF drives the torque against the motion
    actual, _ = motor.torques(np.zeros(1), np.zeros(1), np.array([100.0]))
    assert actual[0] < 0


def test_rgb_array_render():
    env = make_env(render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8 and frame.std() > 5
    env.close()


def test_gymnasium_checker_passes():
    from gymnasium.utils.env_checker import check_env

    env = MinitaurEnv()
    check_env(env, skip_render_check=True)
    env.close()
    assert gym.spec(ENV_ID).entry_point is MinitaurEnv


def test_an_env_never_closed_exits_quietly():
    """A script that leaves its env open (a model card's snippet does) must not end in pybullet's
    BulletClient.__del__ traceback, which fires when the interpreter has already torn pybullet down."""
    import subprocess
    import sys

    script = ("from rlcore import api\n"  # with TensorFlow loaded, pybullet goes before the env at exit
              "env = api.load(('minitaur', 'sac')).make_env()\nenv.reset(seed=0)\nprint('played')\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "played" in done.stdout
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr
