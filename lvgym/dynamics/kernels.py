"""Compiled equations of motion of the non-rigid vehicle (thesis chapter 2).

One vehicle: a rigid body B (6 DOF), K bending modes per plane (assumed modes, mean axes,
mass-normalised), and N slosh pendulums whose hinge is fixed to the deflected attachment node.
The coupled equations are those of the null-space method (thesis eq. 2.41-2.52)::

    A u_dot = b,   A = Y^T M Y,   b = Y^T (f - M Ydot u - D Y u - K q - f_non)

with the independent speeds ``u = [v_zw_i, omega_bi_b, eta_dot, w_1 .. w_N]``. The pendulum speeds
``w_j`` are the two components of the pendulum angular velocity normal to its rod: a point mass has
no rotation about the rod, so the rod-axis speed of the thesis's 3-DOF slosh body (which makes A
singular for a point mass, DESIGN.md note 3) is not a coordinate. The pendulum attitude is a
quaternion, regular through 90 degrees and in free tumbling.

A is assembled blockwise: each pendulum's 2x2 block ``(m L^2 + J) I`` is eliminated by its Schur
complement, written per unit slosh mass, so the reduced matrix ``A_r = M_r + sum m_j B_j^T Q_j B_j``
of the rigid and elastic speeds stays regular for point masses and for a slosh mass going to zero,
and costs a rank-one update per point-mass pendulum. ``B_j`` maps the rigid/elastic speeds to the
hinge velocity, ``Q_j = (1 - s_j) I + s_j n_j n_j^T`` with ``s_j = L^2 / (L^2 + J/m)`` (the rod
projector ``n n^T`` for a point mass: the rod transmits tension only).

Everything here is plain loops over small arrays compiled with numba; a batch is a loop over the
same per-vehicle kernel, so one code path serves one vehicle and many.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from lvgym.rotations import quat_to_dcm

# offsets of the fixed-size parts of the flat vectors (layout.py; tests/test_layout_and_params.py
# checks that the two agree)
X_R, X_V, X_Q, X_W, X_ETA = 0, 3, 6, 10, 13
P_M, P_CG, P_J, P_GIM, P_MODES = 0, 1, 4, 13, 16
U_F, U_M, U_T, U_G, U_ETA = 0, 3, 6, 9, 12
# per-slosh work row kept for the back-substitution: y_s(3) z_s(3) rho_b(3) (g - beta)_i(3) tau(2) m L k2
_S_Y, _S_Z, _S_RHO, _S_GB, _S_TAU, _S_M, _S_L, _S_K2 = 0, 3, 6, 9, 12, 14, 15, 16
SLOSH_WORK = 17


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
def _scaled_row(G, q, c, n):
    """Rank-one term ``q`` of :func:`_add_sym_outers`: ``G[1 + 2q] = c G[2 + 2q]`` (first n entries)."""
    for i in range(n):
        G[1 + 2 * q, i] = c * G[2 + 2 * q, i]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _add_sym_outers(A, G, nq, n):
    """``A += sum_q c_q h_q h_q^T`` on the lower triangle of the leading n x n block, with ``c_q h_q``
    and ``h_q`` in the rows ``1 + 2q`` and ``2 + 2q`` of ``G``; each entry is summed in a register in
    the order of q (the same sums as nq successive rank-one updates)."""
    for i in range(n):
        for q in range(nq):
            ci = G[1 + 2 * q, i]
            for k in range(i + 1):
                A[i, k] += ci * G[2 + 2 * q, k]


@nb.njit(cache=True, error_model="numpy", inline="always")
def _body_row_map(C, rho0, rho1, rho2, phi, a0, a1, a2, K, h):
    """``h = Bt^T a_b`` for a body-frame vector ``a_b`` at a node with offset rho from the CG and
    mode shape phi: ``h = [C a_b, rho x a_b, phi a_b,y, phi a_b,z]`` (the transpose of the map from
    rigid and elastic speeds to the node velocity)."""
    h[0] = C[0, 0] * a0 + C[0, 1] * a1 + C[0, 2] * a2
    h[1] = C[1, 0] * a0 + C[1, 1] * a1 + C[1, 2] * a2
    h[2] = C[2, 0] * a0 + C[2, 1] * a1 + C[2, 2] * a2
    h[3] = rho1 * a2 - rho2 * a1
    h[4] = rho2 * a0 - rho0 * a2
    h[5] = rho0 * a1 - rho1 * a0
    for k in range(K):
        h[6 + k] = phi[k] * a1
        h[6 + K + k] = phi[k] * a2


@nb.njit(cache=True, error_model="numpy")
def vehicle_deriv(x, p, u, n_slosh, n_modes, xdot, A, rhs, h, C, S, work):
    """Time derivative ``xdot`` of one vehicle's state ``x`` for parameters ``p`` and loads ``u``.

    Work arrays (any contents; sized by the caller, see ``make_workspace``): ``A`` (n_r, n_r),
    ``rhs`` and ``h`` (n_r,), ``C`` (2, 3, 3), ``S`` (max(N, 1), SLOSH_WORK), ``work`` (1 + 8N,
    max(n_r, 3)), with ``n_r = 6 + 2K``.
    """
    K = n_modes
    N = n_slosh
    nr = 6 + 2 * K
    Cb = C[0]
    Cs = C[1]
    quat_to_dcm(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3], Cb)
    w0, w1, w2 = x[X_W], x[X_W + 1], x[X_W + 2]
    o_eta = X_ETA
    o_etad = X_ETA + 2 * K
    o_qs = X_ETA + 4 * K
    o_ws = o_qs + 4 * N
    o_om = P_MODES
    o_ze = P_MODES + K
    o_pg = P_MODES + 2 * K
    o_dg = P_MODES + 3 * K
    o_sl = P_MODES + 4 * K
    sb = 8 + K
    m_b = p[P_M]
    cgx, cgy, cgz = p[P_CG], p[P_CG + 1], p[P_CG + 2]

    # ---------------------------------------------------------------- mass matrix of B and modes
    for i in range(nr):
        for k in range(nr):
            A[i, k] = 0.0
    for i in range(3):
        A[i, i] = m_b
        for k in range(3):
            A[3 + i, 3 + k] = p[P_J + 3 * i + k]
    for i in range(6, nr):
        A[i, i] = 1.0

    # ---------------------------------------------------------------- thrust at the deflected gimbal
    sy = 0.0
    sz = 0.0
    dy = 0.0
    dz = 0.0
    for k in range(K):
        sy += p[o_dg + k] * x[o_eta + k]
        sz += p[o_dg + k] * x[o_eta + K + k]
        dy += p[o_pg + k] * x[o_eta + k]
        dz += p[o_pg + k] * x[o_eta + K + k]
    # rotate the engine-frame thrust by theta = (0, -sz, sy) (Rodrigues)
    t0, t1, t2 = u[U_T], u[U_T + 1], u[U_T + 2]
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
    rex = p[P_GIM] - cgx
    rey = p[P_GIM + 1] - cgy + dy
    rez = p[P_GIM + 2] - cgz + dz

    # ---------------------------------------------------------------- right-hand side of B and modes
    for i in range(3):
        rhs[i] = u[U_F + i] + m_b * u[U_G + i] + Cb[i, 0] * f0 + Cb[i, 1] * f1 + Cb[i, 2] * f2
    # Euler: m - omega x J omega + thrust moment
    Jw0 = p[P_J] * w0 + p[P_J + 1] * w1 + p[P_J + 2] * w2
    Jw1 = p[P_J + 3] * w0 + p[P_J + 4] * w1 + p[P_J + 5] * w2
    Jw2 = p[P_J + 6] * w0 + p[P_J + 7] * w1 + p[P_J + 8] * w2
    rhs[3] = u[U_M] - (w1 * Jw2 - w2 * Jw1) + (rey * f2 - rez * f1)
    rhs[4] = u[U_M + 1] - (w2 * Jw0 - w0 * Jw2) + (rez * f0 - rex * f2)
    rhs[5] = u[U_M + 2] - (w0 * Jw1 - w1 * Jw0) + (rex * f1 - rey * f0)
    for k in range(K):
        om = p[o_om + k]
        c = 2.0 * p[o_ze + k] * om
        kk = om * om
        pg = p[o_pg + k]
        rhs[6 + k] = (u[U_ETA + k] + pg * f1 - c * x[o_etad + k] - kk * x[o_eta + k])
        rhs[6 + K + k] = (u[U_ETA + K + k] + pg * f2 - c * x[o_etad + K + k]
                          - kk * x[o_eta + K + k])

    # ---------------------------------------------------------------- slosh pendulums (Schur complement)
    # body rate in inertial components
    wi0 = Cb[0, 0] * w0 + Cb[0, 1] * w1 + Cb[0, 2] * w2
    wi1 = Cb[1, 0] * w0 + Cb[1, 1] * w1 + Cb[1, 2] * w2
    wi2 = Cb[2, 0] * w0 + Cb[2, 1] * w1 + Cb[2, 2] * w2
    nq = 0                                  # rank-one terms of A_r collected in work
    for j in range(N):
        o = o_sl + j * sb
        m = p[o]
        S[j, _S_M] = m
        if m <= 0.0:
            continue
        L = p[o + 1]
        k2 = p[o + 2] / m
        S[j, _S_L] = L
        S[j, _S_K2] = k2
        qo = o_qs + 4 * j
        quat_to_dcm(x[qo], x[qo + 1], x[qo + 2], x[qo + 3], Cs)
        for i in range(3):
            S[j, _S_Y + i] = Cs[i, 1]
            S[j, _S_Z + i] = Cs[i, 2]
        # deflected hinge offset from the CG and hinge deflection rate, body frame
        py = 0.0
        pz = 0.0
        vy = 0.0
        vz = 0.0
        for k in range(K):
            ph = p[o + 8 + k]
            py += ph * x[o_eta + k]
            pz += ph * x[o_eta + K + k]
            vy += ph * x[o_etad + k]
            vz += ph * x[o_etad + K + k]
        r0 = p[o + 3] - cgx
        r1 = p[o + 4] - cgy + py
        r2 = p[o + 5] - cgz + pz
        S[j, _S_RHO] = r0
        S[j, _S_RHO + 1] = r1
        S[j, _S_RHO + 2] = r2
        # bias acceleration of the mass: C [w x (w x rho) + 2 w x (Psi eta_dot)] + L |w_s|^2 n_i
        a0 = w1 * r2 - w2 * r1
        a1 = w2 * r0 - w0 * r2
        a2 = w0 * r1 - w1 * r0
        b0 = w1 * a2 - w2 * a1 + 2.0 * (w1 * vz - w2 * vy)
        b1 = w2 * a0 - w0 * a2 + 2.0 * (-w0 * vz)
        b2 = w0 * a1 - w1 * a0 + 2.0 * (w0 * vy)
        ws1 = x[o_ws + 2 * j]
        ws2 = x[o_ws + 2 * j + 1]
        cen = L * (ws1 * ws1 + ws2 * ws2)
        for i in range(3):
            beta = Cb[i, 0] * b0 + Cb[i, 1] * b1 + Cb[i, 2] * b2 + cen * Cs[i, 0]
            S[j, _S_GB + i] = u[U_G + i] - beta
        # damper torque per unit slosh mass, s-frame (y, z): -c (w_s - omega_b components)
        cd = 2.0 * p[o + 6] * p[o + 7] * L * L
        tau1 = -cd * (ws1 - (Cs[0, 1] * wi0 + Cs[1, 1] * wi1 + Cs[2, 1] * wi2))
        tau2 = -cd * (ws2 - (Cs[0, 2] * wi0 + Cs[1, 2] * wi1 + Cs[2, 2] * wi2))
        S[j, _S_TAU] = tau1
        S[j, _S_TAU + 1] = tau2
        # reaction torque on B, body frame: -m C^T (tau1 y_s + tau2 z_s)
        for i in range(3):
            rhs[3 + i] -= m * (Cb[0, i] * (tau1 * Cs[0, 1] + tau2 * Cs[0, 2])
                               + Cb[1, i] * (tau1 * Cs[1, 1] + tau2 * Cs[1, 2])
                               + Cb[2, i] * (tau1 * Cs[2, 1] + tau2 * Cs[2, 2]))
        s = L * L / (L * L + k2)
        lam = L / (L * L + k2)
        # rod direction in body frame
        nb0 = Cb[0, 0] * Cs[0, 0] + Cb[1, 0] * Cs[1, 0] + Cb[2, 0] * Cs[2, 0]
        nb1 = Cb[0, 1] * Cs[0, 0] + Cb[1, 1] * Cs[1, 0] + Cb[2, 1] * Cs[2, 0]
        nb2 = Cb[0, 2] * Cs[0, 0] + Cb[1, 2] * Cs[1, 0] + Cb[2, 2] * Cs[2, 0]
        phi = p[o + 8:o + 8 + K]
        # the rank-one terms c h h^T of A_r are collected (rows c h and h of work) and summed after
        # the loop, entry by entry in the same order: no load and store of A per pendulum
        _body_row_map(Cb, r0, r1, r2, phi, nb0, nb1, nb2, K, work[2 + 2 * nq])
        _scaled_row(work, nq, m * s, nr)
        nq += 1
        if s < 1.0:
            for r in range(3):
                _body_row_map(Cb, r0, r1, r2, phi, 1.0 if r == 0 else 0.0,
                              1.0 if r == 1 else 0.0, 1.0 if r == 2 else 0.0, K, work[2 + 2 * nq])
                _scaled_row(work, nq, m * (1.0 - s), nr)
                nq += 1
        # z = Q (g - beta) - lam (tau1 z_s - tau2 y_s), then rhs += m Bt^T C^T z
        gb0, gb1, gb2 = S[j, _S_GB], S[j, _S_GB + 1], S[j, _S_GB + 2]
        nd = Cs[0, 0] * gb0 + Cs[1, 0] * gb1 + Cs[2, 0] * gb2
        z = work[0]
        for i in range(3):
            z[i] = ((1.0 - s) * S[j, _S_GB + i] + s * nd * Cs[i, 0]
                    - lam * (tau1 * Cs[i, 2] - tau2 * Cs[i, 1]))
        zb0 = Cb[0, 0] * z[0] + Cb[1, 0] * z[1] + Cb[2, 0] * z[2]
        zb1 = Cb[0, 1] * z[0] + Cb[1, 1] * z[1] + Cb[2, 1] * z[2]
        zb2 = Cb[0, 2] * z[0] + Cb[1, 2] * z[1] + Cb[2, 2] * z[2]
        _body_row_map(Cb, r0, r1, r2, phi, zb0, zb1, zb2, K, h)
        for i in range(nr):
            rhs[i] += m * h[i]

    # ---------------------------------------------------------------- solve the reduced system
    _add_sym_outers(A, work, nq, nr)
    _cholesky_solve(A, rhs, nr)
    # rhs now holds [v_dot_i, omega_dot_b, eta_ddot]

    # ---------------------------------------------------------------- kinematics and outputs
    for i in range(3):
        xdot[X_R + i] = x[X_V + i]
        xdot[X_V + i] = rhs[i]
        xdot[X_W + i] = rhs[3 + i]
    _quat_rate(x, X_Q, w0, w1, w2, xdot, X_Q)
    for k in range(2 * K):
        xdot[o_eta + k] = x[o_etad + k]
        xdot[o_etad + k] = rhs[6 + k]

    # ---------------------------------------------------------------- pendulum accelerations
    wd0, wd1, wd2 = rhs[3], rhs[4], rhs[5]
    for j in range(N):
        qo = o_qs + 4 * j
        wo = o_ws + 2 * j
        if S[j, _S_M] <= 0.0:
            for i in range(4):
                xdot[qo + i] = 0.0
            xdot[wo] = 0.0
            xdot[wo + 1] = 0.0
            continue
        o = o_sl + j * sb
        L = S[j, _S_L]
        k2 = S[j, _S_K2]
        r0, r1, r2 = S[j, _S_RHO], S[j, _S_RHO + 1], S[j, _S_RHO + 2]
        ey = 0.0
        ez = 0.0
        for k in range(K):
            ph = p[o + 8 + k]
            ey += ph * rhs[6 + k]
            ez += ph * rhs[6 + K + k]
        # hinge acceleration (without bias), body frame: C^T v_dot + omega_dot x rho + Psi eta_ddot
        hb0 = wd1 * r2 - wd2 * r1
        hb1 = wd2 * r0 - wd0 * r2 + ey
        hb2 = wd0 * r1 - wd1 * r0 + ez
        dy = 0.0
        dz = 0.0
        for i in range(3):
            ai = rhs[i] + Cb[i, 0] * hb0 + Cb[i, 1] * hb1 + Cb[i, 2] * hb2
            d = S[j, _S_GB + i] - ai
            dy += S[j, _S_Y + i] * d
            dz += S[j, _S_Z + i] * d
        den = L * L + k2
        xdot[wo] = (L * dz + S[j, _S_TAU]) / den
        xdot[wo + 1] = (-L * dy + S[j, _S_TAU + 1]) / den
        _quat_rate(x, qo, 0.0, x[wo], x[wo + 1], xdot, qo)


@nb.njit(cache=True, error_model="numpy")
def make_workspace(n_slosh, n_modes):
    """Allocate the work arrays of ``vehicle_deriv``: (A, rhs, h, C, S, work)."""
    nr = 6 + 2 * n_modes
    return (np.empty((nr, nr)), np.empty(nr), np.empty(nr), np.empty((2, 3, 3)),
            np.zeros((max(n_slosh, 1), SLOSH_WORK)), np.empty((1 + 8 * n_slosh, max(nr, 3))))
