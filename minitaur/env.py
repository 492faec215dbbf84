"""Our Gymnasium version of pybullet's ``MinitaurBulletEnv-v0`` task (no dependency on ``gym``).

What we matched, read from pybullet 3.2.7's ``pybullet_envs/bullet/minitaur_gym_env.py`` with the
defaults the ``-v0`` registration uses:

* Simulation: 0.01 s control step split into 5 substeps of 0.002 s (60 solver iterations each);
  the motor model recomputes torques every substep; gravity -10; a hard reset every episode
  (fresh world, plane, robot), then 100 substeps holding every motor at pi/2 to settle.
* Observation (28): 8 motor angles, 8 motor velocities, 8 sensed torques, base quaternion; bounds
  +-(pi, 167.7 rad/s, 5.7 N m, 1) widened by 0.01. No observation noise.
* Action (8) in [-1, 1]: the leg model (extension and swing per leg) mapped to motor angles.
* Reward: forward (x) progress of the base minus 0.005 x |torque . velocity| x 0.002 s; drift and
  shake weights are 0 in -v0, so those terms are left out.
* Episode: 1000 steps (TimeLimit); terminated when the robot falls: its up axis tilts below
  0.85 of vertical or the base drops under 0.13 m. Reward threshold 15 (the registered one).
* Motor model on, overheat protection on, self-collision on, and the env randomizer on: masses,
  battery voltage, motor damping and foot friction vary per episode, drawn from the env's seeded
  ``np_random`` (pybullet drew them from the unseeded global RNGs), so a seed fixes a trajectory.

Rendering (``rgb_array``) uses pybullet's CPU TinyRenderer, following the base with the original
camera (distance 1 m, yaw 0, pitch -30).
"""
from __future__ import annotations

import os
import weakref

import gymnasium as gym
import numpy as np

from minitaur.motor import OBSERVED_TORQUE_LIMIT, SPEED_LIMIT
from minitaur.robot import NUM_MOTORS, Minitaur, leg_model_to_motor_angles
from rlcore.host.quiet import filtered_stderr

ENV_ID = "deeprl/Minitaur-v0"
CONTROL_STEP = 0.01
SUBSTEPS = 5
SUBSTEP = CONTROL_STEP / SUBSTEPS
SOLVER_ITERATIONS = 300 // SUBSTEPS
SETTLE_SUBSTEPS = 100
DISTANCE_WEIGHT, ENERGY_WEIGHT = 1.0, 0.005
FALL_UP_DOT, FALL_HEIGHT = 0.85, 0.13
OBSERVATION_EPS, ACTION_EPS = 0.01, 0.01


def observation_bound() -> np.ndarray:
    return np.concatenate([np.full(NUM_MOTORS, np.pi), np.full(NUM_MOTORS, SPEED_LIMIT),
                           np.full(NUM_MOTORS, OBSERVED_TORQUE_LIMIT), np.ones(4)]) + OBSERVATION_EPS


class MinitaurEnv(gym.Env):
    """The Minitaur walking task: go forward (+x) fast without wasting energy or falling."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 100}

    def __init__(self, render_mode: str | None = None, randomize: bool = True,
                 render_size: tuple[int, int] = (320, 240)):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode {render_mode!r} is not supported; use 'rgb_array' or None")
        # pybullet prints its build time on import and "argv[0]=" on every connect
        from rlcore.host.extras import require

        with filtered_stderr():
            pybullet = require("pybullet", "Minitaur")  # the minitaur extra, or one line saying so
            import pybullet_data
            from pybullet_utils import bullet_client

            self.p = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        # disconnect while pybullet is still importable: an env never closed by hand is otherwise left to
        # BulletClient.__del__ at interpreter exit, which prints a TypeError traceback (pybullet gone)
        self._disconnect = weakref.finalize(self, _disconnect, self.p)
        self.render_mode, self.randomize, self.render_size = render_mode, randomize, render_size
        self._pybullet = pybullet
        self._urdf_root = pybullet_data.getDataPath()
        high = observation_bound().astype(np.float32)
        self.observation_space = gym.spaces.Box(-high, high, dtype=np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (NUM_MOTORS,), np.float32)
        self.robot: Minitaur | None = None

    # --------------------------------------------------------------- episodes
    def reset(self, *, seed: int | None = None, options=None):
        super().reset(seed=seed)
        p = self.p
        p.resetSimulation()
        p.setPhysicsEngineParameter(numSolverIterations=SOLVER_ITERATIONS)
        p.setTimeStep(SUBSTEP)
        plane = p.loadURDF(f"{self._urdf_root}/plane.urdf")
        p.changeVisualShape(plane, -1, rgbaColor=[1, 1, 1, 0.9])
        p.setGravity(0, 0, -10)
        self.robot = Minitaur(p, self._urdf_root, SUBSTEP)
        if self.randomize:
            self.robot.randomize(self.np_random)
        settle = np.full(NUM_MOTORS, np.pi / 2)
        for _ in range(SETTLE_SUBSTEPS):
            self.robot.apply_motor_angles(settle)
            p.stepSimulation()
        self._last_position = np.zeros(3)  # as pybullet: the first step's progress counts from 0
        self.steps = 0
        return self._observation(), {}

    def step(self, action):
        action = np.asarray(action, np.float64)
        if action.shape != (NUM_MOTORS,) or not np.all(np.abs(action) <= 1.0 + ACTION_EPS):
            raise ValueError(f"action must be 8 values in [-1, 1], got {np.round(action, 3)}")
        desired = leg_model_to_motor_angles(action)
        for _ in range(SUBSTEPS):
            self.robot.apply_motor_angles(desired)
            self.p.stepSimulation()
        self.steps += 1
        position, orientation = self.robot.base_pose()
        position = np.asarray(position)
        forward = position[0] - self._last_position[0]
        self._last_position = position
        _, velocities = self.robot.motor_states()
        energy = abs(float(np.dot(self.robot.observed_torques, velocities))) * SUBSTEP
        reward = DISTANCE_WEIGHT * forward - ENERGY_WEIGHT * energy
        terminated = self._fallen(position, orientation)
        info = {"x": float(position[0]), "forward": float(forward), "energy": energy}
        return self._observation(), float(reward), terminated, False, info

    def _fallen(self, position, orientation) -> bool:
        up_z = self.p.getMatrixFromQuaternion(orientation)[8]  # z of the base's up axis
        return bool(up_z < FALL_UP_DOT or position[2] < FALL_HEIGHT)

    def _observation(self) -> np.ndarray:
        return self.robot.observation().astype(np.float32)

    # -------------------------------------------------------------- rendering
    def render(self):
        if self.render_mode != "rgb_array":
            return None
        width, height = self.render_size
        view = self.p.computeViewMatrixFromYawPitchRoll(
            cameraTargetPosition=self.robot.base_pose()[0], distance=1.0, yaw=0, pitch=-30, roll=0,
            upAxisIndex=2)
        projection = self.p.computeProjectionMatrixFOV(fov=60, aspect=width / height, nearVal=0.1,
                                                       farVal=100.0)
        _, _, pixels, _, _ = self.p.getCameraImage(width, height, viewMatrix=view, projectionMatrix=projection,
                                                   renderer=self._pybullet.ER_TINY_RENDERER)
        return np.asarray(pixels, np.uint8).reshape(height, width, 4)[:, :, :3]

    def close(self):
        if getattr(self, "p", None) is not None:
            self._disconnect()
            self.p = None


def _disconnect(client) -> None:
    """Disconnect ``client`` once, in the process that connected it (as its ``__del__`` checks); its
    ``__del__`` then has nothing left to do."""
    if client._client < 0 or client._pid != os.getpid():
        return
    try:
        client.disconnect()
    except Exception:  # already disconnected
        pass
    client._client = -1


def register() -> None:
    if ENV_ID not in gym.registry:
        gym.register(ENV_ID, entry_point=MinitaurEnv, max_episode_steps=1000, reward_threshold=15.0)


def make_env(render_mode: str | None = None, max_episode_steps: int | None = None) -> gym.Env:
    """``deeprl/Minitaur-v0`` with its 1000-step limit unless ``max_episode_steps`` is given."""
    register()
    return gym.make(ENV_ID, render_mode=render_mode, max_episode_steps=max_episode_steps,
                    disable_env_checker=True)
