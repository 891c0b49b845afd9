"""Bang-bang roll-rate control with reaction-control pulses (thesis 5.2-5.3, Stratos III/IV).

``lvgym/StratosIII-v0`` (``control="rcs"``) takes ``MultiDiscrete([3])`` actions: 0 a negative roll
torque, 1 none, 2 a positive one. The law fires against the roll rate (``roll_rate``, rad/s) when its size
exceeds the deadband, with a hysteresis: once firing, it keeps firing until the rate is back inside
``release_fraction`` of the deadband (fewer pulses than a plain relay chattering on the deadband edge).
It is off while the env's controller-on flag (``controller_on``) is 0. The entries are read by name from
the observation layout (:data:`lvgym.envs.layouts.OBSERVATIONS`; both modes have them at the same index).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lvgym.envs.layouts import OBS_STATE

NEGATIVE, NONE, POSITIVE = 0, 1, 2
_ROLL, _ON = OBS_STATE.index("roll_rate"), OBS_STATE.index("controller_on")


class BangBangRollPolicy:
    """Roll bang-bang with deadband ``deadband_degps`` [deg/s] and hysteresis (see the module docstring)."""

    def __init__(self, deadband_degps: float = 1.0, release_fraction: float = 0.25, name: str = "bang-bang") -> None:
        if not deadband_degps >= 0.0:
            raise ValueError(f"deadband_degps = {deadband_degps!r}: >= 0 deg/s")
        if not 0.0 <= release_fraction <= 1.0:
            raise ValueError(f"release_fraction = {release_fraction!r}: in [0, 1]")
        self.name = name
        self.deadband = math.radians(deadband_degps)
        self.release = release_fraction * self.deadband
        self.firing = NONE

    def reset(self) -> None:
        self.firing = NONE

    def command(self, roll_rate: float, on: bool = True) -> int:
        """The pulse for a roll rate [rad/s]."""
        if not on:
            self.firing = NONE
        elif roll_rate > self.deadband:
            self.firing = NEGATIVE
        elif roll_rate < -self.deadband:
            self.firing = POSITIVE
        elif abs(roll_rate) <= self.release or (self.firing == NEGATIVE and roll_rate < 0) or (
                self.firing == POSITIVE and roll_rate > 0):
            self.firing = NONE
        return self.firing

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        return np.array([self.command(float(obs[_ROLL]), float(obs[_ON]) >= 0.5)], dtype=np.int64)
