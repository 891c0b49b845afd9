"""The compiled act of ``privileged`` (:mod:`.privileged`) for any number of rows, one row after the other (a
row's operations its own, so a batch of one gives the bits of the same row of any batch).

Per row ``r`` of ``rows`` and its position ``i`` in the call, from the row's privileged step info (pitch, yaw)::

    lever  = thrust share arm                         no thrust (lever < 1 N m): action 0
    hold   = 1 - clip((q_alpha / q_alpha_limit - onset) / (full - onset), 0, 1)
    alpha  = -2 z w e_rate - hold w^2 e_att           e_rate = (omega_y - ref_i, omega_z)
    delta  = (J alpha - hold M_aero) / lever
    delta  = (delta - mis) / max(eff, 0.1)            with ``plant``
    action = clip(delta / limit, -1, 1)

the operations in the order of the elementwise NumPy expressions they replace, so the actions are the same to
the bit.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

__all__ = ["PrivilegedGains", "PrivilegedInfo", "privileged_act_k"]


class PrivilegedGains(NamedTuple):
    """The law's constants: ``w`` [rad/s] and ``z`` [-] of the attitude loop, the relief's ``onset`` and ``full``
    (shares of the q-alpha limit), the gimbal ``limit`` [rad], ``plant`` (1.0: take off the true misalignment and
    divide by the actuator's effectiveness; 0.0: not)."""

    w: float
    z: float
    onset: float
    full: float
    limit: float
    plant: float


class PrivilegedInfo(NamedTuple):
    """The step's privileged info of the whole batch (row-indexed, float64): ``thrust`` (B,) [N],
    ``share`` (B,) vectored share [-], ``arm`` (B,) [m], ``omega`` (B, 3) body rates [rad/s], ``att`` (B, 2)
    attitude errors [rad], ``m_aero`` (B, 3) the aerodynamic moment the law reads [N m], ``J`` (B, 3) principal
    inertias [kg m^2], ``qalpha`` (B,) [Pa deg], ``qalpha_limit`` (B,) [Pa deg], ``mis`` (B, 2) [rad],
    ``eff`` (B, 2) [-]."""

    thrust: np.ndarray
    share: np.ndarray
    arm: np.ndarray
    omega: np.ndarray
    att: np.ndarray
    m_aero: np.ndarray
    J: np.ndarray
    qalpha: np.ndarray
    qalpha_limit: np.ndarray
    mis: np.ndarray
    eff: np.ndarray


@nb.njit(cache=True)
def privileged_act_k(rows: np.ndarray, ref: np.ndarray, info: PrivilegedInfo, gains: PrivilegedGains,
                     out: np.ndarray) -> None:
    """Write the actions (len(rows), 2) of ``rows`` into ``out`` (float32); ``ref`` (len(rows),) each row's
    reference pitch rate from its observation [rad/s] (module docstring)."""
    a = -2.0 * gains.z * gains.w
    for i in range(rows.shape[0]):
        r = rows[i]
        lever = info.thrust[r] * info.share[r] * info.arm[r]
        if not lever >= 1.0:
            out[i, 0] = 0.0
            out[i, 1] = 0.0
            continue
        x = (info.qalpha[r] / info.qalpha_limit[r] - gains.onset) / (gains.full - gains.onset)
        hold = 1.0 - min(max(x, 0.0), 1.0)
        hw = hold * gains.w * gains.w
        for j in range(2):
            e_rate = info.omega[r, 1] - ref[i] if j == 0 else info.omega[r, 2]
            alpha = a * e_rate - hw * info.att[r, j]
            delta = (info.J[r, j + 1] * alpha - hold * info.m_aero[r, j + 1]) / lever
            if gains.plant != 0.0:
                delta = (delta - info.mis[r, j]) / max(info.eff[r, j], 0.1)
            out[i, j] = min(max(delta / gains.limit, -1.0), 1.0)
