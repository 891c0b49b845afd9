"""Engine mass flow and thrust (thesis eq. 4.1), integrated exactly over time.

An engine either follows the thrust equation ``T = mdot Isp g0 + A_e (p_e - p_0)`` with
``mdot = throttle * mass_flow`` (``isp`` is the momentum-thrust specific impulse, exit velocity over
g0), or a thrust table ``T(tau)`` of the time since ignition, linear between rows and zero outside
them, measured at sea-level pressure (the ambient correction ``A_e (p_sl - p_0)`` is added when the
nozzle exit area is given); its mass flow is then ``mass_flow * T(tau) / T_mean`` with ``T_mean`` the
table's time-average, so ``mass_flow`` is the mean flow. Propellant consumed over an interval is the
exact integral of the flow (the thrust table is piecewise linear, so its integral is piecewise
quadratic), which makes tank-empty times exact event times.
"""

from __future__ import annotations

import numpy as np

from .definition import G0, Engine

#: sea-level pressure of a thrust table [Pa]
P_SEA_LEVEL = 101325.0


class EngineModel:
    """Flow and thrust of one :class:`~lvgym.vehicle.definition.Engine`.

    ``tau`` is the time since the engine's ignition [s]; ``throttle`` is clipped to the engine's range.
    """

    def __init__(self, engine: Engine):
        self.engine = engine
        table = engine.thrust_table
        if table is not None:
            t, T = table[:, 0], table[:, 1]
            self._t, self._T = t, T
            self._cum = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (T[1:] + T[:-1]))])
            self._T_mean = self._cum[-1] / (t[-1] - t[0])
            if self._T_mean <= 0.0:
                raise ValueError(f"{engine.key}.thrust_table: the table has no impulse")

    @property
    def burn_end(self) -> float:
        """Time since ignition at which the thrust table ends [s] (inf for the thrust equation)."""
        return float(self._t[-1]) if self.engine.thrust_table is not None else np.inf

    def throttle(self, throttle: float) -> float:
        lo, hi = self.engine.throttle
        return float(min(max(throttle, lo), hi))

    def table_thrust(self, tau):
        """Tabulated thrust at ``tau`` [N] (a float or an array), zero outside the table."""
        tau = np.asarray(tau, dtype=float)
        return np.where((tau < self._t[0]) | (tau > self._t[-1]), 0.0, np.interp(tau, self._t, self._T))[()]

    def _impulse(self, tau):
        """``int_{t_0}^{tau} T dt`` of the table [N s] (``tau`` a float or an array)."""
        t, T = self._t, self._T
        tau = np.asarray(tau, dtype=float)
        k = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, t.size - 2)
        with np.errstate(divide="ignore", invalid="ignore"):          # rows outside the table: not used
            T_tau = T[k] + (T[k + 1] - T[k]) * (tau - t[k]) / (t[k + 1] - t[k])
            inside = self._cum[k] + 0.5 * (tau - t[k]) * (T[k] + T_tau)
        return np.where(tau <= t[0], 0.0, np.where(tau >= t[-1], self._cum[-1], inside))[()]

    def mass_flow(self, tau, throttle: float = 1.0):
        """Total propellant mass flow at ``tau`` [kg/s] (>= 0; ``tau`` a float or an array)."""
        e = self.engine
        if e.thrust_table is None:
            return (self.throttle(throttle) * e.mass_flow + np.zeros(np.shape(tau)))[()]
        return e.mass_flow * self.table_thrust(tau) / self._T_mean

    def consumed(self, tau0, tau1, throttle: float = 1.0):
        """Propellant used between ``tau0`` and ``tau1`` [kg], exactly (floats or arrays)."""
        e = self.engine
        if e.thrust_table is None:
            return self.throttle(throttle) * e.mass_flow * np.maximum(np.subtract(tau1, tau0), 0.0)
        return e.mass_flow * (self._impulse(tau1) - self._impulse(tau0)) / self._T_mean

    def time_to_consume(self, tau0: float, mass: float, throttle: float = 1.0) -> float:
        """Time after ``tau0`` at which ``mass`` [kg] has been used [s] (inf if never)."""
        if mass <= 0.0:
            return 0.0
        e = self.engine
        if e.thrust_table is None:
            rate = self.throttle(throttle) * e.mass_flow
            return mass / rate if rate > 0.0 else np.inf
        if self.consumed(tau0, self.burn_end) < mass:
            return np.inf
        from scipy.optimize import brentq       # imported here: scipy.optimize takes 0.5 s to import

        return brentq(lambda tau: self.consumed(tau0, tau) - mass, tau0, self.burn_end, xtol=1e-12) - tau0

    def thrust(self, tau, throttle: float = 1.0, p_ambient=0.0):
        """Thrust magnitude [N] at ``tau`` and ambient pressure ``p_ambient`` [Pa], never negative
        (floats or arrays)."""
        e = self.engine
        if e.thrust_table is None:
            mdot = self.mass_flow(tau, throttle)
            T = mdot * e.isp * G0 + e.nozzle_exit_area * (e.nozzle_exit_pressure - np.asarray(p_ambient, dtype=float))
            return np.where(mdot <= 0.0, 0.0, np.maximum(T, 0.0))[()]
        T = self.table_thrust(tau)
        with_p = T + e.nozzle_exit_area * (P_SEA_LEVEL - np.asarray(p_ambient, dtype=float))
        return np.where(T <= 0.0, 0.0, np.maximum(with_p, 0.0))[()]
