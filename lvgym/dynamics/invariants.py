"""Energy, linear momentum and slosh-mass kinematics of a batch of vehicles (compiled).

Energy follows thesis eq. 4.15-4.21: kinetic energy of B, the modes and the slosh bodies,
gravitational potential ``-m g . r`` in a uniform field, and the elastic energy
``0.5 eta^T Omega^2 eta``. The *internal* energy used to normalise an energy drift (physics
note 7, docs/physics-notes.md) is the energy of the internal motions: rotation of B, bending (kinetic and elastic) and the
slosh motion relative to the CG of B.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from lvgym.packing import Field, Packed, at
from lvgym.rotations import quat_to_dcm

from .kernels import hinge_offset
from .layout import SLOSH_BLOCK, X_PER_SLOSH, P, S, X

#: the columns written by ``energy_batch`` (an interface: callers read them in this order)
ENERGY = Packed("energy terms", [
    Field("kinetic", 1, "J", "kinetic energy of B, the modes and the slosh bodies"),
    Field("gravitational", 1, "J", "potential -m g . r in the uniform field"),
    Field("elastic", 1, "J", "0.5 eta^T Omega^2 eta"),
    Field("total", 1, "J", "kinetic + gravitational + elastic"),
    Field("internal", 1, "J", "rotation + bending + slosh motion relative to the CG of B (physics note 7)"),
    Field("rotation", 1, "J", "rotation of B"),
    Field("bending", 1, "J", "kinetic and elastic energy of the modes"),
    Field("slosh", 1, "J", "slosh motion relative to the CG of B"),
], interface=True)
ENERGY_TERMS = ENERGY.names
_E = ENERGY.at


@nb.njit(cache=True)
def slosh_mass_kinematics(x, p, j, n_slosh, n_modes, C, r_out, v_out):
    """Inertial position ``r_cw_i`` and velocity ``v_cw_i`` of slosh mass j of one vehicle.

    ``r_c = r_z + C_ib (r_az + Psi eta) - L n_s``; ``v_c = v_z + C_ib (w x rho + Psi eta_dot) +
    L (w1 z_s - w2 y_s)`` (thesis eq. 4.20). ``C`` is (2, 3, 3) scratch.
    """
    K = n_modes
    N = n_slosh
    Cb = C[0]
    Cs = C[1]
    o_q = at(X.q_bi, K, N)
    quat_to_dcm(x[o_q], x[o_q + 1], x[o_q + 2], x[o_q + 3], Cb)
    qo = at(X.q_si, K, N) + j * X_PER_SLOSH.q_si
    quat_to_dcm(x[qo], x[qo + 1], x[qo + 2], x[qo + 3], Cs)
    L = p[at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N) + at(S.length, K, N)]
    o_cg = at(P.r_cg, K, N)
    r0, r1, r2, vy, vz = hinge_offset(x, p, j, p[o_cg], p[o_cg + 1], p[o_cg + 2], K, N)
    o_w = at(X.omega_bi_b, K, N)
    w0, w1, w2 = x[o_w], x[o_w + 1], x[o_w + 2]
    hb0 = w1 * r2 - w2 * r1
    hb1 = w2 * r0 - w0 * r2 + vy
    hb2 = w0 * r1 - w1 * r0 + vz
    wo = at(X.omega_si_s, K, N) + j * X_PER_SLOSH.omega_si_s
    ws1 = x[wo]
    ws2 = x[wo + 1]
    o_r = at(X.r_zw_i, K, N)
    o_v = at(X.v_zw_i, K, N)
    for i in range(3):
        r_out[i] = x[o_r + i] + Cb[i, 0] * r0 + Cb[i, 1] * r1 + Cb[i, 2] * r2 - L * Cs[i, 0]
        v_out[i] = (x[o_v + i] + Cb[i, 0] * hb0 + Cb[i, 1] * hb1 + Cb[i, 2] * hb2
                    + L * (ws1 * Cs[i, 2] - ws2 * Cs[i, 1]))


@nb.njit(cache=True)
def energy_batch(x, p, g, n_slosh, n_modes, out):
    """Energy terms (``ENERGY_TERMS``) of every vehicle for the uniform gravity ``g`` (B, 3) [J]."""
    B = x.shape[0]
    K = n_modes
    N = n_slosh
    o_r = at(X.r_zw_i, K, N)
    o_v = at(X.v_zw_i, K, N)
    o_w = at(X.omega_bi_b, K, N)
    o_eta = at(X.eta, K, N)
    o_etad = at(X.eta_dot, K, N)
    o_J = at(P.J_b, K, N)
    o_om = at(P.omega_modes, K, N)
    C = np.empty((2, 3, 3))
    rc = np.empty(3)
    vc = np.empty(3)
    for b in range(B):
        xb = x[b]
        pb = p[b]
        m = pb[at(P.m_b, K, N)]
        v0, v1, v2 = xb[o_v], xb[o_v + 1], xb[o_v + 2]
        ke_t = 0.5 * m * (v0 ** 2 + v1 ** 2 + v2 ** 2)
        w0, w1, w2 = xb[o_w], xb[o_w + 1], xb[o_w + 2]
        ke_r = 0.5 * (w0 * (pb[o_J] * w0 + pb[o_J + 1] * w1 + pb[o_J + 2] * w2)
                      + w1 * (pb[o_J + 3] * w0 + pb[o_J + 4] * w1 + pb[o_J + 5] * w2)
                      + w2 * (pb[o_J + 6] * w0 + pb[o_J + 7] * w1 + pb[o_J + 8] * w2))
        pe_g = -m * (g[b, 0] * xb[o_r] + g[b, 1] * xb[o_r + 1] + g[b, 2] * xb[o_r + 2])
        ke_f = 0.0
        pe_f = 0.0
        for k in range(2 * K):
            om = pb[o_om + k % K]
            ke_f += 0.5 * xb[o_etad + k] ** 2
            pe_f += 0.5 * om * om * xb[o_eta + k] ** 2
        ke_s = 0.0
        ke_s_rel = 0.0
        for j in range(N):
            o = at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N)
            ms = pb[o + at(S.m, K, N)]
            if ms <= 0.0:
                continue
            slosh_mass_kinematics(xb, pb, j, N, K, C, rc, vc)
            wo = at(X.omega_si_s, K, N) + j * X_PER_SLOSH.omega_si_s
            rot = 0.5 * pb[o + at(S.inertia, K, N)] * (xb[wo] ** 2 + xb[wo + 1] ** 2)
            ke_s += 0.5 * ms * (vc[0] ** 2 + vc[1] ** 2 + vc[2] ** 2) + rot
            ke_s_rel += 0.5 * ms * ((vc[0] - v0) ** 2 + (vc[1] - v1) ** 2 + (vc[2] - v2) ** 2) + rot
            pe_g -= ms * (g[b, 0] * rc[0] + g[b, 1] * rc[1] + g[b, 2] * rc[2])
        kin = ke_t + ke_r + ke_f + ke_s
        out[b, _E.kinetic] = kin
        out[b, _E.gravitational] = pe_g
        out[b, _E.elastic] = pe_f
        out[b, _E.total] = kin + pe_g + pe_f
        out[b, _E.internal] = ke_r + ke_f + pe_f + ke_s_rel
        out[b, _E.rotation] = ke_r
        out[b, _E.bending] = ke_f + pe_f
        out[b, _E.slosh] = ke_s_rel


@nb.njit(cache=True)
def momentum_batch(x, p, n_slosh, n_modes, out):
    """Total linear momentum ``m_B v_z + sum m_j v_cj`` of every vehicle, inertial [kg m/s]."""
    B = x.shape[0]
    K = n_modes
    N = n_slosh
    o_v = at(X.v_zw_i, K, N)
    C = np.empty((2, 3, 3))
    rc = np.empty(3)
    vc = np.empty(3)
    for b in range(B):
        m = p[b, at(P.m_b, K, N)]
        for i in range(3):
            out[b, i] = m * x[b, o_v + i]
        for j in range(N):
            ms = p[b, at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N) + at(S.m, K, N)]
            if ms <= 0.0:
                continue
            slosh_mass_kinematics(x[b], p[b], j, N, K, C, rc, vc)
            for i in range(3):
                out[b, i] += ms * vc[i]


@nb.njit(cache=True)
def slosh_positions_batch(x, p, n_slosh, n_modes, r_out, v_out):
    """Inertial positions and velocities of every slosh mass: ``r_out``, ``v_out`` (B, N, 3)."""
    C = np.empty((2, 3, 3))
    for b in range(x.shape[0]):
        for j in range(n_slosh):
            slosh_mass_kinematics(x[b], p[b], j, n_slosh, n_modes, C, r_out[b, j], v_out[b, j])
