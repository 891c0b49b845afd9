"""Liquid tanks and hybrid grains: mass, CG, inertia and the slosh pendulum (thesis 2.3, 4.1).

The equivalent mechanical model of the first lateral slosh mode of a cylindrical tank of radius R and
liquid height h (Abramson, NASA SP-106; thesis eq. 2.23-2.29 with the radius, DESIGN.md note 1):

- ``kappa = xi h / R`` with ``xi = 1.84119``, the first root of ``J1'``;
- slosh mass ``m_s = m_liq 2 tanh(kappa) / ((xi^2 - 1) kappa)``;
- pendulum length ``L = R / (xi tanh kappa)`` (so ``omega^2 = a / L``), capped at the liquid height
  (thesis 4.1.2, DESIGN.md note 4);
- the slosh mass sits ``h/2 - (2R/xi) tanh(kappa/2)`` above the liquid's CG, the hinge one pendulum
  length above the slosh mass;
- the fixed mass ``m_f = m_liq - m_s`` is a solid cylinder of the liquid's radius and height with the
  slip factor on its roll inertia (eq. 4.3-4.4). By default it sits where fixed and slosh mass at rest
  together keep the liquid's static CG (DESIGN.md note 2, Abramson); ``cg_convention="thesis"`` puts it
  at the liquid centroid as the thesis did (which moves the vehicle's CG).

Below :data:`MIN_SLOSH_HEIGHT` of liquid the tank has no slosh degree of freedom: its pendulum is
inactive (mass 0) and the liquid is all fixed mass (DESIGN.md note 4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .config import Grain, Tank

#: first root of the derivative of the Bessel function J1 [-]
XI = 1.84119
#: liquid height below which a tank has no slosh degree of freedom [m]; the capped pendulum (L <= h)
#: of a 1 mm film under 10 g swings at 310 rad/s, still resolved by RK4 at 1 ms
MIN_SLOSH_HEIGHT = 1e-3
CG_CONVENTIONS = ("static", "thesis")


@dataclass(frozen=True)
class TankProperties:
    """Mass properties of one tank's liquid at one instant. Stations in metres from the nose tip.

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


def slosh_fraction(kappa: float) -> float:
    """``m_s / m_liq = 2 tanh(kappa) / ((xi^2 - 1) kappa)`` [-], with its limit 2 / (xi^2 - 1) at 0."""
    if kappa < 1e-8:
        return 2.0 / (XI**2 - 1.0)
    return 2.0 * np.tanh(kappa) / ((XI**2 - 1.0) * kappa)


def tank_properties(tank: Tank, liquid_mass: float, cg_convention: str = "static") -> TankProperties:
    """Mass properties of ``tank`` holding ``liquid_mass`` [kg] (thesis eq. 2.23-2.29, 4.3-4.4)."""
    if cg_convention not in CG_CONVENTIONS:
        raise ValueError(f"cg_convention = {cg_convention!r}: one of {CG_CONVENTIONS}")
    R = tank.inner_radius
    m = max(float(liquid_mass), 0.0)
    h = m / (np.pi * R**2 * tank.density)
    x_liq = tank.bottom + 0.5 * h
    if h < MIN_SLOSH_HEIGHT or not tank.slosh:
        m_s, L, L_rob, x_s, x_h = 0.0, 0.0, 0.0, x_liq, x_liq
    else:
        kappa = XI * h / R
        m_s = m * slosh_fraction(kappa)
        L_rob = R / (XI * np.tanh(kappa))
        L = min(L_rob, h)
        x_s = x_liq + 0.5 * h - (2.0 * R / XI) * np.tanh(0.5 * kappa)
        x_h = x_s + L
    m_f = m - m_s
    if m_f <= 0.0:
        x_f = x_liq
    elif cg_convention == "static":
        x_f = (m * x_liq - m_s * x_s) / m_f
    else:
        x_f = x_liq
    J_f = np.diag([0.5 * m_f * R**2 * (1.0 - tank.slip_factor),
                   m_f * (3.0 * R**2 + h**2) / 12.0, m_f * (3.0 * R**2 + h**2) / 12.0])
    return TankProperties(liquid_mass=m, height=h, liquid_cg=x_liq, slosh_mass=m_s, pendulum_length=L,
                          pendulum_length_roberts=L_rob, slosh_station=x_s, hinge_station=x_h,
                          fixed_mass=m_f, fixed_cg=x_f, fixed_inertia=J_f)


def grain_properties(grain: Grain, mass: float) -> tuple[float, float, np.ndarray]:
    """Mass [kg], CG station [m] and inertia about its CG [kg m^2] (3, 3) of a hybrid fuel grain of
    ``mass`` [kg]: a thick-walled cylinder burnt uniformly from the port, so the port radius is
    ``sqrt(Ro^2 - m / (rho pi L))``."""
    m = min(max(float(mass), 0.0), grain.capacity)
    Ro, Lg = grain.outer_radius, grain.length
    r_port2 = max(Ro**2 - m / (grain.density * np.pi * Lg), 0.0)
    Ixx = 0.5 * m * (Ro**2 + r_port2)
    Iyy = m * (3.0 * (Ro**2 + r_port2) + Lg**2) / 12.0
    return m, grain.top - 0.5 * Lg, np.diag([Ixx, Iyy, Iyy])
