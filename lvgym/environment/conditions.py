"""Flight conditions: the environment models evaluated once for a vehicle state.

:class:`Environment` bundles a launch site with gravity, atmosphere, wind and aerodynamics models (each
chosen by name, see :func:`lvgym.environment.make`) and :meth:`Environment.conditions` evaluates them all
once for a batch of vehicle states, so the simulator and the recorded trajectories see the same altitude,
wind, air-relative velocity, angle of attack, Mach and dynamic pressure as the loads:

1. geodetic altitude and the local NED frame under the vehicle (:class:`~.earth.LaunchSite`);
2. wind in NED from the wind model, turned into the inertial frame;
3. velocity relative to the air ``v_air = v - omega_e x r - wind`` (the atmosphere turns with the Earth),
   in body axes;
4. density, pressure, temperature and speed of sound at that altitude;
5. aerodynamic force and moment about the CG, and angle of attack, sideslip, Mach and dynamic pressure.

Quaternions are scalar-first, ``C_ib = R(q_bi)``, as in the dynamics core.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.rotations import quat_to_dcm_batch

from .earth import LaunchSite
from .registry import make


@dataclass(frozen=True)
class FlightConditions:
    """The environment at a batch of vehicle states; arrays with a leading batch axis.

    ``altitude`` geodetic [m]; ``density`` [kg/m^3], ``pressure`` [Pa], ``temperature`` [K],
    ``speed_of_sound`` [m/s]; ``wind_n`` wind in local NED [m/s]; ``wind_i`` the same in the inertial
    frame; ``v_air_b`` vehicle velocity relative to the air, body axes [m/s]; ``alpha``, ``beta``,
    ``alpha_total`` [rad]; ``mach`` [-]; ``qbar`` dynamic pressure [Pa]; ``f_aero_b`` [N] and
    ``m_aero_b`` [N m] about the CG, body axes; ``g_i`` gravitational acceleration [m/s^2]."""

    altitude: np.ndarray
    density: np.ndarray
    pressure: np.ndarray
    temperature: np.ndarray
    speed_of_sound: np.ndarray
    wind_n: np.ndarray
    wind_i: np.ndarray
    v_air_b: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    alpha_total: np.ndarray
    mach: np.ndarray
    qbar: np.ndarray
    f_aero_b: np.ndarray
    m_aero_b: np.ndarray
    g_i: np.ndarray


class Environment:
    """A launch site and the four environment models, each a name or a mapping for :func:`make`.

    Defaults are the thesis's: US76 atmosphere, EGM2008 of degree and order 4, no wind (the thesis's HWM
    is not available, see docs/atmosphere-and-wind.md). ``aerodynamics`` may be None (no aerodynamic
    loads, e.g. in vacuum verification cases)."""

    def __init__(self, site: LaunchSite, gravity: Any = "egm2008", atmosphere: Any = "us76", wind: Any = "none",
                 aerodynamics: Any = None):
        self.site = site
        self.gravity = make("gravity", gravity) if isinstance(gravity, (str, dict)) else gravity
        self.atmosphere = make("atmosphere", atmosphere) if isinstance(atmosphere, (str, dict)) else atmosphere
        self.wind = make("wind", wind) if isinstance(wind, (str, dict)) else wind
        self.aerodynamics = (make("aerodynamics", aerodynamics) if isinstance(aerodynamics, (str, dict))
                             else aerodynamics)

    def reset(self, rng: np.random.Generator) -> None:
        """Draw whatever is random (turbulence, random wind profiles) from ``rng``."""
        self.wind.reset(rng)

    def conditions(self, t: Any, r_zw_i: Any, v_zw_i: Any, q_bi: Any, omega_bi_b: Any, x_cg: Any) -> FlightConditions:
        """Evaluate every model once at time ``t`` [s] for CG positions ``r_zw_i`` [m], velocities
        ``v_zw_i`` [m/s], attitudes ``q_bi`` and body rates ``omega_bi_b`` [rad/s] (leading batch axis or
        one vehicle) with CG stations ``x_cg`` [m] (for the aerodynamic moment)."""
        r = np.atleast_2d(np.asarray(r_zw_i, dtype=float))
        v = np.atleast_2d(np.asarray(v_zw_i, dtype=float))
        q = np.atleast_2d(np.asarray(q_bi, dtype=float))
        w = np.atleast_2d(np.asarray(omega_bi_b, dtype=float))
        n = r.shape[0]
        t_b = np.broadcast_to(np.asarray(t, dtype=float), (n,))
        x_cg = np.broadcast_to(np.asarray(x_cg, dtype=float), (n,))
        alt = np.atleast_1d(self.site.altitude(r, t_b))
        C_ni = self.site.C_ni(r, t_b).reshape(n, 3, 3)
        wind_n = np.atleast_2d(self.wind.velocity_ned(alt, t_b))
        wind_i = np.einsum("bji,bj->bi", C_ni, wind_n)
        v_rel_i = np.atleast_2d(self.site.velocity_wrt_earth(r, v)) - wind_i
        C_ib = np.empty((n, 3, 3))
        quat_to_dcm_batch(np.ascontiguousarray(q), C_ib)
        v_air_b = np.einsum("bji,bj->bi", C_ib, v_rel_i)
        atm = self.atmosphere(alt)
        rho, a = np.atleast_1d(atm.density), np.atleast_1d(atm.speed_of_sound)
        g_i = np.atleast_2d(self.gravity.acceleration(r, t_b))
        if self.aerodynamics is None:  # no loads; the flow angles as the aerodynamics kernel defines them
            u, v_, w_ = v_air_b[:, 0], v_air_b[:, 1], v_air_b[:, 2]
            speed = np.linalg.norm(v_air_b, axis=1)
            alpha, beta = np.arctan2(w_, u), np.arctan2(v_, np.hypot(u, w_))
            alpha_total = np.arctan2(np.hypot(v_, w_), u)
            mach = np.divide(speed, a, out=np.zeros(n), where=a > 0)
            f_b, m_b, qbar = np.zeros((n, 3)), np.zeros((n, 3)), 0.5 * rho * speed**2
        else:
            f_b, m_b, st = self.aerodynamics.loads(v_air_b, w, rho, a, x_cg, alt)
            alpha, beta, alpha_total = st.alpha, st.beta, st.alpha_total
            mach, qbar = st.mach, st.qbar
        return FlightConditions(altitude=alt, density=rho, pressure=np.atleast_1d(atm.pressure),
                                temperature=np.atleast_1d(atm.temperature), speed_of_sound=a, wind_n=wind_n,
                                wind_i=wind_i, v_air_b=v_air_b, alpha=np.atleast_1d(alpha), beta=np.atleast_1d(beta),
                                alpha_total=np.atleast_1d(alpha_total), mach=np.atleast_1d(mach),
                                qbar=np.atleast_1d(qbar), f_aero_b=np.atleast_2d(f_b), m_aero_b=np.atleast_2d(m_b),
                                g_i=g_i)
