"""The next stage's ignition as a flight computer sees it, and the disturbance it can measure there from the
rigid body while a learned observer's window still holds the staging coast (:mod:`lvgym.agents.policies.inversion`).

SMILE's first stage burns out at about 43 s; the gimbal is held at zero through a coast of about ten seconds
(the observation's ``controller_on`` is 0) and the next stage ignites at about 54 s. Its first seconds are
where the fault suite's learned observer lost its flights (docs/training-results.md, "The next stage's
ignition"): its window has seen no thrust, the aerodynamic moment of an unstable vehicle at the end of the
coast is large beside the new stage's control moment, and an estimate 40 % short lets the attitude diverge.

- :class:`Ignition`: per row, the control steps since the controller came back after a coast.
- :class:`Measured`: the moment the law cancels, ``f_aero + f_mis`` in gimbal limits, from the rigid body's
  pitch and yaw equations: ``a omega_dot = delta + f_aero + f_mis`` (``a``: the gimbal angle per rad/s^2 of
  angular acceleration, ``delta``: the gimbal's position, both over the gimbal limit), so
  ``f_aero + f_mis = a omega_dot - delta`` with ``omega_dot`` the gyro rates' slope over the last
  :data:`SPAN` control steps and ``delta`` the observed gimbal position averaged over the same steps (a
  disturbance observer; its ``a`` is the learned observer's estimate). Over the coast its steps hold the
  aerodynamic moment alone, which the new stage meets at once. The law on it is an incremental dynamic
  inversion, ``delta = delta_mean + a (alpha - omega_dot)`` (INDI; Sieberling, Chu and Mulder, J. Guid.
  Control Dyn. 33(6), 2010): its increment loop feeds ``1 - a / a_true`` of the gimbal position back, so it
  needs the estimated ``a`` under twice the true one, and less behind the servo's lag; a gain ``k`` between
  the command and the servo that the observer reads into its ``a`` (``a_true / k``) feeds back ``k - 1``.
  Flying a share of the measured moment (:class:`lvgym.agents.policies.inversion.Staging`) scales that loop's gain by
  it (docs/training-results.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lvgym.errors import ConfigError

__all__ = ["GIMBAL", "RATES", "SPAN", "Ignition", "Measured", "signal_index"]

#: the observation's gyro entries (the pitch rate is its error plus the reference) and gimbal positions
RATES = ("pitch_rate_error", "yaw_rate_error", "pitch_rate_reference")
GIMBAL = ("gimbal_pitch", "gimbal_yaw")
#: the control steps the measured angular acceleration spans (0.06 s at 0.02 s)
SPAN = 3


def signal_index(env: Any, names: tuple[str, ...], what: str = "") -> list[int]:
    """Where ``names`` sit in ``env``'s observation (its layout's offsets; refused by name where one is
    missing, ``what`` saying what needs them)."""
    layout = env.unwrapped.func.observation_layout
    missing = [n for n in names if n not in layout]
    if missing:
        raise ConfigError("env observation", f"without {missing}",
                          f"an observation with {list(names)}" + (f" ({what})" if what else ""))
    return [layout.index(n) for n in names]


class Ignition:
    """Per row of ``n``, the control steps since the next stage's ignition: the observation's ``controller_on``
    (at index ``on``) back to 1 after it fell to 0 once the controller had acted (the staging coast); -1
    before (a flight without a coast: throughout)."""

    def __init__(self, n: int, on: int) -> None:
        self.on = on
        self.acted = np.zeros(n, dtype=bool)          # the controller has acted
        self.coast = np.zeros(n, dtype=bool)          # ... and stopped since
        self.since = np.full(n, -1, dtype=np.int64)

    def push(self, rows: np.ndarray, observations: np.ndarray) -> np.ndarray:
        """The step's observations of ``rows`` in; their steps since ignition (0: the first step it acts again)."""
        now = np.asarray(observations)[:, self.on] > 0.5
        lit = self.since[rows] >= 0
        self.since[rows] = np.where(lit, self.since[rows] + 1, np.where(self.coast[rows] & now, 0, -1))
        self.coast[rows] |= self.acted[rows] & ~now
        self.acted[rows] |= now
        return self.since[rows].copy()

    def reset(self, rows: np.ndarray) -> None:
        """Forget the flights of ``rows``."""
        self.acted[rows] = self.coast[rows] = False
        self.since[rows] = -1


class Measured:
    """The moment the law cancels, measured (module docstring), for ``n`` rows: the last :data:`SPAN` + 1
    steps' gyro pitch and yaw rates [rad/s] and gimbal positions [gimbal limits] from the observation
    (``rates``: the indices of :data:`RATES`, ``gimbal``: of :data:`GIMBAL`; ``dt``: the control period [s]);
    zeros before the first step."""

    def __init__(self, n: int, rates: list[int], gimbal: list[int], dt: float, span: int = SPAN) -> None:
        if span < 1 or not dt > 0.0:
            raise ConfigError("measured disturbance", {"span": span, "dt": dt}, "span >= 1 step and dt > 0 s")
        self.rates, self.gimbal, self.dt, self.span = rates, gimbal, float(dt), int(span)
        self.omega = np.zeros((n, span + 1, 2))
        self.delta = np.zeros((n, span + 1, 2))

    def push(self, rows: np.ndarray, observations: np.ndarray) -> None:
        """Add the step's observations of ``rows``."""
        o = np.asarray(observations, dtype=np.float64)
        self.omega[rows, :-1] = self.omega[rows, 1:]
        self.omega[rows, -1] = o[:, self.rates[:2]] + np.c_[o[:, self.rates[2]], np.zeros(len(o))]
        self.delta[rows, :-1] = self.delta[rows, 1:]
        self.delta[rows, -1] = o[:, self.gimbal]

    def moment(self, rows: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``(len(rows), 2)``: ``f_aero + f_mis`` [gimbal limits] of ``rows`` given their ``a`` ``(len(rows), 2)``
        [gimbal limits per rad/s^2]."""
        omega_dot = (self.omega[rows, -1] - self.omega[rows, 0]) / (self.span * self.dt)
        return np.asarray(a, dtype=np.float64) * omega_dot - self.delta[rows].mean(axis=1)

    def reset(self, rows: np.ndarray) -> None:
        """Forget the flights of ``rows``."""
        self.omega[rows] = 0.0
        self.delta[rows] = 0.0
