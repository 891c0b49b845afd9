"""Gimbal actuator: a second-order servo per axis with position and rate limits, for a batch.

``delta_ddot = w^2 (delta_c - delta) - 2 z w delta_dot`` with natural frequency ``w`` [rad/s] and damping
``z``; the rate is clipped to ``rate_limit`` [rad/s] and the position to ``limit`` [rad] (the rate is
zeroed when the position saturates against it). Integrated with semi-implicit Euler at the physics step
(``w h = 0.15`` at the defaults 15 rad/s and 10 ms).
"""

from __future__ import annotations

import numpy as np


class Actuator:
    """B two-axis gimbal servos (pitch, yaw), angles in rad."""

    def __init__(self, batch: int, frequency: float = 15.0, damping: float = 0.7, limit: float = np.radians(5.0),
                 rate_limit: float = np.radians(30.0)) -> None:
        self.w, self.z, self.limit, self.rate_limit = float(frequency), float(damping), float(limit), float(rate_limit)
        self.position = np.zeros((batch, 2))
        self.rate = np.zeros((batch, 2))

    def reset(self, rows: np.ndarray) -> None:
        self.position[rows] = 0.0
        self.rate[rows] = 0.0

    def step(self, command: np.ndarray, h: float) -> np.ndarray:
        """Advance by ``h`` [s] towards ``command`` (B, 2) [rad] (clipped to the limit); returns the
        new position (a copy)."""
        c = np.clip(command, -self.limit, self.limit)
        acc = self.w**2 * (c - self.position) - 2.0 * self.z * self.w * self.rate
        self.rate = np.clip(self.rate + h * acc, -self.rate_limit, self.rate_limit)
        pos = self.position + h * self.rate
        hit = np.abs(pos) >= self.limit
        self.position = np.clip(pos, -self.limit, self.limit)
        self.rate = np.where(hit & (np.sign(self.rate) == np.sign(pos)), 0.0, self.rate)
        return self.position.copy()
