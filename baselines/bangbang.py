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
from collections.abc import Mapping
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.envs.layouts import OBS_STATE
from lvgym.errors import ConfigError

NEGATIVE, NONE, POSITIVE = 0, 1, 2
_ROLL, _ON = OBS_STATE.index("roll_rate"), OBS_STATE.index("controller_on")


class BangBangLaw(BatchLaw):
    """Roll bang-bang with deadband ``deadband_degps`` [deg/s] and hysteresis (see the module docstring) for
    ``n`` rows; :attr:`firing` (n,) each row's pulse."""

    def __init__(self, deadband_degps: float = 1.0, release_fraction: float = 0.25, name: str = "bang-bang",
                 n: int = 1) -> None:
        if not deadband_degps >= 0.0:
            raise ConfigError("bang-bang deadband_degps", deadband_degps, ">= 0 deg/s")
        if not 0.0 <= release_fraction <= 1.0:
            raise ConfigError("bang-bang release_fraction", release_fraction, "in [0, 1]")
        self.name = name
        self.deadband = math.radians(deadband_degps)
        self.release = release_fraction * self.deadband
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.firing = np.full(n, NONE, dtype=np.int64)

    def reset(self, rows: Any) -> None:
        self.firing[np.asarray(rows, dtype=np.int64).reshape(-1)] = NONE

    def command(self, rows: Any, roll_rate: np.ndarray, on: np.ndarray) -> np.ndarray:
        """The pulses of the rows ``rows`` for their roll rates [rad/s], the law on where ``on``."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        w, f = np.asarray(roll_rate, dtype=float).reshape(-1), self.firing[rows]
        held = (f == NEGATIVE) & (w < 0) | (f == POSITIVE) & (w > 0)
        stop = (np.abs(w) <= self.release) | held
        f = np.where(w > self.deadband, NEGATIVE, np.where(w < -self.deadband, POSITIVE, np.where(stop, NONE, f)))
        f = np.where(np.asarray(on, dtype=bool).reshape(-1), f, NONE)
        self.firing[rows] = f
        return f

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        obs = np.asarray(observations, dtype=float)
        return self.command(rows, obs[:, _ROLL], obs[:, _ON] >= 0.5)[:, None].astype(np.int64)


class BangBangRollPolicy(RowFace):
    """:class:`BangBangLaw` for one row (its arguments)."""

    def __init__(self, deadband_degps: float = 1.0, release_fraction: float = 0.25, name: str = "bang-bang") -> None:
        self.law = BangBangLaw(deadband_degps, release_fraction, name)
