"""Coast attitude control: what the vehicle's flight software does while no engine burns.

Between a stage's burnout and the next ignition the thrust vector cannot steer, and an upper stack
without fins is aerodynamically unstable (the centre of pressure of its nose lies ahead of its centre of
gravity). Launchers hold their attitude through such coasts with reaction control (cold-gas or
hydrazine thrusters). With ``coast_control`` on, the ascent env applies, over every control period in
which the policy is off after ``controller_on_after_s`` (and not for the roll task, whose action is
already reaction control), the body moment

    M_y = -J_yy (w_n^2 theta + 2 zeta w_n q_err),    M_z = -J_zz (w_n^2 psi + 2 zeta w_n r)

each limited to +-``coast_torque_nm`` [N m] (a thruster pulse-width modulation averaged over the
period), with ``theta``, ``psi`` [rad] the pitch and yaw attitude errors against the task's reference
axis, ``q_err`` the pitch rate less the reference pitch rate and ``r`` the yaw rate [rad/s] (the
vehicle's true state: the coast mode is not part of what a policy is scored on, so it is not given
sensor errors), ``J_yy``, ``J_zz`` [kg m^2] the rigid body's inertias at the row's time, ``w_n`` =
``coast_bandwidth_radps`` and ``zeta`` = :data:`DAMPING`. With an aerodynamic divergence rate lambda
the closed loop's stiffness is ``w_n^2 - lambda^2``, so ``w_n`` must exceed the divergence rate of the
coasting stack (about 1 rad/s for SMILE's finless upper stack at 2 kPa: docs/vehicles.md).
"""

from __future__ import annotations

import numpy as np

__all__ = ["DAMPING", "coast_moment"]

#: damping ratio of the coast attitude loop [-]
DAMPING = 0.7


def coast_moment(att: np.ndarray, rate_error: np.ndarray, inertia: np.ndarray, bandwidth: float,
                 torque_limit: float) -> np.ndarray:
    """Pitch and yaw moments (R, 2) [N m] of the coast attitude hold (module docstring).

    ``att`` (R, 2) [rad] attitude errors (pitch, yaw); ``rate_error`` (R, 2) [rad/s] the signed pitch rate
    error and yaw rate; ``inertia`` (R, 2) [kg m^2] J_yy, J_zz; ``bandwidth`` [rad/s]; ``torque_limit`` [N m]."""
    w = float(bandwidth)
    m = -np.asarray(inertia, float) * (w * w * np.asarray(att, float) + 2.0 * DAMPING * w * np.asarray(rate_error, float))
    return np.clip(m, -torque_limit, torque_limit)
