"""Gimbal servo: a second-order actuator per axis with position and rate limits.

``delta_ddot = w^2 (delta_c - delta) - 2 z w delta_dot`` with natural frequency ``w`` [rad/s] and
damping ``z``; the command is clipped to the position limit ``limit`` [rad], the rate to
``rate_limit`` [rad/s], the position to ``limit`` (and the rate is zeroed when the position saturates
against it). Integrated with semi-implicit Euler at the simulator's physics step (``w h = 0.15`` at
the defaults 15 rad/s and 10 ms). The simulator integrates it inside its compiled step
(:mod:`.advance`), so the gimbal moves between the RK4 steps of one control period. The parameters
have the layout :data:`.layouts.SERVO`, a row's command and servo state :data:`.layouts.ACTUATOR`.

Actuator faults, per row and axis (the row's ``ACTUATOR`` fields, zero nominal; set by the env's fault draws):
``effectiveness_loss`` ``l``: the servo drives towards ``(1 - l)`` times the (clipped) command;
``bandwidth_loss`` ``b``: its natural frequency is ``(1 - b) w``; ``stuck``: the gimbal holds its angle, rate
zero. Without a servo the gimbal takes ``(1 - l)`` times the command, or holds when stuck.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from .layouts import SERVO, SV, A


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
        """Parameter vector of the compiled servo (layout :data:`.layouts.SERVO`)."""
        return SERVO.pack({"on": 1.0, "frequency": self.frequency, "damping": self.damping, "limit": self.limit,
                           "rate_limit": self.rate_limit})


#: no servo: the gimbal takes the commanded angle at once
DIRECT = SERVO.zeros()


@nb.njit(cache=True, nogil=True, inline="always")
def _clip(v, lo, hi):
    return min(max(v, lo), hi)


@nb.njit(cache=True, nogil=True, inline="always")
def servo_step_k(s, act, h, k):
    """Advance the two axes of the actuator row ``act`` (layout ``ACTUATOR``: gimbal and gimbal rate)
    in place by ``h`` [s], physics step ``k`` of a control period, towards its command [rad] (the previous
    period's while ``k`` is below the row's ``delay``) with servo parameters ``s`` (layout ``SERVO``; the
    natural frequency times ``1 + frequency_shift`` of the row); with ``s[SV.on] == 0`` the gimbal is the
    command and the rate is zero."""
    o = A.previous if k < act[A.delay] else A.command
    if s[SV.on] == 0.0:
        for i in range(2):
            act[A.gimbal_rate + i] = 0.0
            if act[A.stuck + i] == 0.0:
                act[A.gimbal + i] = act[o + i] * (1.0 - act[A.effectiveness_loss + i])
        return
    w0, z, lim, rl = s[SV.frequency], s[SV.damping], s[SV.limit], s[SV.rate_limit]
    if act[A.frequency_shift] != 0.0:
        w0 = w0 * (1.0 + act[A.frequency_shift])
    for i in range(2):
        if act[A.stuck + i] != 0.0:                     # a jammed axis holds its angle
            act[A.gimbal_rate + i] = 0.0
            continue
        c = _clip(act[o + i], -lim, lim)
        if act[A.effectiveness_loss + i] != 0.0:
            c = c * (1.0 - act[A.effectiveness_loss + i])
        w = w0
        if act[A.bandwidth_loss + i] != 0.0:
            w = w0 * (1.0 - act[A.bandwidth_loss + i])
        pos, rate = act[A.gimbal + i], act[A.gimbal_rate + i]
        acc = w * w * (c - pos) - 2.0 * z * w * rate
        r = _clip(rate + h * acc, -rl, rl)
        p = pos + h * r
        if abs(p) >= lim and (r > 0.0) == (p > 0.0) and r != 0.0:
            r = 0.0
        act[A.gimbal + i] = _clip(p, -lim, lim)
        act[A.gimbal_rate + i] = r
