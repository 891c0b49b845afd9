"""The compiled period of the MPC (:mod:`.mpc`) for any number of rows: the inner loop of :class:`.mpc.MPCLaw`.

Per plane and row, :func:`mpc_plan_k` does what needs no solver: the engagement restart, the schedule row by
flight time and the carry of the estimate at a switch (as :func:`.lqgkernel.lqg_step_k`), the measurement
update, the unconstrained plan ``U = gain z0`` (``z0``: the filtered state and the integral) and its check
against the gimbal's angle and rate limits (:meth:`.mpcqp.CondensedQP.feasible`). A row whose plan meets
them is finished here (:func:`_finish`: the command ``U_0``, the integral, the time update); the others are
left to the QP (:meth:`.mpcqp.CondensedQP.qp`, OSQP, one call per such row) and finished by
:func:`mpc_finish_k` with its command. Each row's sums are its own, in a fixed order, so a batch of one gives
the bits of the same row of any batch. The blocks: :class:`PlanTables` (per schedule row its plan's gain and,
for the servo-rate form, the servo's predicted rates), :class:`Limits` and :class:`MPCState`.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from .lqgkernel import row_index

__all__ = ["DONE", "OFF", "QP", "Limits", "MPCState", "PlanTables", "mpc_finish_k", "mpc_plan_k"]

#: what :func:`mpc_plan_k` left a row: the law off (command 0), the period done, the QP to solve
OFF, DONE, QP = 0, 1, 2


class PlanTables(NamedTuple):
    """Per schedule row ``i`` (R rows, N states padded, plans of H periods): ``gain`` (R, H, N + 1) the
    unconstrained plan's gain on ``z0 = (x_f[:dim_i], xi)`` (the integral at index ``dim_i``); ``Pr`` (R, H,
    N + 1) and ``Gr`` (R, H, H) the servo's predicted rates ``Pr z0 + Gr U`` (zeros in the command form)."""

    gain: np.ndarray
    Pr: np.ndarray
    Gr: np.ndarray


class Limits(NamedTuple):
    """``servo``: the rate limit on the model's servo rate (else on the command); ``limit`` [rad] the gimbal
    limit; ``rate`` [rad/s] the servo's rate limit; ``rate_step`` [rad] its change per period."""

    servo: bool
    limit: float
    rate: float
    rate_step: float


class MPCState(NamedTuple):
    """One plane's rows: ``x`` (n, N) the predicted state, ``xi`` (n,) the integral, ``row`` (n,) the schedule
    row in use (-1 since the last engagement), ``was_on``, ``saturated`` (n,) bool, ``u`` (n,) the last command
    [rad], ``warm`` (n, H) the last plan [gimbal limits] and ``has_warm`` (n,) bool (the QP's warm start)."""

    x: np.ndarray
    xi: np.ndarray
    row: np.ndarray
    was_on: np.ndarray
    saturated: np.ndarray
    u: np.ndarray
    warm: np.ndarray
    has_warm: np.ndarray


@nb.njit(cache=True)
def _finish(tb, pt, lim, st, b, y, z0, u, v):
    """The end of row ``b``'s period with the command ``u`` sent and ``v`` the unconstrained one [rad]: the
    integral (held while a limit holds the command and it would push further) and the time update."""
    i = st.row[b]
    m = tb.dim[i]
    sat = abs(u - v) > 1e-9 * lim.limit
    dxi = (tb.a[i] - 1.0) * st.xi[b] - tb.dt[i] * y
    if not (sat and (v - u) * (pt.gain[i, 0, m] * dxi) > 0.0):
        st.xi[b] += dxi
    for r in range(m):
        acc = 0.0
        for k in range(m):
            acc += tb.A[i, r, k] * z0[k]
        st.x[b, r] = acc + tb.B[i, r] * u
    st.saturated[b] = sat
    st.u[b] = u


@nb.njit(cache=True)
def mpc_plan_k(tb, pt, lim, st, which, y, t, on, z0, v, status):
    """Rows ``which`` (k,) of one plane (``tb``: its :class:`.lqgkernel.LQGTables`; ``pt``: :class:`PlanTables`;
    ``lim``: :class:`Limits`; ``st``: :class:`MPCState`) with their gyro samples ``y`` (k,) [rad/s] at flight
    times ``t`` (k,) [s], on where ``on``: ``status`` (k,) :data:`OFF`, :data:`DONE` (its command in
    ``st.u``) or :data:`QP` (its ``z0`` (k, N + 1) and unconstrained first move ``v`` (k,) [rad] for the QP)."""
    N = tb.A.shape[1]
    H = pt.gain.shape[1]
    old = np.empty(N)
    U = np.empty(H)
    for j in range(which.size):
        b = which[j]
        if not on[j]:
            st.was_on[b], st.saturated[b], st.u[b] = False, False, 0.0
            status[j] = OFF
            continue
        if not st.was_on[b]:                      # engagement: restart from zero
            st.row[b] = -1
            st.x[b, :] = 0.0
            st.xi[b] = 0.0
            st.u[b] = 0.0
            st.has_warm[b] = False
        st.was_on[b] = True
        i = row_index(tb, t[j])
        if i != st.row[b]:
            o = st.row[b]
            old[:] = st.x[b, :]
            for k in range(N):
                src = tb.carry[o, i, k] if o >= 0 else -1
                st.x[b, k] = old[src] if src >= 0 else 0.0
            st.row[b] = i
            st.has_warm[b] = False
        m = tb.dim[i]
        cx = 0.0
        for k in range(m):
            cx += tb.C[i, k] * st.x[b, k]
        innov = y[j] - cx
        for k in range(m):
            z0[j, k] = st.x[b, k] + tb.M[i, k] * innov
        z0[j, m] = st.xi[b]
        for h in range(H):
            acc = 0.0
            for k in range(m + 1):
                acc += pt.gain[i, h, k] * z0[j, k]
            U[h] = acc
        v[j] = U[0]
        ok = True
        tol = 1e-12 * lim.limit
        for h in range(H):
            if not abs(U[h]) <= lim.limit + tol:
                ok = False
        if ok and lim.servo:
            for h in range(H):
                rate = 0.0
                for k in range(m + 1):
                    rate += pt.Pr[i, h, k] * z0[j, k]
                for g in range(H):
                    rate += pt.Gr[i, h, g] * U[g]
                if not abs(rate) <= lim.rate * (1 + 1e-12):
                    ok = False
        elif ok:
            prev = st.u[b]
            for h in range(H):
                if not abs(U[h] - prev) <= lim.rate_step + tol:
                    ok = False
                prev = U[h]
        if not ok:
            status[j] = QP
            continue
        for h in range(H):
            st.warm[b, h] = U[h] / lim.limit
        st.has_warm[b] = True
        _finish(tb, pt, lim, st, b, y[j], z0[j], U[0], U[0])
        status[j] = DONE


@nb.njit(cache=True)
def mpc_finish_k(tb, pt, lim, st, which, y, z0, u, v):
    """The end of the period of the rows ``which`` (k,) the QP solved: their commands ``u`` (k,) [rad] sent,
    ``v`` (k,) the unconstrained first moves (:func:`_finish`)."""
    for j in range(which.size):
        _finish(tb, pt, lim, st, which[j], y[j], z0[j], u[j], v[j])
