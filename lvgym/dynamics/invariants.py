"""Energy, linear momentum and slosh-mass kinematics of a batch of vehicles (compiled).

Energy follows thesis eq. 4.15-4.21: kinetic energy of B, the modes and the slosh bodies,
gravitational potential ``-m g . r`` in a uniform field, and the elastic energy
``0.5 eta^T Omega^2 eta``. The *internal* energy used to normalise an energy drift (DESIGN.md
note 7) is the energy of the internal motions: rotation of B, bending (kinetic and elastic) and the
slosh motion relative to the CG of B.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .kernels import P_CG, P_J, P_M, P_MODES, X_ETA, X_Q, X_R, X_V, X_W, quat_to_dcm

#: names of the columns written by ``energy_batch``
ENERGY_TERMS = ("kinetic", "gravitational", "elastic", "total", "internal", "rotation", "bending",
                "slosh")


@nb.njit(cache=True)
def slosh_mass_kinematics(x, p, j, n_slosh, n_modes, C, r_out, v_out):
    """Inertial position ``r_cw_i`` and velocity ``v_cw_i`` of slosh mass j of one vehicle.

    ``r_c = r_z + C_ib (r_az + Psi eta) - L n_s``; ``v_c = v_z + C_ib (w x rho + Psi eta_dot) +
    L (w1 z_s - w2 y_s)`` (thesis eq. 4.20). ``C`` is (2, 3, 3) scratch.
    """
    K = n_modes
    Cb = C[0]
    Cs = C[1]
    quat_to_dcm(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3], Cb)
    qo = X_ETA + 4 * K + 4 * j
    quat_to_dcm(x[qo], x[qo + 1], x[qo + 2], x[qo + 3], Cs)
    o = P_MODES + 4 * K + j * (8 + K)
    L = p[o + 1]
    py = 0.0
    pz = 0.0
    vy = 0.0
    vz = 0.0
    for k in range(K):
        py += p[o + 8 + k] * x[X_ETA + k]
        pz += p[o + 8 + k] * x[X_ETA + K + k]
        vy += p[o + 8 + k] * x[X_ETA + 2 * K + k]
        vz += p[o + 8 + k] * x[X_ETA + 3 * K + k]
    r0 = p[o + 3] - p[P_CG]
    r1 = p[o + 4] - p[P_CG + 1] + py
    r2 = p[o + 5] - p[P_CG + 2] + pz
    w0, w1, w2 = x[X_W], x[X_W + 1], x[X_W + 2]
    hb0 = w1 * r2 - w2 * r1
    hb1 = w2 * r0 - w0 * r2 + vy
    hb2 = w0 * r1 - w1 * r0 + vz
    wo = X_ETA + 4 * K + 4 * n_slosh + 2 * j
    ws1 = x[wo]
    ws2 = x[wo + 1]
    for i in range(3):
        r_out[i] = x[X_R + i] + Cb[i, 0] * r0 + Cb[i, 1] * r1 + Cb[i, 2] * r2 - L * Cs[i, 0]
        v_out[i] = (x[X_V + i] + Cb[i, 0] * hb0 + Cb[i, 1] * hb1 + Cb[i, 2] * hb2
                    + L * (ws1 * Cs[i, 2] - ws2 * Cs[i, 1]))


@nb.njit(cache=True)
def energy_batch(x, p, g, n_slosh, n_modes, out):
    """Energy terms (``ENERGY_TERMS``) of every vehicle for the uniform gravity ``g`` (B, 3) [J]."""
    B = x.shape[0]
    K = n_modes
    C = np.empty((2, 3, 3))
    rc = np.empty(3)
    vc = np.empty(3)
    for b in range(B):
        xb = x[b]
        pb = p[b]
        m = pb[P_M]
        v0, v1, v2 = xb[X_V], xb[X_V + 1], xb[X_V + 2]
        ke_t = 0.5 * m * (v0 ** 2 + v1 ** 2 + v2 ** 2)
        w0, w1, w2 = xb[X_W], xb[X_W + 1], xb[X_W + 2]
        ke_r = 0.5 * (w0 * (pb[P_J] * w0 + pb[P_J + 1] * w1 + pb[P_J + 2] * w2)
                      + w1 * (pb[P_J + 3] * w0 + pb[P_J + 4] * w1 + pb[P_J + 5] * w2)
                      + w2 * (pb[P_J + 6] * w0 + pb[P_J + 7] * w1 + pb[P_J + 8] * w2))
        pe_g = -m * (g[b, 0] * xb[X_R] + g[b, 1] * xb[X_R + 1] + g[b, 2] * xb[X_R + 2])
        ke_f = 0.0
        pe_f = 0.0
        for k in range(2 * K):
            om = pb[P_MODES + k % K]
            ke_f += 0.5 * xb[X_ETA + 2 * K + k] ** 2
            pe_f += 0.5 * om * om * xb[X_ETA + k] ** 2
        ke_s = 0.0
        ke_s_rel = 0.0
        for j in range(n_slosh):
            o = P_MODES + 4 * K + j * (8 + K)
            ms = pb[o]
            if ms <= 0.0:
                continue
            slosh_mass_kinematics(xb, pb, j, n_slosh, K, C, rc, vc)
            wo = X_ETA + 4 * K + 4 * n_slosh + 2 * j
            rot = 0.5 * pb[o + 2] * (xb[wo] ** 2 + xb[wo + 1] ** 2)
            ke_s += 0.5 * ms * (vc[0] ** 2 + vc[1] ** 2 + vc[2] ** 2) + rot
            ke_s_rel += 0.5 * ms * ((vc[0] - v0) ** 2 + (vc[1] - v1) ** 2 + (vc[2] - v2) ** 2) + rot
            pe_g -= ms * (g[b, 0] * rc[0] + g[b, 1] * rc[1] + g[b, 2] * rc[2])
        kin = ke_t + ke_r + ke_f + ke_s
        out[b, 0] = kin
        out[b, 1] = pe_g
        out[b, 2] = pe_f
        out[b, 3] = kin + pe_g + pe_f
        out[b, 4] = ke_r + ke_f + pe_f + ke_s_rel
        out[b, 5] = ke_r
        out[b, 6] = ke_f + pe_f
        out[b, 7] = ke_s_rel


@nb.njit(cache=True)
def momentum_batch(x, p, n_slosh, n_modes, out):
    """Total linear momentum ``m_B v_z + sum m_j v_cj`` of every vehicle, inertial [kg m/s]."""
    B = x.shape[0]
    K = n_modes
    C = np.empty((2, 3, 3))
    rc = np.empty(3)
    vc = np.empty(3)
    for b in range(B):
        m = p[b, P_M]
        for i in range(3):
            out[b, i] = m * x[b, X_V + i]
        for j in range(n_slosh):
            ms = p[b, P_MODES + 4 * K + j * (8 + K)]
            if ms <= 0.0:
                continue
            slosh_mass_kinematics(x[b], p[b], j, n_slosh, K, C, rc, vc)
            for i in range(3):
                out[b, i] += ms * vc[i]


@nb.njit(cache=True)
def slosh_positions_batch(x, p, n_slosh, n_modes, r_out, v_out):
    """Inertial positions and velocities of every slosh mass: ``r_out``, ``v_out`` (B, N, 3)."""
    C = np.empty((2, 3, 3))
    for b in range(x.shape[0]):
        for j in range(n_slosh):
            slosh_mass_kinematics(x[b], p[b], j, n_slosh, n_modes, C, r_out[b, j], v_out[b, j])
