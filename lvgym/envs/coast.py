"""Coast attitude control: what the vehicle's flight software does while no engine burns.

Between a stage's burnout and the next ignition the thrust vector cannot steer, and an upper stack
without fins is aerodynamically unstable (the centre of pressure of its nose lies ahead of its centre of
gravity). Launchers hold their attitude through such coasts with reaction control (cold-gas or
hydrazine thrusters), and in the atmosphere they hold it against the relative wind, at zero angle of
attack, which keeps the aerodynamic moment that drives the divergence at zero. With ``coast_control`` on,
the ascent env applies, over every control period in which the policy is off after
``controller_on_after_s`` (and not for the roll task, whose action is already reaction control), the body
moment

    M_y = -J_yy (w_n^2 alpha + 2 zeta w_n q),    M_z = -J_zz (-w_n^2 beta + 2 zeta w_n r)

each limited to +-``coast_torque_nm`` [N m] (a thruster pulse-width modulation averaged over the
period), with ``alpha``, ``beta`` [rad] the angle of attack and sideslip of the row's latest flight
conditions, ``q``, ``r`` [rad/s] the body pitch and yaw rates (the vehicle's true state, as its
navigation would estimate it: the coast mode is not what a policy is scored on), ``J_yy``, ``J_zz``
[kg m^2] the rigid body's inertias at the row's time, ``w_n`` = ``coast_bandwidth_radps`` and ``zeta`` =
:data:`DAMPING`. A positive ``alpha`` (nose above the relative wind) asks for a nose-down moment, a
positive ``beta`` (relative wind from +y_b) for a yaw towards +y_b. With an aerodynamic divergence rate
lambda the closed loop's stiffness is ``w_n^2 - lambda^2``, so ``w_n`` must exceed the divergence rate of
the coasting stack (about 1 rad/s for SMILE's finless upper stack at 2 kPa: docs/vehicles.md). The
policy takes over at ignition from this attitude, whatever its error against the task's reference.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DAMPING", "coast_moment"]

#: damping ratio of the coast attitude loop [-]
DAMPING = 0.7


def coast_moment(alpha: np.ndarray, beta: np.ndarray, rates: np.ndarray, inertia: np.ndarray, bandwidth: float,
                 torque_limit: float) -> np.ndarray:
    """Pitch and yaw moments (R, 2) [N m] of the coast attitude hold (module docstring).

    ``alpha``, ``beta`` (R,) [rad] angle of attack and sideslip; ``rates`` (R, 2) [rad/s] body pitch and yaw
    rates q, r; ``inertia`` (R, 2) [kg m^2] J_yy, J_zz; ``bandwidth`` [rad/s]; ``torque_limit`` [N m]."""
    w = float(bandwidth)
    angle = np.stack([np.asarray(alpha, float), -np.asarray(beta, float)], axis=-1)
    m = -np.asarray(inertia, float) * (w * w * angle + 2.0 * DAMPING * w * np.asarray(rates, float))
    return np.clip(m, -torque_limit, torque_limit)
