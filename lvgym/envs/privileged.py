"""What no flight sensor gives: the env's ``privileged_info`` (for a privileged reference or a teacher policy,
never for a scored causal one), read off the simulator's rows; the flight stays the same to the bit."""

from __future__ import annotations

import numpy as np

from lvgym.simulator import SimData, Simulator
from lvgym.simulator.layouts import ACTUATOR, CONDITIONS

__all__ = ["PREVIEW_PERIODS", "privileged_info"]

#: the preview of the wind ahead: 1 to this many control periods
PREVIEW_PERIODS = 10


def privileged_info(sim: Simulator, data: SimData, control_dt_s: float) -> dict[str, np.ndarray]:
    """Per row of ``data``: the true body rates ``omega_bi_b`` (B, 3) [rad/s] (of the rigid body, no bending,
    no noise), the aerodynamic moment about the CG ``m_aero_b`` (B, 3) [N m] (the wind's included), the thrust
    (B,) [N], the gimbal's lever arm ``gimbal_arm`` (B,) [m] (CG station minus gimbal station along x_b), the
    share of the thrust the gimbal turns ``vectored_share`` (B,) [-], the body's principal inertias
    ``J_b_diag`` (B, 3) [kg m^2] and the velocity relative to the air in body axes ``v_air_b`` (B, 3) [m/s];
    the true thrust misalignment ``misalignment`` (B, 2) [rad] (pitch, yaw: the dispersion's and a fault's)
    and the share of the command each gimbal axis still reaches ``actuator_effectiveness`` (B, 2) [-] (1 but
    after a fault); and the wind ahead of the vehicle over the next :data:`PREVIEW_PERIODS` control periods
    of ``control_dt_s`` [s] (the horizons ``k`` periods, ``k`` = 1, 2, ...,
    :meth:`~lvgym.simulator.Simulator.conditions_ahead`): the wind it flies into ``wind_ahead_n`` (B, K, 3)
    [m/s] (local north-east-down) and the aerodynamic moment that wind and air would cause at the present
    attitude and rates ``m_aero_ahead_b`` (B, K, 3) [N m]."""
    cond, lay = sim.conditions, sim.layout
    ahead = sim.conditions_ahead(data, [k * control_dt_s for k in range(1, PREVIEW_PERIODS + 1)])
    J = data.p[:, lay.params["J_b"]].reshape(-1, 3, 3)
    r_cg, r_gimbal = data.p[:, lay.params["r_cg"]], data.p[:, lay.params["r_gimbal"]]
    return {"omega_bi_b": sim.state(data, "omega_bi_b").copy(), "m_aero_b": cond(data, "m_aero_b").copy(),
            "thrust": cond(data, "thrust").copy(), "gimbal_arm": r_cg[:, 0] - r_gimbal[:, 0],
            "vectored_share": sim.vectored_share(data),
            "J_b_diag": np.stack([J[:, 0, 0], J[:, 1, 1], J[:, 2, 2]], axis=1),
            "v_air_b": cond(data, "v_air_b").copy(), "misalignment": sim.misalignment(data).copy(),
            "actuator_effectiveness": 1.0 - ACTUATOR.view(data.actuator, "effectiveness_loss"),
            "wind_ahead_n": CONDITIONS.view(ahead, "wind_n").transpose(1, 0, 2).copy(),
            "m_aero_ahead_b": CONDITIONS.view(ahead, "m_aero_b").transpose(1, 0, 2).copy()}
