"""The Minitaur quadruped in a pybullet simulation: pose, motors, sensors and the leg model.

Follows pybullet's ``pybullet_envs/bullet/minitaur.py`` with the settings ``MinitaurBulletEnv-v0``
uses: the accurate motor model (kp 1.0, kd 0.02 on the PWM), overheat protection (a motor
above 2.45 N m for more than 1 s of simulated time is switched off), self-collision on, the
knees closed by point-to-point constraints, and actions in the leg model (swing and extension
of each leg) rather than raw motor angles.
"""
from __future__ import annotations

import math

import numpy as np

from minitaur.motor import MotorModel

INIT_POSITION = (0.0, 0.0, 0.2)
INIT_ORIENTATION = (0.0, 0.0, 0.0, 1.0)
LEGS = ("front_left", "back_left", "front_right", "back_right")
MOTOR_NAMES = tuple(f"motor_{leg}{side}_joint" for leg in LEGS for side in "LR")
MOTOR_DIRECTION = np.array([-1, -1, -1, -1, 1, 1, 1, 1], np.float64)
KNEE_ANGLE = -2.1834  # rad, the knees' resting angle
KNEE_POINT_RIGHT, KNEE_POINT_LEFT = (0.0, 0.005, 0.2), (0.0, 0.01, 0.2)
LEG_LINKS = (2, 3, 5, 6, 8, 9, 11, 12, 15, 16, 18, 19, 21, 22, 24, 25)
MOTOR_LINKS = (1, 4, 7, 10, 14, 17, 20, 23)
FOOT_LINKS = (3, 6, 9, 12, 16, 19, 22, 25)
OVERHEAT_TORQUE, OVERHEAT_SECONDS = 2.45, 1.0
NUM_MOTORS = 8


def leg_model_to_motor_angles(action: np.ndarray) -> np.ndarray:
    """Leg-model action in [-1, 1]^8 -> the 8 motor angles (pybullet's ``ConvertFromLegModel``).

    ``action[0:4]`` extend each leg, ``action[4:8]`` swing it forward or back; each leg's two
    motors move together for the swing and apart for the extension.
    """
    action = np.asarray(action, np.float64)
    angles = np.empty(NUM_MOTORS)
    for i in range(NUM_MOTORS):
        leg = i // 2
        swing = -math.pi / 4 * (action[leg + 4] + 1.5)
        extension = (-1) ** i * math.pi / 4 * action[leg]
        if i >= 4:
            extension = -extension
        angles[i] = math.pi + swing + extension
    return angles


class Minitaur:
    """One robot on a pybullet client, loaded fresh (the -v0 task hard-resets every episode)."""

    def __init__(self, client, urdf_root: str, time_step: float):
        self.p, self.time_step = client, time_step
        self.body = client.loadURDF(f"{urdf_root}/quadruped/minitaur.urdf", INIT_POSITION,
                                    flags=client.URDF_USE_SELF_COLLISION)
        joints = {client.getJointInfo(self.body, j)[1].decode(): j for j in range(client.getNumJoints(self.body))}
        self.motor_ids = [joints[name] for name in MOTOR_NAMES]
        self.base_mass = client.getDynamicsInfo(self.body, -1)[0]
        self.leg_masses = (client.getDynamicsInfo(self.body, LEG_LINKS[0])[0],
                           client.getDynamicsInfo(self.body, MOTOR_LINKS[0])[0])
        self.motor = MotorModel(kp=1.0, kd=0.02)
        for leg_index, leg in enumerate(LEGS):
            self._reset_leg(joints, leg_index, leg)
        self.observed_torques = np.zeros(NUM_MOTORS)
        self.overheat_counter = np.zeros(NUM_MOTORS)
        self.motor_enabled = np.ones(NUM_MOTORS, bool)

    def _reset_leg(self, joints: dict, leg_index: int, leg: str) -> None:
        p = self.p
        for k, side in enumerate("LR"):
            direction = MOTOR_DIRECTION[2 * leg_index + k]
            p.resetJointState(self.body, joints[f"motor_{leg}{side}_joint"], direction * math.pi / 2,
                              targetVelocity=0)
            p.resetJointState(self.body, joints[f"knee_{leg}{side}_link"], direction * KNEE_ANGLE,
                              targetVelocity=0)
        p.createConstraint(self.body, joints[f"knee_{leg}R_link"], self.body, joints[f"knee_{leg}L_link"],
                           p.JOINT_POINT2POINT, [0, 0, 0], KNEE_POINT_RIGHT, KNEE_POINT_LEFT)
        # free the motors and knees from pybullet's default velocity motors: torques drive them
        for name in (f"motor_{leg}L_joint", f"motor_{leg}R_joint", f"knee_{leg}L_link", f"knee_{leg}R_link"):
            p.setJointMotorControl2(self.body, joints[name], p.VELOCITY_CONTROL, targetVelocity=0, force=0)

    # ---------------------------------------------------------------- sensors
    def motor_states(self) -> tuple[np.ndarray, np.ndarray]:
        """(angles, velocities) of the 8 motors, signs flipped to the motor convention."""
        states = self.p.getJointStates(self.body, self.motor_ids)
        angles = np.array([s[0] for s in states]) * MOTOR_DIRECTION
        velocities = np.array([s[1] for s in states]) * MOTOR_DIRECTION
        return angles, velocities

    def base_pose(self) -> tuple[tuple, tuple]:
        return self.p.getBasePositionAndOrientation(self.body)

    def observation(self) -> np.ndarray:
        """8 motor angles, 8 motor velocities, 8 sensed torques, the base quaternion (x, y, z, w)."""
        angles, velocities = self.motor_states()
        return np.concatenate([angles, velocities, self.observed_torques, self.base_pose()[1]])

    # --------------------------------------------------------------- actuation
    def apply_motor_angles(self, desired: np.ndarray) -> None:
        """One simulation substep's worth of motor torques toward ``desired`` angles."""
        angles, velocities = self.motor_states()
        actual, observed = self.motor.torques(desired, angles, velocities)
        hot = np.abs(actual) > OVERHEAT_TORQUE
        self.overheat_counter = np.where(hot, self.overheat_counter + 1, 0)
        self.motor_enabled &= self.overheat_counter <= OVERHEAT_SECONDS / self.time_step
        self.observed_torques = observed
        applied = np.where(self.motor_enabled, actual * MOTOR_DIRECTION, 0.0)
        self.p.setJointMotorControlArray(self.body, self.motor_ids, self.p.TORQUE_CONTROL, forces=applied)

    # ---------------------------------------------------------- randomization
    def randomize(self, rng: np.random.Generator) -> None:
        """Per-episode physical variation of the -v0 task (pybullet's MinitaurEnvRandomizer):
        base and leg masses +-20 %, battery 14.8-16.8 V, motor damping 0-0.01, foot friction 0.8-1.5."""
        p = self.p
        p.changeDynamics(self.body, -1, mass=rng.uniform(0.8, 1.2) * self.base_mass)
        leg_mass, motor_mass = (rng.uniform(0.8, 1.2) * m for m in self.leg_masses)
        for link in LEG_LINKS:
            p.changeDynamics(self.body, link, mass=leg_mass)
        for link in MOTOR_LINKS:
            p.changeDynamics(self.body, link, mass=motor_mass)
        self.motor.voltage = rng.uniform(14.8, 16.8)
        self.motor.viscous_damping = rng.uniform(0.0, 0.01)
        friction = rng.uniform(0.8, 1.5)
        for link in FOOT_LINKS:
            p.changeDynamics(self.body, link, lateralFriction=friction)
