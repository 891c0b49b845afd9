"""Compiled equations of motion of the non-rigid vehicle (thesis chapter 2).

One vehicle: a rigid body B (6 DOF), K bending modes per plane (assumed modes, mean axes,
mass-normalised), and N slosh pendulums whose hinge is fixed to the deflected attachment node.
The coupled equations are those of the null-space method (thesis eq. 2.41-2.52)::

    A u_dot = b,   A = Y^T M Y,   b = Y^T (f - M Ydot u - D Y u - K q - f_non)

with the independent speeds ``u = [v_zw_i, omega_bi_b, eta_dot, w_1 .. w_N]``. The pendulum speeds
``w_j`` are the two components of the pendulum angular velocity normal to its rod: a point mass has
no rotation about the rod, so the rod-axis speed of the thesis's 3-DOF slosh body (which makes A
singular for a point mass, physics note 3) is not a coordinate. The pendulum attitude is a
quaternion, regular through 90 degrees and in free tumbling.

A is assembled blockwise: each pendulum's 2x2 block ``(m L^2 + J) I`` is eliminated by its Schur
complement, written per unit slosh mass, so the reduced matrix ``A_r = M_r + sum m_j B_j^T Q_j B_j``
of the rigid and elastic speeds stays regular for point masses and for a slosh mass going to zero,
and costs a rank-one update per point-mass pendulum. ``B_j`` maps the rigid/elastic speeds to the
hinge velocity, ``Q_j = (1 - s_j) I + s_j n_j n_j^T`` with ``s_j = L^2 / (L^2 + J/m)`` (the rod
projector ``n n^T`` for a point mass: the rod transmits tension only).

:func:`vehicle_deriv` follows those steps, one compiled piece each (inlined, so the pieces cost
nothing): the loads (:func:`_gimbal_thrust`, and the external force and moment in
:func:`_rigid_body`), the rigid body (:func:`_rigid_body`: mass matrix and right-hand side of B), the
modes (:func:`_modes`), the slosh elimination (:func:`_eliminate_pendulum`, per pendulum), the solve
(:func:`_solve`) and the back-substitution (:func:`_kinematics`, :func:`_pendulum_accelerations`).

Every offset comes from a layout: the state, parameters, loads and speeds from :mod:`.layout`, the
kernel's own work arrays from ``SLOSH_WORK``, ``WORK_ROWS``, ``RANK_ONE`` and ``ATTITUDES`` there too
(so the padding switch of :mod:`lvgym.packing` moves them); the scratch is one :data:`DerivWork`. The steps
take a few named blocks: the rigid body's motion (:data:`BodyMotion`), the tilted thrust
(:data:`GimbalThrust`) and a pendulum's scratch (:data:`PendulumWork`). Everything is plain
loops over small arrays compiled with numba; a batch is a loop over the same per-vehicle kernel, so
one code path serves one vehicle and many.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.borrow import unowned
from lvgym.packing import at
from lvgym.rotations import quat_to_dcm

from .layout import ATTITUDES, RANK_ONE, SIZES, SLOSH_BLOCK, SLOSH_WORK, WORK_ROWS, X_PER_SLOSH, P, S, U, V, X

# ---------------------------------------------------------------------------- the kernel's own arrays
# the same for compiled code (numba freezes module globals that are numbers and tuples)
SW, RO, WR, AT = SLOSH_WORK.at, RANK_ONE.at, WORK_ROWS.at, ATTITUDES.at
_SLOSH_WORK_SIZE, _RANK_ONE_SIZE, _ATTITUDES_SIZE = SLOSH_WORK.size, RANK_ONE.size, ATTITUDES.size
_WORK_SIZE = WORK_ROWS.size_form
_TERMS = WORK_ROWS.fixed.terms

#: scratch of :func:`vehicle_deriv` (made by :func:`make_deriv_work`; the part ``deriv`` of the
#: stepper's :data:`~lvgym.dynamics.stepper.Workspace`)
DerivWork = namedtuple("DerivWork", [
    "n_slosh", "n_modes",               # N pendulums, K modes per plane
    "A", "rhs", "h",                    # reduced system (n_r, n_r), its right-hand side and a row (n_r,)
    "C",                                # (ATTITUDES.size, 3, 3): the attitude matrices C_ib, C_is
    "slosh",                            # (max(N, 1), SLOSH_WORK.size): rows kept for the back-substitution
    "work",                             # WORK_ROWS rows of max(n_r, 3) columns
])

#: the rigid body's motion that the steps of :func:`vehicle_deriv` read: ``C_ib`` (3, 3) the attitude
#: matrix; ``omega_b`` (3) [rad/s] the body rate, body axes, and ``omega_i`` the same in inertial
#: components; ``r_cg`` (3) [m] the CG of B (numbers)
BodyMotion = namedtuple("BodyMotion", ["C_ib", "omega_b", "omega_i", "r_cg"])
#: the thrust tilted by the mode slope at the gimbal ``f_b`` (3) [N] and the deflected gimbal from the CG
#: of B ``r_b`` (3) [m], body frame (numbers; :func:`_gimbal_thrust`)
GimbalThrust = namedtuple("GimbalThrust", ["f_b", "r_b"])
#: the arrays a pendulum's elimination writes: ``C_is`` (3, 3) its attitude matrix; ``rhs`` (n_r) the
#: reduced right-hand side; ``h`` (n_r) a row; ``slosh`` the rows kept for the back-substitution and
#: ``work`` the rank-one terms (:data:`DerivWork`)
PendulumWork = namedtuple("PendulumWork", ["C_is", "rhs", "h", "slosh", "work"])


@nb.njit(cache=True, error_model="numpy")
def make_deriv_work(n_slosh, n_modes):
    """A :data:`DerivWork` for ``n_slosh`` pendulums and ``n_modes`` modes per plane."""
    K = n_modes
    N = n_slosh
    nr = at(SIZES.speeds, K, N)
    return DerivWork(N, K, np.empty((nr, nr)), np.empty(nr), np.empty(nr), np.empty((_ATTITUDES_SIZE, 3, 3)),
                     np.zeros((max(N, 1), _SLOSH_WORK_SIZE)), np.empty((at(_WORK_SIZE, K, N), max(nr, 3))))


# ---------------------------------------------------------------------------- small helpers
@nb.njit(cache=True, error_model="numpy", inline="always")
def _quat_rate(q, o, w1, w2, w3, out, oo):
    """``out[oo:oo+4] = 0.5 q (x) (0, w)`` for the quaternion ``q[o:o+4]`` and body rate w."""
    q0, q1, q2, q3 = q[o], q[o + 1], q[o + 2], q[o + 3]
    out[oo] = 0.5 * (-q1 * w1 - q2 * w2 - q3 * w3)
    out[oo + 1] = 0.5 * (q0 * w1 + q2 * w3 - q3 * w2)
    out[oo + 2] = 0.5 * (q0 * w2 + q3 * w1 - q1 * w3)
    out[oo + 3] = 0.5 * (q0 * w3 + q1 * w2 - q2 * w1)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _cholesky_solve(A, b, n):
    """Solve ``A x = b`` in place for the symmetric positive definite leading ``n x n`` block
    of A (only its lower triangle is read); the solution overwrites b. The diagonal of A is
    overwritten with the reciprocals of the Cholesky factor's diagonal."""
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        inv = 1.0 / math.sqrt(s)
        A[j, j] = inv
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s * inv
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= A[i, k] * b[k]
        b[i] = s * A[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= A[k, i] * b[k]
        b[i] = s * A[i, i]


@nb.njit(cache=True, error_model="numpy", inline="always")
def term_rows(q):
    """Rows of ``c_q h_q`` and ``h_q`` (rank-one term ``q``) in the ``work`` matrix (:data:`WORK_ROWS`)."""
    r = _TERMS + q * _RANK_ONE_SIZE
    return r + RO.ch, r + RO.h


@nb.njit(cache=True, error_model="numpy", inline="always")
def _scaled_row(G, q, c, n):
    """Rank-one term ``q`` of :func:`_add_sym_outers`: its row ``c h`` from its row ``h`` (first n
    entries)."""
    rc, rh = term_rows(q)
    for i in range(n):
        G[rc, i] = c * G[rh, i]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _add_sym_outers(A, G, nq, n):
    """``A += sum_q c_q h_q h_q^T`` on the lower triangle of the leading n x n block, with the rows
    ``c_q h_q`` and ``h_q`` of ``G`` at :func:`term_rows`; each entry is summed in a register in the
    order of q (the same sums as nq successive rank-one updates)."""
    for i in range(n):
        for q in range(nq):
            rc, rh = term_rows(q)
            ci = G[rc, i]
            for k in range(i + 1):
                A[i, k] += ci * G[rh, k]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _body_row_map(C, rho0, rho1, rho2, phi, a0, a1, a2, K, N, h):
    """``h = Bt^T a_b`` for a body-frame vector ``a_b`` at a node with offset rho from the CG and
    mode shape phi: ``h = [C a_b, rho x a_b, phi a_b,y, phi a_b,z]`` (the transpose of the map from
    rigid and elastic speeds to the node velocity; ``h`` is a vector of speeds, :data:`.layout.SPEEDS`)."""
    o_v, o_w, o_e = at(V.v_zw_i, K, N), at(V.omega_bi_b, K, N), at(V.eta_dot, K, N)
    h[o_v] = C[0, 0] * a0 + C[0, 1] * a1 + C[0, 2] * a2
    h[o_v + 1] = C[1, 0] * a0 + C[1, 1] * a1 + C[1, 2] * a2
    h[o_v + 2] = C[2, 0] * a0 + C[2, 1] * a1 + C[2, 2] * a2
    h[o_w] = rho1 * a2 - rho2 * a1
    h[o_w + 1] = rho2 * a0 - rho0 * a2
    h[o_w + 2] = rho0 * a1 - rho1 * a0
    for k in range(K):
        h[o_e + k] = phi[k] * a1
        h[o_e + K + k] = phi[k] * a2


@nb.njit(cache=True, error_model="numpy", inline="always")
def hinge_offset(x, p, j, cg0, cg1, cg2, K, N):
    """Pendulum j's deflected hinge from the CG ``cg`` of B ``rho = r_hinge - r_cg + Psi eta`` and the
    hinge deflection rate ``Psi eta_dot`` (y and z), body frame: ``(rho0, rho1, rho2, vy, vz)``."""
    o = at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N)
    o_phi = o + at(S.phi, K, N)
    o_hinge = o + at(S.r_hinge, K, N)
    o_eta, o_etad = at(X.eta, K, N), at(X.eta_dot, K, N)
    py = pz = vy = vz = 0.0
    for k in range(K):
        ph = p[o_phi + k]
        py += ph * x[o_eta + k]
        pz += ph * x[o_eta + K + k]
        vy += ph * x[o_etad + k]
        vz += ph * x[o_etad + K + k]
    r0 = p[o_hinge] - cg0
    r1 = p[o_hinge + 1] - cg1 + py
    r2 = p[o_hinge + 2] - cg2 + pz
    return r0, r1, r2, vy, vz


# ---------------------------------------------------------------------------- the steps of the equations
@nb.njit(cache=True, error_model="numpy", inline="always")
def _gimbal_thrust(x, p, u, cg0, cg1, cg2, K, N):
    """Thrust tilted by the mode slope at the gimbal and the deflected gimbal from the CG of B
    (thesis eq. 2.20-2.22), body frame: a :data:`GimbalThrust`."""
    o_eta = at(X.eta, K, N)
    o_pg = at(P.phi_gimbal, K, N)
    o_dg = at(P.dphi_gimbal, K, N)
    sy = sz = dy = dz = 0.0
    for k in range(K):
        sy += p[o_dg + k] * x[o_eta + k]
        sz += p[o_dg + k] * x[o_eta + K + k]
        dy += p[o_pg + k] * x[o_eta + k]
        dz += p[o_pg + k] * x[o_eta + K + k]
    # rotate the engine-frame thrust by theta = (0, -sz, sy) (Rodrigues)
    o_t = at(U.thrust_b, K, N)
    t0, t1, t2 = u[o_t], u[o_t + 1], u[o_t + 2]
    th1 = -sz
    th2 = sy
    ang = math.sqrt(th1 * th1 + th2 * th2)
    if ang > 0.0:
        e1 = th1 / ang
        e2 = th2 / ang
        ca = math.cos(ang)
        sa = math.sin(ang)
        # e x t, with e = (0, e1, e2)
        c0 = e1 * t2 - e2 * t1
        c1 = e2 * t0
        c2 = -e1 * t0
        ed = e1 * t1 + e2 * t2
        f0 = t0 * ca + c0 * sa
        f1 = t1 * ca + c1 * sa + e1 * ed * (1.0 - ca)
        f2 = t2 * ca + c2 * sa + e2 * ed * (1.0 - ca)
    else:
        f0, f1, f2 = t0, t1, t2
    o_gim = at(P.r_gimbal, K, N)
    re0 = p[o_gim] - cg0
    re1 = p[o_gim + 1] - cg1 + dy
    re2 = p[o_gim + 2] - cg2 + dz
    return GimbalThrust((f0, f1, f2), (re0, re1, re2))


@nb.njit(cache=True, error_model="numpy", inline="always")
def _rigid_body(p, u, body, thrust, K, N, A, rhs):
    """Mass matrix of B (zero elsewhere in ``A``) and the right-hand side of its Newton and Euler
    equations: external force, gravity and thrust (inertial); external moment, gyroscopic term and
    thrust moment (body). ``body``: a :data:`BodyMotion`; ``thrust``: a :data:`GimbalThrust`."""
    Cb = body.C_ib
    w0, w1, w2 = body.omega_b
    f0, f1, f2 = thrust.f_b
    re0, re1, re2 = thrust.r_b
    nr = at(SIZES.speeds, K, N)
    o_v = at(V.v_zw_i, K, N)
    o_w = at(V.omega_bi_b, K, N)
    o_J = at(P.J_b, K, N)
    m_b = p[at(P.m_b, K, N)]
    for i in range(nr):
        for k in range(nr):
            A[i, k] = 0.0
    for i in range(3):
        A[o_v + i, o_v + i] = m_b
        for k in range(3):
            A[o_w + i, o_w + k] = p[o_J + 3 * i + k]
    o_f = at(U.f_b_i, K, N)
    o_g = at(U.g_i, K, N)
    for i in range(3):
        rhs[o_v + i] = u[o_f + i] + m_b * u[o_g + i] + Cb[i, 0] * f0 + Cb[i, 1] * f1 + Cb[i, 2] * f2
    # Euler: m - omega x J omega + thrust moment
    Jw0 = p[o_J] * w0 + p[o_J + 1] * w1 + p[o_J + 2] * w2
    Jw1 = p[o_J + 3] * w0 + p[o_J + 4] * w1 + p[o_J + 5] * w2
    Jw2 = p[o_J + 6] * w0 + p[o_J + 7] * w1 + p[o_J + 8] * w2
    o_m = at(U.m_b_b, K, N)
    rhs[o_w] = u[o_m] - (w1 * Jw2 - w2 * Jw1) + (re1 * f2 - re2 * f1)
    rhs[o_w + 1] = u[o_m + 1] - (w2 * Jw0 - w0 * Jw2) + (re2 * f0 - re0 * f2)
    rhs[o_w + 2] = u[o_m + 2] - (w0 * Jw1 - w1 * Jw0) + (re0 * f1 - re1 * f0)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _modes(x, p, u, f1, f2, K, N, A, rhs):
    """Unit modal masses in ``A`` and the modal right-hand side: generalised forces, the thrust's
    through the mode shape at the gimbal, damping and stiffness (y-plane modes, then z)."""
    o_r = at(V.eta_dot, K, N)
    for i in range(2 * K):
        A[o_r + i, o_r + i] = 1.0
    o_om, o_ze, o_pg = at(P.omega_modes, K, N), at(P.zeta_modes, K, N), at(P.phi_gimbal, K, N)
    o_fe = at(U.f_eta, K, N)
    o_eta, o_etad = at(X.eta, K, N), at(X.eta_dot, K, N)
    for k in range(K):
        om = p[o_om + k]
        c = 2.0 * p[o_ze + k] * om
        kk = om * om
        pg = p[o_pg + k]
        rhs[o_r + k] = (u[o_fe + k] + pg * f1 - c * x[o_etad + k] - kk * x[o_eta + k])
        rhs[o_r + K + k] = (u[o_fe + K + k] + pg * f2 - c * x[o_etad + K + k]
                            - kk * x[o_eta + K + k])


@nb.njit(cache=True, error_model="numpy", inline="always")
def _eliminate_pendulum(j, x, p, u, K, N, body, scratch, nq):
    """Eliminate pendulum j by its Schur complement, per unit slosh mass: add its damper's reaction
    torque and ``m B^T C^T z`` to ``rhs``, collect its rank-one terms ``m s n n^T`` (and ``m (1 - s) I``
    for a slosh body with inertia) in ``work`` from term ``nq`` on, keep in its row ``j`` of ``slosh`` what
    the back-substitution needs (an inactive pendulum, ``m <= 0``, only its mass). ``body``: a
    :data:`BodyMotion`; ``scratch``: a :data:`PendulumWork` (``rhs``, ``h``, ``slosh``, ``work``). Returns the
    number of terms collected so far."""
    Cb, Cs = body.C_ib, scratch.C_is
    w0, w1, w2 = body.omega_b
    wi0, wi1, wi2 = body.omega_i
    cg0, cg1, cg2 = body.r_cg
    rhs, h, sw, work = scratch.rhs, scratch.h, scratch.slosh, scratch.work
    nr = at(SIZES.speeds, K, N)
    o = at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N)
    m = p[o + at(S.m, K, N)]
    sw[j, SW.m] = m
    if m <= 0.0:
        return nq
    L = p[o + at(S.length, K, N)]
    k2 = p[o + at(S.inertia, K, N)] / m
    sw[j, SW.length] = L
    sw[j, SW.k2] = k2
    qo = at(X.q_si, K, N) + j * X_PER_SLOSH.q_si
    quat_to_dcm(x[qo], x[qo + 1], x[qo + 2], x[qo + 3], Cs)
    for i in range(3):
        sw[j, SW.y_s + i] = Cs[i, 1]
        sw[j, SW.z_s + i] = Cs[i, 2]
    # deflected hinge offset from the CG and hinge deflection rate, body frame
    r0, r1, r2, vy, vz = hinge_offset(x, p, j, cg0, cg1, cg2, K, N)
    sw[j, SW.rho_b] = r0
    sw[j, SW.rho_b + 1] = r1
    sw[j, SW.rho_b + 2] = r2
    # bias acceleration of the mass: C [w x (w x rho) + 2 w x (Psi eta_dot)] + L |w_s|^2 n_i
    a0 = w1 * r2 - w2 * r1
    a1 = w2 * r0 - w0 * r2
    a2 = w0 * r1 - w1 * r0
    b0 = w1 * a2 - w2 * a1 + 2.0 * (w1 * vz - w2 * vy)
    b1 = w2 * a0 - w0 * a2 + 2.0 * (-w0 * vz)
    b2 = w0 * a1 - w1 * a0 + 2.0 * (w0 * vy)
    wo = at(X.omega_si_s, K, N) + j * X_PER_SLOSH.omega_si_s
    ws1 = x[wo]
    ws2 = x[wo + 1]
    cen = L * (ws1 * ws1 + ws2 * ws2)
    o_g = at(U.g_i, K, N)
    for i in range(3):
        beta = Cb[i, 0] * b0 + Cb[i, 1] * b1 + Cb[i, 2] * b2 + cen * Cs[i, 0]
        sw[j, SW.g_beta + i] = u[o_g + i] - beta
    # damper torque per unit slosh mass, s-frame (y, z): -c (w_s - omega_b components)
    cd = 2.0 * p[o + at(S.zeta, K, N)] * p[o + at(S.omega, K, N)] * L * L
    tau1 = -cd * (ws1 - (Cs[0, 1] * wi0 + Cs[1, 1] * wi1 + Cs[2, 1] * wi2))
    tau2 = -cd * (ws2 - (Cs[0, 2] * wi0 + Cs[1, 2] * wi1 + Cs[2, 2] * wi2))
    sw[j, SW.tau] = tau1
    sw[j, SW.tau + 1] = tau2
    # reaction torque on B, body frame: -m C^T (tau1 y_s + tau2 z_s)
    o_rw = at(V.omega_bi_b, K, N)
    for i in range(3):
        rhs[o_rw + i] -= m * (Cb[0, i] * (tau1 * Cs[0, 1] + tau2 * Cs[0, 2])
                              + Cb[1, i] * (tau1 * Cs[1, 1] + tau2 * Cs[1, 2])
                              + Cb[2, i] * (tau1 * Cs[2, 1] + tau2 * Cs[2, 2]))
    s = L * L / (L * L + k2)
    lam = L / (L * L + k2)
    # rod direction in body frame
    nb0 = Cb[0, 0] * Cs[0, 0] + Cb[1, 0] * Cs[1, 0] + Cb[2, 0] * Cs[2, 0]
    nb1 = Cb[0, 1] * Cs[0, 0] + Cb[1, 1] * Cs[1, 0] + Cb[2, 1] * Cs[2, 0]
    nb2 = Cb[0, 2] * Cs[0, 0] + Cb[1, 2] * Cs[1, 0] + Cb[2, 2] * Cs[2, 0]
    o_phi = o + at(S.phi, K, N)
    phi = p[o_phi:o_phi + K]
    # the rank-one terms c h h^T of A_r are collected (rows c h and h of work) and summed after
    # the loop, entry by entry in the same order: no load and store of A per pendulum
    _body_row_map(Cb, r0, r1, r2, phi, nb0, nb1, nb2, K, N, work[term_rows(nq)[1]])
    _scaled_row(work, nq, m * s, nr)
    nq += 1
    if s < 1.0:
        for r in range(3):
            _body_row_map(Cb, r0, r1, r2, phi, 1.0 if r == 0 else 0.0, 1.0 if r == 1 else 0.0,
                          1.0 if r == 2 else 0.0, K, N, work[term_rows(nq)[1]])
            _scaled_row(work, nq, m * (1.0 - s), nr)
            nq += 1
    # z = Q (g - beta) - lam (tau1 z_s - tau2 y_s), then rhs += m Bt^T C^T z
    gb0, gb1, gb2 = sw[j, SW.g_beta], sw[j, SW.g_beta + 1], sw[j, SW.g_beta + 2]
    nd = Cs[0, 0] * gb0 + Cs[1, 0] * gb1 + Cs[2, 0] * gb2
    z = work[at(WR.scratch, K, N)]
    for i in range(3):
        z[i] = ((1.0 - s) * sw[j, SW.g_beta + i] + s * nd * Cs[i, 0]
                - lam * (tau1 * Cs[i, 2] - tau2 * Cs[i, 1]))
    zb0 = Cb[0, 0] * z[0] + Cb[1, 0] * z[1] + Cb[2, 0] * z[2]
    zb1 = Cb[0, 1] * z[0] + Cb[1, 1] * z[1] + Cb[2, 1] * z[2]
    zb2 = Cb[0, 2] * z[0] + Cb[1, 2] * z[1] + Cb[2, 2] * z[2]
    _body_row_map(Cb, r0, r1, r2, phi, zb0, zb1, zb2, K, N, h)
    for i in range(nr):
        rhs[i] += m * h[i]
    return nq


@nb.njit(cache=True, error_model="numpy", inline="always")
def _solve(A, rhs, work, nq, K, N):
    """Add the collected rank-one terms to ``A`` and solve ``A_r u_dot = b`` in place: ``rhs`` then
    holds the accelerations of the speeds (:data:`.layout.SPEEDS`)."""
    nr = at(SIZES.speeds, K, N)
    _add_sym_outers(A, work, nq, nr)
    _cholesky_solve(A, rhs, nr)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _kinematics(x, rhs, w0, w1, w2, K, N, xdot):
    """The derivatives of the position, attitude and modal coordinates (kinematics) and of the rigid
    and elastic speeds (the solution ``rhs``)."""
    o_r = at(X.r_zw_i, K, N)
    o_v = at(X.v_zw_i, K, N)
    o_q = at(X.q_bi, K, N)
    o_w = at(X.omega_bi_b, K, N)
    o_eta, o_etad = at(X.eta, K, N), at(X.eta_dot, K, N)
    r_v, r_w, r_e = at(V.v_zw_i, K, N), at(V.omega_bi_b, K, N), at(V.eta_dot, K, N)
    for i in range(3):
        xdot[o_r + i] = x[o_v + i]
        xdot[o_v + i] = rhs[r_v + i]
        xdot[o_w + i] = rhs[r_w + i]
    _quat_rate(x, o_q, w0, w1, w2, xdot, o_q)
    for k in range(2 * K):
        xdot[o_eta + k] = x[o_etad + k]
        xdot[o_etad + k] = rhs[r_e + k]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _pendulum_accelerations(x, p, rhs, Cb, sw, K, N, xdot):
    """Back-substitution: each pendulum's angular acceleration from the hinge acceleration and the
    quantities its elimination kept, and its attitude rate (an inactive pendulum's state is frozen)."""
    r_v, r_w, r_e = at(V.v_zw_i, K, N), at(V.omega_bi_b, K, N), at(V.eta_dot, K, N)
    wd0, wd1, wd2 = rhs[r_w], rhs[r_w + 1], rhs[r_w + 2]
    for j in range(N):
        qo = at(X.q_si, K, N) + j * X_PER_SLOSH.q_si
        wo = at(X.omega_si_s, K, N) + j * X_PER_SLOSH.omega_si_s
        if sw[j, SW.m] <= 0.0:
            for i in range(4):
                xdot[qo + i] = 0.0
            xdot[wo] = 0.0
            xdot[wo + 1] = 0.0
            continue
        o_phi = at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N) + at(S.phi, K, N)
        L = sw[j, SW.length]
        k2 = sw[j, SW.k2]
        r0, r1, r2 = sw[j, SW.rho_b], sw[j, SW.rho_b + 1], sw[j, SW.rho_b + 2]
        ey = ez = 0.0
        for k in range(K):
            ph = p[o_phi + k]
            ey += ph * rhs[r_e + k]
            ez += ph * rhs[r_e + K + k]
        # hinge acceleration (without bias), body frame: C^T v_dot + omega_dot x rho + Psi eta_ddot
        hb0 = wd1 * r2 - wd2 * r1
        hb1 = wd2 * r0 - wd0 * r2 + ey
        hb2 = wd0 * r1 - wd1 * r0 + ez
        dy = dz = 0.0
        for i in range(3):
            ai = rhs[r_v + i] + Cb[i, 0] * hb0 + Cb[i, 1] * hb1 + Cb[i, 2] * hb2
            d = sw[j, SW.g_beta + i] - ai
            dy += sw[j, SW.y_s + i] * d
            dz += sw[j, SW.z_s + i] * d
        den = L * L + k2
        xdot[wo] = (L * dz + sw[j, SW.tau]) / den
        xdot[wo + 1] = (-L * dy + sw[j, SW.tau + 1]) / den
        _quat_rate(x, qo, 0.0, x[wo], x[wo + 1], xdot, qo)


# ---------------------------------------------------------------------------- the equations of motion
@nb.njit(cache=True, error_model="numpy")
def vehicle_deriv(x, p, u, xdot, ws):
    """Time derivative ``xdot`` of one vehicle's state ``x`` for parameters ``p`` and loads ``u``
    (layouts :data:`.layout.STATE`, :data:`.layout.PARAMS`, :data:`.layout.LOADS` for ``ws.n_modes``
    modes per plane and ``ws.n_slosh`` pendulums), with the scratch ``ws``, a :data:`DerivWork` (the
    part ``deriv`` of the stepper's ``Workspace``; any contents). Only the state's fields of ``xdot`` are
    written.

    The arrays are used through :func:`unowned` views (the caller holds them for the call): numba
    would otherwise count references to them across the inlined steps, with atomic instructions."""
    K = ws.n_modes
    N = ws.n_slosh
    x, p, u, xdot = unowned(x), unowned(p), unowned(u), unowned(xdot)
    A, rhs, h, sw, work = unowned(ws.A), unowned(ws.rhs), unowned(ws.h), unowned(ws.slosh), unowned(ws.work)
    C = unowned(ws.C)
    Cb, Cs = C[AT.C_ib], C[AT.C_is]
    o_q = at(X.q_bi, K, N)
    quat_to_dcm(x[o_q], x[o_q + 1], x[o_q + 2], x[o_q + 3], Cb)
    o_w = at(X.omega_bi_b, K, N)
    w0, w1, w2 = x[o_w], x[o_w + 1], x[o_w + 2]
    o_cg = at(P.r_cg, K, N)
    cg0, cg1, cg2 = p[o_cg], p[o_cg + 1], p[o_cg + 2]
    # the body rate in inertial components, for the pendulums' dampers
    wi0 = Cb[0, 0] * w0 + Cb[0, 1] * w1 + Cb[0, 2] * w2
    wi1 = Cb[1, 0] * w0 + Cb[1, 1] * w1 + Cb[1, 2] * w2
    wi2 = Cb[2, 0] * w0 + Cb[2, 1] * w1 + Cb[2, 2] * w2
    body = BodyMotion(Cb, (w0, w1, w2), (wi0, wi1, wi2), (cg0, cg1, cg2))
    # loads, rigid body and modes
    thrust = _gimbal_thrust(x, p, u, cg0, cg1, cg2, K, N)
    _rigid_body(p, u, body, thrust, K, N, A, rhs)
    _, f1, f2 = thrust.f_b
    _modes(x, p, u, f1, f2, K, N, A, rhs)
    # slosh pendulums, eliminated one by one
    scratch = PendulumWork(Cs, rhs, h, sw, work)
    nq = 0                                  # rank-one terms of A_r collected in work
    for j in range(N):
        nq = _eliminate_pendulum(j, x, p, u, K, N, body, scratch, nq)
    # the reduced system, then the back-substitution
    _solve(A, rhs, work, nq, K, N)
    _kinematics(x, rhs, w0, w1, w2, K, N, xdot)
    _pendulum_accelerations(x, p, rhs, Cb, sw, K, N, xdot)
