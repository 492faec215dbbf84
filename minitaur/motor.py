"""The Minitaur's DC motor model: a PD position command becomes a PWM duty cycle, then a torque.

Numbers from pybullet's Minitaur (``pybullet_envs/bullet/motor.py``): 16 V battery, 0.186 ohm
winding, torque constant 0.0954 N m / A, torque saturating along a measured current-torque table,
back-EMF opposing the command, a torque sensor that reads at most 5.7 N m.
"""
from __future__ import annotations

import numpy as np

VOLTAGE = 16.0  # V
RESISTANCE = 0.186  # ohm
TORQUE_CONSTANT = 0.0954  # N m / A
VISCOUS_DAMPING = 0.0  # N m s / rad
VOLTAGE_CLIP = 50.0  # V
OBSERVED_TORQUE_LIMIT = 5.7  # N m, what the sensor can report
SPEED_LIMIT = VOLTAGE / (VISCOUS_DAMPING + TORQUE_CONSTANT)  # rad/s: back-EMF equals the battery
CURRENT_TABLE = np.array([0.0, 10, 20, 30, 40, 50, 60])  # A
TORQUE_TABLE = np.array([0.0, 1, 1.9, 2.45, 3.0, 3.25, 3.5])  # N m


class MotorModel:
    """Position control through a simulated DC motor (kp, kd act on the PWM duty cycle)."""

    def __init__(self, kp: float = 1.0, kd: float = 0.02):
        self.kp, self.kd = kp, kd
        self.voltage, self.viscous_damping = VOLTAGE, VISCOUS_DAMPING

    def torques(self, desired_angles, angles, velocities) -> tuple[np.ndarray, np.ndarray]:
        """(torque applied to the joint, torque the sensor reports) for each motor."""
        pwm = np.clip(-self.kp * (angles - desired_angles) - self.kd * velocities, -1.0, 1.0)
        observed = np.clip(TORQUE_CONSTANT * pwm * self.voltage / RESISTANCE,
                           -OBSERVED_TORQUE_LIMIT, OBSERVED_TORQUE_LIMIT)
        back_emf = (TORQUE_CONSTANT + self.viscous_damping) * velocities
        current = np.clip(pwm * self.voltage - back_emf, -VOLTAGE_CLIP, VOLTAGE_CLIP) / RESISTANCE
        actual = np.sign(current) * np.interp(np.abs(current), CURRENT_TABLE, TORQUE_TABLE)
        return actual, observed
