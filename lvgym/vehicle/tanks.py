"""Liquid tanks and hybrid grains: mass, CG, inertia and the slosh pendulum (thesis 2.3, 4.1).

The equivalent mechanical model of the first lateral slosh mode of a cylindrical tank of radius R and
liquid height h (Abramson, NASA SP-106; thesis eq. 2.23-2.29 with the radius, physics note 1):

- ``kappa = xi h / R`` with ``xi = 1.84119``, the first root of ``J1'``;
- slosh mass ``m_s = m_liq 2 tanh(kappa) / ((xi^2 - 1) kappa)``;
- pendulum length ``L = R / (xi tanh kappa)`` (so ``omega^2 = a / L``), capped at the liquid height
  (thesis 4.1.2, physics note 4);
- the slosh mass sits ``h/2 - (2R/xi) tanh(kappa/2)`` above the liquid's CG, the hinge one pendulum
  length above the slosh mass;
- the fixed mass ``m_f = m_liq - m_s`` is a solid cylinder of the liquid's radius and height with the
  slip factor on its roll inertia (eq. 4.3-4.4). By default it sits where fixed and slosh mass at rest
  together keep the liquid's static CG (physics note 2, Abramson); ``cg_convention="thesis"`` puts it
  at the liquid centroid as the thesis did (which moves the vehicle's CG).

Below :data:`MIN_SLOSH_HEIGHT` of liquid the tank has no slosh degree of freedom: its pendulum is
inactive (mass 0) and the liquid is all fixed mass (physics note 4; docs/physics-notes.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .definition import Grain, Tank

#: first root of the derivative of the Bessel function J1 [-]
XI = 1.84119
#: liquid height below which a tank has no slosh degree of freedom [m]; the capped pendulum (L <= h)
#: of a 1 mm film under 10 g swings at 310 rad/s, still resolved by RK4 at 1 ms
MIN_SLOSH_HEIGHT = 1e-3
CG_CONVENTIONS = ("static", "thesis")


@dataclass(frozen=True)
class TankProperties:
    """Mass properties of one tank's liquid at one instant, or at B instants (every field then carries a
    leading axis of B, see :func:`tank_properties`). Stations in metres from the nose tip.

    ``liquid_mass`` [kg], ``height`` of the liquid [m], ``liquid_cg`` station [m];
    ``slosh_mass`` [kg] (0: no pendulum), ``pendulum_length`` [m] (capped at the height),
    ``pendulum_length_roberts`` [m] (uncapped ``R / (xi tanh kappa)``), ``slosh_station`` [m] (rest
    position of the slosh mass), ``hinge_station`` [m]; ``fixed_mass`` [kg], ``fixed_cg`` station [m],
    ``fixed_inertia`` about the fixed mass's CG, body axes [kg m^2] (3, 3)."""

    liquid_mass: float
    height: float
    liquid_cg: float
    slosh_mass: float
    pendulum_length: float
    pendulum_length_roberts: float
    slosh_station: float
    hinge_station: float
    fixed_mass: float
    fixed_cg: float
    fixed_inertia: np.ndarray

    def row(self, i: int) -> TankProperties:
        """Instant ``i`` of a batch (floats and a (3, 3) inertia)."""
        g = self.__getattribute__
        return TankProperties(*(float(g(name)[i]) for name in _TANK_FLOATS), self.fixed_inertia[i].copy())


#: the fields of :class:`TankProperties` before ``fixed_inertia``, in order (floats of one instant)
_TANK_FLOATS = ("liquid_mass", "height", "liquid_cg", "slosh_mass", "pendulum_length", "pendulum_length_roberts",
                "slosh_station", "hinge_station", "fixed_mass", "fixed_cg")


def slosh_fraction(kappa):
    """``m_s / m_liq = 2 tanh(kappa) / ((xi^2 - 1) kappa)`` [-], with its limit 2 / (xi^2 - 1) at 0
    (``kappa`` a float or an array)."""
    k = np.asarray(kappa, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(k < 1e-8, 2.0 / (XI**2 - 1.0), 2.0 * np.tanh(k) / ((XI**2 - 1.0) * k))
    return out[()]


def tank_properties(tank: Tank, liquid_mass, cg_convention: str = "static") -> TankProperties:
    """Mass properties of ``tank`` holding ``liquid_mass`` [kg] (thesis eq. 2.23-2.29, 4.3-4.4): a float
    gives floats and a (3, 3) inertia, an array (B,) of masses the same fields with a leading axis B."""
    if cg_convention not in CG_CONVENTIONS:
        raise ValueError(f"cg_convention = {cg_convention!r}: one of {CG_CONVENTIONS}")
    single = np.ndim(liquid_mass) == 0
    R = tank.inner_radius
    m = np.maximum(np.atleast_1d(np.asarray(liquid_mass, dtype=float)), 0.0)
    h = m / (np.pi * R**2 * tank.density)
    x_liq = tank.bottom + 0.5 * h
    live = (h >= MIN_SLOSH_HEIGHT) & tank.slosh         # a pendulum (else none: all the liquid is fixed)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = XI * h / R
        m_s = np.where(live, m * slosh_fraction(kappa), 0.0)
        L_rob = np.where(live, R / (XI * np.tanh(kappa)), 0.0)
        L = np.where(live, np.minimum(L_rob, h), 0.0)
        x_s = np.where(live, x_liq + 0.5 * h - (2.0 * R / XI) * np.tanh(0.5 * kappa), x_liq)
        x_h = np.where(live, x_s + L, x_liq)
        m_f = m - m_s
        static = (m * x_liq - m_s * x_s) / m_f if cg_convention == "static" else x_liq
        x_f = np.where(m_f <= 0.0, x_liq, static)
    J_f = np.zeros((m.size, 3, 3))
    J_f[:, 0, 0] = 0.5 * m_f * R**2 * (1.0 - tank.slip_factor)
    J_f[:, 1, 1] = J_f[:, 2, 2] = m_f * (3.0 * R**2 + h**2) / 12.0
    tp = TankProperties(liquid_mass=m, height=h, liquid_cg=x_liq, slosh_mass=m_s, pendulum_length=L,
                        pendulum_length_roberts=L_rob, slosh_station=x_s, hinge_station=x_h,
                        fixed_mass=m_f, fixed_cg=x_f, fixed_inertia=J_f)
    return tp.row(0) if single else tp


def grain_properties(grain: Grain, mass) -> tuple:
    """Mass [kg], CG station [m] and inertia about its CG [kg m^2] (3, 3) of a hybrid fuel grain of
    ``mass`` [kg]: a thick-walled cylinder burnt uniformly from the port, so the port radius is
    ``sqrt(Ro^2 - m / (rho pi L))``. An array (B,) of masses gives masses (B,) and inertias (B, 3, 3)."""
    m = np.minimum(np.maximum(np.asarray(mass, dtype=float), 0.0), grain.capacity)
    Ro, Lg = grain.outer_radius, grain.length
    r_port2 = np.maximum(Ro**2 - m / (grain.density * np.pi * Lg), 0.0)
    J = np.zeros(m.shape + (3, 3))
    J[..., 0, 0] = 0.5 * m * (Ro**2 + r_port2)
    J[..., 1, 1] = J[..., 2, 2] = m * (3.0 * (Ro**2 + r_port2) + Lg**2) / 12.0
    return m[()], grain.top - 0.5 * Lg, J
