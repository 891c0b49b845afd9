"""The compiled act of ``eso`` (:mod:`.eso`): the extended-state observer and the law of both planes for any
number of rows, one row after the other (a row's operations its own, so a batch of one gives the bits of the same
row of any batch).

Per plane and control period, the row on (the observation's ``controller_on``; the equations of
:mod:`.design.esodesign`, whose :func:`~.design.esodesign.compensator` is this law unclipped)::

    d_k     = Cs s                                   the gimbal the observer assumes (servo model, delayed)
    x_hat   = F x_hat + H (theta_k, omega_k) + G b0 (d_prev + d_k) / 2
    u       = clip(-(kp x_hat[0] + kd x_hat[1] + x_hat[2]) / b0, -limit, limit)

``theta_k``, ``omega_k``: the attitude and rate errors [rad, rad/s]; ``F``, ``H``, ``G`` the row's observer
(:func:`.eso.observer_matrices`: the attitude-fed full-order ESO or the rate-fed reduced-order one).
    s      <- As s + Bs c;  c <- u;  d_prev <- d_k   the servo model steps on the command of the last period

The attitude and rate errors pass first through the row's structural filter (one section, the same on both,
so the attitude the observer reads is the integral of the rate it reads); its states are set at rest on the
current sample at engagement and when the row in use changes to one of another filter. At the first step of an
engagement the estimate starts at ``(theta_k, rate error_k, 0)`` and the servo model at
rest at the gimbal's observed position (no observer step). Off: the command is zero and the state frozen.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from .pidkernel import nearest_k

__all__ = ["ESOCols", "ESOState", "ESOTables", "eso_act_k", "new_state"]


class ESOTables(NamedTuple):
    """The schedule: ``t`` (m,) the design rows' flight times [s] (nearest row in use), ``kp`` (m,), ``kd`` (m,)
    the law's gains, ``F`` (m, 3, 3), ``H`` (m, 3, 2), ``G`` (m, 3) the observer's matrices; ``fb``, ``fa``
    (m, 3) the row's structural filter on both the attitude and the rate error (one Tustin section, ``fa[0] = 1``;
    ``(1, 0, 0), (1, 0, 0)``: none); ``tb`` (q,) and ``b0`` (q,) the control power [1/s^2] over
    flight time (linear between, held beyond); ``As`` (2, 2), ``Bs`` (2,) the servo model over a control
    period (states position [rad], rate [rad/s]); ``dt`` [s], ``mission`` [s] (time = fraction x mission),
    ``limit`` [rad]."""

    t: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    F: np.ndarray
    H: np.ndarray
    G: np.ndarray
    fb: np.ndarray
    fa: np.ndarray
    tb: np.ndarray
    b0: np.ndarray
    As: np.ndarray
    Bs: np.ndarray
    dt: float
    mission: float
    limit: float


class ESOCols(NamedTuple):
    """Observation columns: ``att`` (2,) attitude errors, ``rate`` (2,) rate errors, ``gimbal`` (2,) actuator
    positions over the limit, ``time`` the time fraction, ``on`` the controller flag."""

    att: np.ndarray
    rate: np.ndarray
    gimbal: np.ndarray
    time: int
    on: int


class ESOState(NamedTuple):
    """``n`` rows: ``x`` (n, 2, 3) the estimates (attitude [rad], rate [rad/s], disturbance [rad/s^2]) per plane,
    ``srv`` (n, 2, 2) the servo model, ``flt`` (n, 2, 2, 2) the filter's states (plane, signal: attitude, rate),
    ``row`` (n,) the design row in use, ``cmd`` (n, 2) the last command [rad], ``dprev`` (n, 2) the last assumed
    gimbal [rad], ``was_on`` (n,) whether the row acted at its last step, ``gimbal`` (n, 2) the last command."""

    x: np.ndarray
    srv: np.ndarray
    flt: np.ndarray
    row: np.ndarray
    cmd: np.ndarray
    dprev: np.ndarray
    was_on: np.ndarray
    gimbal: np.ndarray


def new_state(n: int) -> ESOState:
    """The state of ``n`` rows, as after a reset."""
    return ESOState(np.zeros((n, 2, 3)), np.zeros((n, 2, 2)), np.zeros((n, 2, 2, 2)), np.zeros(n, np.int64),
                    np.zeros((n, 2)), np.zeros((n, 2)),
                    np.zeros(n, np.bool_), np.zeros((n, 2)))


@nb.njit(cache=True)
def _b0(tb, b0, t):
    """The control power at ``t`` [s]: linear between the table's rows, held beyond."""
    m = tb.size
    if t <= tb[0]:
        return b0[0]
    if t >= tb[m - 1]:
        return b0[m - 1]
    j = 0
    while t >= tb[j + 1]:
        j += 1
    return b0[j] + (b0[j + 1] - b0[j]) * (t - tb[j]) / (tb[j + 1] - tb[j])


@nb.njit(cache=True)
def _settle(fb, fa, z, x):
    """Filter states ``z`` (2,) at rest for the constant input ``x`` (a section of unit gain at zero frequency)."""
    z[1] = (fb[2] - fa[2]) * x
    z[0] = (fb[1] - fa[1]) * x + z[1]


@nb.njit(cache=True)
def _section(fb, fa, z, x):
    """One step of the section (direct form II transposed) on ``x``; its output."""
    y = fb[0] * x + z[0]
    z[0] = fb[1] * x - fa[1] * y + z[1]
    z[1] = fb[2] * x - fa[2] * y
    return y


@nb.njit(cache=True)
def eso_act_k(tb, oc, st, rows, obs, out):
    """The actions ``out`` (k, 2) float32 (command / limit) of the rows ``rows`` (k,) for their observations
    ``obs`` (k, n_obs) (module docstring)."""
    dt, lim = tb.dt, tb.limit
    for j in range(rows.size):
        b = rows[j]
        o = obs[j]
        if not float(o[oc.on]) >= 0.5:
            st.was_on[b] = False
            st.gimbal[b, 0] = 0.0
            st.gimbal[b, 1] = 0.0
            out[j, 0] = np.float32(0.0)
            out[j, 1] = np.float32(0.0)
            continue
        t = float(o[oc.time]) * tb.mission
        i = nearest_k(tb.t, t)
        kp, kd = tb.kp[i], tb.kd[i]
        F, H, G = tb.F[i], tb.H[i], tb.G[i]
        b0 = _b0(tb.tb, tb.b0, t)
        first = not st.was_on[b]
        fb, fa = tb.fb[i], tb.fa[i]
        resettle = first
        if not first and st.row[b] != i:
            for q in range(3):
                if fb[q] != tb.fb[st.row[b], q] or fa[q] != tb.fa[st.row[b], q]:
                    resettle = True
        st.row[b] = i
        for ax in range(2):
            theta = float(o[oc.att[ax]])
            omega = float(o[oc.rate[ax]])
            if resettle:
                _settle(fb, fa, st.flt[b, ax, 0], theta)
                _settle(fb, fa, st.flt[b, ax, 1], omega)
            theta = _section(fb, fa, st.flt[b, ax, 0], theta)
            omega = _section(fb, fa, st.flt[b, ax, 1], omega)
            x = st.x[b, ax]
            s = st.srv[b, ax]
            if first:
                g = float(o[oc.gimbal[ax]]) * lim
                x[0], x[1], x[2] = theta, omega, 0.0
                s[0], s[1] = g, 0.0
                st.cmd[b, ax] = g
                st.dprev[b, ax] = g
            else:
                d = s[0]
                v = b0 * 0.5 * (st.dprev[b, ax] + d)
                y0 = F[0, 0] * x[0] + F[0, 1] * x[1] + F[0, 2] * x[2] + H[0, 0] * theta + H[0, 1] * omega + G[0] * v
                y1 = F[1, 0] * x[0] + F[1, 1] * x[1] + F[1, 2] * x[2] + H[1, 0] * theta + H[1, 1] * omega + G[1] * v
                y2 = F[2, 0] * x[0] + F[2, 1] * x[1] + F[2, 2] * x[2] + H[2, 0] * theta + H[2, 1] * omega + G[2] * v
                x[0], x[1], x[2] = y0, y1, y2
                st.dprev[b, ax] = d
            u = -(kp * x[0] + kd * x[1] + x[2]) / b0
            u = max(-lim, min(lim, u))
            c = st.cmd[b, ax]
            s0 = tb.As[0, 0] * s[0] + tb.As[0, 1] * s[1] + tb.Bs[0] * c
            s1 = tb.As[1, 0] * s[0] + tb.As[1, 1] * s[1] + tb.Bs[1] * c
            s[0], s[1] = s0, s1
            st.cmd[b, ax] = u
            st.gimbal[b, ax] = u
            out[j, ax] = np.float32(u / lim)
        st.was_on[b] = True
