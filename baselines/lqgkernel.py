"""The compiled step of the LQG law (:mod:`.lqg`) for any number of rows: one row for a benchmark policy,
all the env rows of a residual policy's baselines in training. One code path for both.

The schedule's rows are stacked, zero-padded to the largest state (:class:`LQGTables`, built once per
schedule and plane by :func:`lqg_tables`); a law's state is :class:`LQGState` (``x``: the predicted
state ``x_p`` per row in the first ``dim`` entries of the row in use; ``xi``: the integral; ``row``: the schedule
row in use, -1 since the last engagement; ``was_on``; ``saturated``; ``u``: the last command sent [rad];
``e0``: the attitude error sample at the last engagement [rad]).
:func:`lqg_step_k` is the module docstring of :mod:`.lqg` row by row::

    x_f = x_p + M (y - C x_p);  v = -K_x x_f - K_i xi;  u = clip(v);  xi <- a xi - dt s (held while clipped
    and pushing further);  x_p <- A x_f + B u

where the integral's input ``s`` is the row's ``source`` (:data:`INTEGRAL_SOURCES`): the gyro sample ``y``
(``lqg``: the rate error, with a leak ``a < 1``) or the attitude error sample ``e`` [rad] (``lqi``: the
strapdown attitude error, a pure integral ``a = 1``) or that error less its value at the engagement,
``e - e_0`` (``lqi-hold``: the attitude the vehicle holds when the law engages is its reference, as ``lqg``'s rate
integral holds it); its leak ``a`` is the row's too. A row integrating the attitude also takes the measured
attitude (less ``e_0`` for the third source) for the estimate's attitude state after the measurement update,
``x_f[att] = e`` (the strapdown attitude is the better estimate: its error grows with the gyro's random walk,
0.02 deg over the flight, where the rate-only filter's attitude drifts with every unmodelled moment, and the
integral would hold the regulator's attitude gain times that drift). One law, one code path.

with the engagement restart, the schedule row chosen by flight time (the row whose interval holds it,
else the nearest) and, at a switch, the states both rows name carried (``carry``) and the others zeroed. The
integral is carried too: the rate's as it is (``lqg``), the attitude's by its command ``K_i xi`` (``xi`` scaled by
the old row's ``K_i`` over the new one's). The pure integral holds the trim a constant moment asks for, and the
rows' ``K_i`` differ by up to five times: carried as it is, a switch would step the command by that much (a
q-alpha failure at the 32.4 s switch on validation seed 0 of smile-v2-faults before this).

Anti-windup (:class:`AntiWindup`, the ``lqg-aw`` policy; ``lqg`` flies :data:`NO_ANTI_WINDUP`, which leaves
the law above unchanged): the command is also held to ``rate_step`` [rad] from the last one (the servo's rate
limit times the control period), so that the filter's time update carries the command the servo can follow,
and the integral is back-calculated instead of held: ``xi <- a xi - dt y + back_gain (v - u) / K_i``, which
moves the unclipped output ``v`` towards the command sent by the fraction ``back_gain`` per period.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba as nb
import numpy as np

from .pidkernel import clip_k

__all__ = ["INTEGRAL_SOURCES", "NO_ANTI_WINDUP", "AntiWindup", "LQGState", "LQGTables", "from_engagement", "lqg_act_k",
           "lqg_step_k", "lqg_tables", "row_index"]


class LQGTables(NamedTuple):
    """One plane's schedule, R rows padded to N states: ``A`` (R, N, N), ``B``, ``C``, ``Kx``, ``M`` (R, N),
    ``Ki``, ``a``, ``dt`` (R,), ``dim`` (R,) the row's own state count, ``lo``, ``hi`` (R,) its interval [s],
    ``carry`` (R, R, N): at a switch from row ``o`` to row ``i`` the new state ``k`` takes the old state
    ``carry[o, i, k]`` (-1: zero); ``source`` (R,) the integral's input (:data:`INTEGRAL_SOURCES` index); ``att`` (R,)
    the index of the attitude state (``theta_y``, ``theta_z``) of a row integrating the attitude (-1: none)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    Kx: np.ndarray
    M: np.ndarray
    Ki: np.ndarray
    a: np.ndarray
    dt: np.ndarray
    dim: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    carry: np.ndarray
    source: np.ndarray
    att: np.ndarray


class LQGState(NamedTuple):
    """The state of ``n`` rows of one plane's law (module docstring)."""

    x: np.ndarray
    xi: np.ndarray
    row: np.ndarray
    was_on: np.ndarray
    saturated: np.ndarray
    u: np.ndarray
    e0: np.ndarray


class AntiWindup(NamedTuple):
    """The anti-windup of the law (module docstring): ``on`` (False: the plain law of ``lqg``), the
    largest change of the command per period ``rate_step`` [rad] and the back-calculation gain
    ``back_gain`` [-] per period (0: the integral is held as in ``lqg``)."""

    on: bool
    rate_step: float
    back_gain: float


#: what the integral of a row integrates (index in :data:`LQGTables`' ``source``): the rate error (the gyro
#: sample ``y`` [rad/s]), the attitude error (the observation's strapdown attitude error ``e`` [rad]) or the
#: attitude error from the engagement (``e - e_0``, ``e_0`` its sample at the engagement; a schedule's rows
#: name the first two, a law flies a schedule of the second with the third: :func:`from_engagement`)
INTEGRAL_SOURCES = ("rate", "attitude", "attitude-from-engagement")

#: the plain law (``lqg``): the command clipped to the gimbal limit only, the integral held while clipped
NO_ANTI_WINDUP = AntiWindup(False, np.inf, 0.0)


def lqg_tables(rows: Any) -> LQGTables:
    """The stacked tables of a plane's :class:`.lqg.LQGRow` sequence (carry maps from the state labels:
    identical labels carry every state; otherwise a state named once in the new row takes the old state
    of that name; ``source``: each row's ``integral``, :data:`INTEGRAL_SOURCES`)."""
    R, N = len(rows), max(r.A.shape[0] for r in rows)
    A, (B, C, Kx, M) = np.zeros((R, N, N)), (np.zeros((R, N)) for _ in range(4))
    carry = np.full((R, R, N), -1, dtype=np.int64)
    for i, r in enumerate(rows):
        m = r.A.shape[0]
        A[i, :m, :m], B[i, :m], C[i, :m], Kx[i, :m], M[i, :m] = r.A, r.B[:, 0], r.C[0], r.Kx[0], r.M[:, 0]
        for o, old in enumerate(rows):
            if old.labels == r.labels:
                carry[o, i, :m] = np.arange(m)
                continue
            where = {name: k for k, name in enumerate(old.labels)}
            for k, name in enumerate(r.labels):
                if name in where and r.labels.count(name) == 1:
                    carry[o, i, k] = where[name]
    return LQGTables(A, B, C, Kx, M, np.array([r.Ki for r in rows]), np.array([r.a for r in rows]),
                     np.array([r.dt for r in rows]), np.array([r.A.shape[0] for r in rows], dtype=np.int64),
                     np.array([r.interval_s[0] for r in rows]), np.array([r.interval_s[1] for r in rows]), carry,
                     np.array([INTEGRAL_SOURCES.index(r.integral) for r in rows], dtype=np.int64),
                     np.array([_attitude_state(r) for r in rows], dtype=np.int64))


def from_engagement(tables: LQGTables) -> LQGTables:
    """``tables`` with every row that integrates the attitude error integrating it from the engagement instead
    (:data:`INTEGRAL_SOURCES`; the arrays shared, ``source`` new)."""
    attitude = INTEGRAL_SOURCES.index("attitude")
    source = np.where(tables.source == attitude, INTEGRAL_SOURCES.index("attitude-from-engagement"), tables.source)
    return tables._replace(source=source.astype(np.int64))


def _attitude_state(row: Any) -> int:
    """The index of the attitude state of a row that integrates the attitude error, else -1."""
    if row.integral != "attitude":
        return -1
    at = [k for k, name in enumerate(row.labels) if name in ("theta_y", "theta_z")]
    if len(at) != 1:
        raise ValueError(f"row {row.time_s:g} s integrates the attitude: one theta_y or theta_z state, found {len(at)}")
    return at[0]


@nb.njit(cache=True)
def row_index(tb, t):
    """The schedule row in use at flight time ``t`` [s]: the one whose interval ``[lo, hi)`` holds it,
    else the one with the nearest interval end."""
    best, dist = 0, np.inf
    for i in range(tb.lo.size):
        if tb.lo[i] <= t < tb.hi[i]:
            return i
        d = min(abs(t - tb.lo[i]), abs(t - tb.hi[i]))
        if d < dist:
            best, dist = i, d
    return best


@nb.njit(cache=True)
def lqg_step_k(tb, st, which, y, e, t, on, u_limit, aw, u):
    """Step the rows ``which`` (k,) of the law ``st`` (:class:`LQGState`) with the gyro samples ``y`` (k,)
    [rad/s] and the attitude error samples ``e`` (k,) [rad] (read by a row whose integral's ``source`` is the
    attitude) at flight times ``t`` (k,) [s], the law on where ``on`` (k,); their commands [rad] into ``u``
    (k,). ``tb``: :class:`LQGTables`; ``u_limit``: the gimbal limit [rad]; ``aw``: :class:`AntiWindup`."""
    N = tb.A.shape[1]
    xf = np.empty(N)
    old = np.empty(N)
    for j in range(which.size):
        b = which[j]
        if not on[j]:
            st.was_on[b] = False
            st.saturated[b] = False
            st.u[b] = 0.0
            u[j] = 0.0
            continue
        if not st.was_on[b]:                      # engagement: restart from zero
            st.row[b] = -1
            st.x[b, :] = 0.0
            st.xi[b] = 0.0
            st.u[b] = 0.0
            st.e0[b] = e[j]
        st.was_on[b] = True
        i = row_index(tb, t[j])
        if i != st.row[b]:
            o = st.row[b]
            old[:] = st.x[b, :]
            for k in range(N):
                src = tb.carry[o, i, k] if o >= 0 else -1
                st.x[b, k] = old[src] if src >= 0 else 0.0
            if o >= 0 and tb.source[i] >= 1 and tb.Ki[i] != 0.0:    # the attitude's integral: its command carried
                st.xi[b] *= tb.Ki[o] / tb.Ki[i]
            st.row[b] = i
        m = tb.dim[i]
        cx = 0.0
        for k in range(m):
            cx += tb.C[i, k] * st.x[b, k]
        innov = y[j] - cx
        for k in range(m):
            xf[k] = st.x[b, k] + tb.M[i, k] * innov
        ej = e[j] - st.e0[b] if tb.source[i] == 2 else e[j]     # the attitude error the row reads
        if tb.source[i] >= 1:                     # the attitude state: the measured attitude error
            xf[tb.att[i]] = ej
        kx = 0.0
        for k in range(m):
            kx += tb.Kx[i, k] * xf[k]
        v = -kx - tb.Ki[i] * st.xi[b]
        uu = min(max(v, -u_limit), u_limit)
        if aw.on:
            uu = min(max(uu, st.u[b] - aw.rate_step), st.u[b] + aw.rate_step)
        sat = uu != v
        s = y[j] if tb.source[i] == 0 else ej            # the integral's input (INTEGRAL_SOURCES)
        dxi = (tb.a[i] - 1.0) * st.xi[b] - tb.dt[i] * s
        if aw.on:
            if aw.back_gain > 0.0 and tb.Ki[i] != 0.0:   # back-calculation: v towards the command sent
                dxi += aw.back_gain * (v - uu) / tb.Ki[i]
            st.xi[b] += dxi
        elif not (sat and (v - uu) * (-tb.Ki[i] * dxi) > 0.0):   # clamp: do not integrate into the limit
            st.xi[b] += dxi
        for r in range(m):
            acc = 0.0
            for k in range(m):
                acc += tb.A[i, r, k] * xf[k]
            st.x[b, r] = acc + tb.B[i, r] * uu
        for r in range(m, N):
            st.x[b, r] = 0.0
        st.saturated[b] = sat
        st.u[b] = uu
        u[j] = uu


@nb.njit(cache=True)
def lqg_act_k(pitch, yaw, sp, sy, oc, rows, obs, t, u_limit, aw, gimbal, out):
    """Both planes' laws (``pitch``, ``yaw``: :class:`LQGTables`; ``sp``, ``sy``: :class:`LQGState`) for
    the rows ``rows`` (k,) on their observations ``obs`` (k, n_obs) (``oc``: the columns of the rate errors,
    the attitude errors (-1: none, read as 0) and the controller-on flag, :class:`.pidkernel.ObsColumns`) at the flight times ``t`` (n,) [s] of every
    row: :func:`lqg_step_k` of each plane (anti-windup ``aw``); the commands [rad] into ``gimbal`` (n, 2),
    the actions ``out`` (k, 2) float32 (gimbal / limit, clipped to [-1, 1])."""
    k = rows.size
    y, e, tk, u = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
    on = np.empty(k, np.bool_)
    for j in range(k):
        tk[j] = t[rows[j]]
        on[j] = float(obs[j, oc.on]) >= 0.5
    for ax in range(2):
        col, cat = oc.err[ax], oc.att[ax]
        for j in range(k):
            y[j] = float(obs[j, col])
            e[j] = float(obs[j, cat]) if cat >= 0 else 0.0
        lqg_step_k(pitch if ax == 0 else yaw, sp if ax == 0 else sy, rows, y, e, tk, on, u_limit, aw, u)
        for j in range(k):
            gimbal[rows[j], ax] = u[j]
            out[j, ax] = np.float32(clip_k(u[j] / u_limit, -1.0, 1.0))
