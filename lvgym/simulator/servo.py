"""Gimbal servo: a second-order actuator per axis with position and rate limits.

``delta_ddot = w^2 (delta_c - delta) - 2 z w delta_dot`` with natural frequency ``w`` [rad/s] and
damping ``z``; the command is clipped to the position limit ``limit`` [rad], the rate to
``rate_limit`` [rad/s], the position to ``limit`` (and the rate is zeroed when the position saturates
against it). Integrated with semi-implicit Euler at the simulator's physics step (``w h = 0.15`` at
the defaults 15 rad/s and 10 ms). The simulator integrates it inside its compiled step
(:mod:`.advance`), so the gimbal moves between the RK4 steps of one control period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

# parameter vector of the compiled servo
S_ON, S_W, S_Z, S_LIMIT, S_RATE = 0, 1, 2, 3, 4
N_SERVO = 5


@dataclass(frozen=True)
class Servo:
    """Second-order gimbal servo: ``frequency`` [rad/s], ``damping`` [-], position ``limit`` [rad],
    ``rate_limit`` [rad/s]."""

    frequency: float = 15.0
    damping: float = 0.7
    limit: float = math.radians(5.0)
    rate_limit: float = math.radians(30.0)

    def __post_init__(self) -> None:
        for key, lo in (("frequency", 0.0), ("damping", 0.0), ("limit", 0.0), ("rate_limit", 0.0)):
            v = getattr(self, key)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > lo):
                raise ValueError(f"servo.{key} = {v!r}: a finite number > {lo:g}")

    def params(self) -> np.ndarray:
        """Parameter vector of the compiled servo (layout ``S_*``)."""
        return np.array([1.0, self.frequency, self.damping, self.limit, self.rate_limit])


#: no servo: the gimbal takes the commanded angle at once
DIRECT = np.zeros(N_SERVO)


@nb.njit(cache=True, nogil=True, inline="always")
def _clip(v, lo, hi):
    return min(max(v, lo), hi)


@nb.njit(cache=True, nogil=True, inline="always")
def servo_step_k(s, cmd, pos, rate, h):
    """Advance the two axes ``pos``, ``rate`` (2) in place by ``h`` [s] towards ``cmd`` (2) [rad]
    with servo parameters ``s`` (layout ``S_*``); with ``s[S_ON] == 0`` the position is the command
    and the rate is zero."""
    if s[S_ON] == 0.0:
        for i in range(2):
            pos[i] = cmd[i]
            rate[i] = 0.0
        return
    w, z, lim, rl = s[S_W], s[S_Z], s[S_LIMIT], s[S_RATE]
    for i in range(2):
        c = _clip(cmd[i], -lim, lim)
        acc = w * w * (c - pos[i]) - 2.0 * z * w * rate[i]
        r = _clip(rate[i] + h * acc, -rl, rl)
        p = pos[i] + h * r
        if abs(p) >= lim and (r > 0.0) == (p > 0.0) and r != 0.0:
            r = 0.0
        pos[i] = _clip(p, -lim, lim)
        rate[i] = r
