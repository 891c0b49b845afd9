"""The compiled act of the PID family (:mod:`.pid`: fixed gains, a gain schedule, structural filters, load
relief) for any number of rows: what :class:`.pidbatch.PIDBatch` runs for the rows of a batched env.

The same floating-point operations in the same order as the per-row policy (:meth:`.pid.PIDPolicy.act`,
:class:`.pid.DiscretePID`, :class:`.filters.FilterChain`), so that row ``b`` of a batch and a policy of its
own give the same actions to the bit (``tests/test_policy_batch.py``). The blocks:

* :class:`ObsColumns`: where the observation holds what the laws read (from the env's observation layout);
* :class:`PIDTable`: the schedule's columns (a fixed-gain policy is a one-row table) and the discrete
  structural filter of each row;
* :class:`PIDSetup`: the constants (control period, gimbal limit, how the schedule is read);
* :class:`PIDState`: the state of each row (the two axes' PIDs, the filters, the last gimbal command).

:func:`interp_k` is ``np.interp`` of one value (numpy's ``arr_interp``: the interval by search, the
slope, the retry from the right end when the left gives NaN); :func:`nearest_k` is
:meth:`.pid.GainSchedule._nearest` (``argmin`` of the distance, the first of equals).
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from lvgym.envs.layouts import G0

__all__ = ["FILTERS_NONE", "FILTERS_ROWS", "FILTERS_TABLE", "ObsColumns", "PIDSetup", "PIDState", "PIDTable", "VAR_FIXED",
           "VAR_MACH", "VAR_VALUE", "clip_k", "interp_k", "nearest_k", "pid_act_k", "pid_row_k"]

#: how a row's scheduling variable is read (:attr:`PIDSetup.variable`): fixed gains (no variable), a value
#: per row handed in (``info["mass"]`` or ``info["time"]``), the observation's Mach entry times 10
VAR_FIXED, VAR_VALUE, VAR_MACH = 0, 1, 2
#: where the structural filter's coefficients come from (:attr:`PIDSetup.filters`): no filters, the
#: schedule row in use (a nearest-row schedule), each row's own (set from Python, a linear schedule)
FILTERS_NONE, FILTERS_TABLE, FILTERS_ROWS = 0, 1, 2


class ObsColumns(NamedTuple):
    """Indices into an observation row: ``err`` (2,) the pitch and yaw rate errors, ``acc`` (2,) the
    accelerometers of load relief (``accel_z``, ``accel_y``; -1 where the observation has none), ``on`` the
    controller-on flag, ``mach`` Mach / 10, ``ref`` the pitch rate reference (-1: none)."""

    err: np.ndarray
    acc: np.ndarray
    on: int
    mach: int
    ref: int


class PIDTable(NamedTuple):
    """A gain schedule of ``m`` rows: ``x`` (m,) its breakpoints in the schedule's order, ``xs`` (m,) the
    same ascending, ``rank`` (m,) the ascending position of each breakpoint, ``kp``, ``ki``, ``kd``, ``n``,
    ``accel`` (m,) the columns in ascending order; the discrete structural filter of each row (S sections):
    ``fb``, ``fa`` (m, S, 3) numerator and denominator, ``fbsum``, ``fasum`` (m, S) their sums (the
    sections' DC gain at a restart)."""

    x: np.ndarray
    xs: np.ndarray
    rank: np.ndarray
    kp: np.ndarray
    ki: np.ndarray
    kd: np.ndarray
    n: np.ndarray
    accel: np.ndarray
    fb: np.ndarray
    fa: np.ndarray
    fbsum: np.ndarray
    fasum: np.ndarray


class PIDSetup(NamedTuple):
    """The constants: ``dt`` [s] the control period, ``limit`` [rad] the gimbal limit (the PID's output
    limits and the action's scale), ``variable`` (:data:`VAR_FIXED` ...), ``nearest`` (the nearest row, else
    linear interpolation), ``accel`` (the schedule has a load-relief column), ``filters``
    (:data:`FILTERS_NONE` ...), ``signs`` (2,) the load-relief signs per axis."""

    dt: float
    limit: float
    variable: int
    nearest: bool
    accel: bool
    filters: int
    signs: np.ndarray


class PIDState(NamedTuple):
    """The state of ``n`` rows, per axis (pitch, yaw): ``integral``, ``deriv``, ``e_prev`` (n, 2) the PID's,
    ``has_prev`` (n, 2) whether ``e_prev`` holds a sample, ``saturated`` (n, 2); ``filtering`` (n,) whether
    the filters run (since the controller switched on); ``s1``, ``s2`` (n, 2, S) the filter sections'
    states; ``fb``, ``fa`` (n, S, 3), ``fbsum``, ``fasum`` (n, S) the filter in use and ``filt`` (n,) its
    schedule row (-1: none yet); ``gimbal`` (n, 2) [rad] the last command."""

    integral: np.ndarray
    deriv: np.ndarray
    e_prev: np.ndarray
    has_prev: np.ndarray
    saturated: np.ndarray
    filtering: np.ndarray
    s1: np.ndarray
    s2: np.ndarray
    fb: np.ndarray
    fa: np.ndarray
    fbsum: np.ndarray
    fasum: np.ndarray
    filt: np.ndarray
    gimbal: np.ndarray


@nb.njit(cache=True)
def interp_k(x, xp, fp):
    """``np.interp(x, xp, fp)`` of one value ``x`` on ascending breakpoints ``xp`` (the ends held)."""
    m = xp.size
    if m == 1:
        return fp[0]
    if np.isnan(x):
        return x
    if x > xp[m - 1]:
        return fp[m - 1]
    if x < xp[0]:
        return fp[0]
    j = 0
    while j < m - 1 and x >= xp[j + 1]:
        j += 1
    if j == m - 1 or xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    r = slope * (x - xp[j]) + fp[j]
    if np.isnan(r):
        r = slope * (x - xp[j + 1]) + fp[j + 1]
        if np.isnan(r) and fp[j] == fp[j + 1]:
            r = fp[j]
    return r


@nb.njit(cache=True)
def nearest_k(x, value):
    """The index of the breakpoint of ``x`` nearest ``value`` (the first of equals)."""
    best, dist = 0, abs(x[0] - value)
    for i in range(1, x.size):
        d = abs(x[i] - value)
        if d < dist:
            best, dist = i, d
    return best


@nb.njit(cache=True)
def clip_k(x, lo, hi):
    """``np.clip`` of one value (NaN stays NaN)."""
    if np.isnan(x):
        return x
    y = x if x > lo else lo
    return y if y < hi else hi


@nb.njit(cache=True)
def _filter_reset(st, b, ax, x0):
    """The sections of row ``b``'s filter of axis ``ax`` in the steady state of the input ``x0``
    (:meth:`.filters.FilterChain.reset`)."""
    x = x0
    for s in range(st.fb.shape[1]):
        y = x * st.fbsum[b, s] / st.fasum[b, s]
        s2 = st.fb[b, s, 2] * x - st.fa[b, s, 2] * y
        st.s1[b, ax, s] = st.fb[b, s, 1] * x - st.fa[b, s, 1] * y + s2
        st.s2[b, ax, s] = s2
        x = y


@nb.njit(cache=True)
def _filter_update(st, b, ax, x):
    """One sample ``x`` through row ``b``'s filter of axis ``ax`` (:meth:`.filters.FilterChain.update`)."""
    y = x
    for s in range(st.fb.shape[1]):
        s1, s2 = st.s1[b, ax, s], st.s2[b, ax, s]
        out = st.fb[b, s, 0] * y + s1
        st.s1[b, ax, s] = st.fb[b, s, 1] * y - st.fa[b, s, 1] * out + s2
        st.s2[b, ax, s] = st.fb[b, s, 2] * y - st.fa[b, s, 2] * out
        y = out
    return y


@nb.njit(cache=True)
def _pid_update(su, st, b, ax, e, on, kp, ki, kd, n):
    """One step of row ``b``'s PID of axis ``ax`` on the error ``e`` (:meth:`.pid.DiscretePID.update`)."""
    if not on:
        st.deriv[b, ax], st.has_prev[b, ax], st.saturated[b, ax] = 0.0, False, False
        return 0.0
    de = e - st.e_prev[b, ax] if st.has_prev[b, ax] else 0.0
    if np.isinf(n):
        d = kd * de / su.dt
    else:
        d = (st.deriv[b, ax] + kd * n * de) / (1.0 + n * su.dt)
    p = kp * e
    i = st.integral[b, ax] + ki * su.dt * e
    v = p + i + d
    if (v > su.limit and e * ki > 0.0) or (v < -su.limit and e * ki < 0.0):
        i = st.integral[b, ax]                         # clamp: do not integrate further into the limit
        v = p + i + d
    st.integral[b, ax], st.deriv[b, ax], st.e_prev[b, ax], st.has_prev[b, ax] = i, d, e, True
    lo = -su.limit if -su.limit > v else v             # Python's max(v, u_min), min(., u_max)
    u = su.limit if su.limit < lo else lo
    st.saturated[b, ax] = u != v
    return u


@nb.njit(cache=True)
def pid_row_k(tb, su, oc, st, b, obs, value):
    """One act of row ``b`` on its observation ``obs`` (n_obs,) and scheduling value ``value`` (mass [kg]
    or time [s]; unused for fixed gains and Mach): the commands [rad] into ``st.gimbal[b]``."""
    on = float(obs[oc.on]) >= 0.5
    if su.variable == VAR_MACH:
        value = float(obs[oc.mach]) * 10.0
    if su.nearest:
        i = nearest_k(tb.x, value)
        r = tb.rank[i]
        kp, ki, kd, n, acc = tb.kp[r], tb.ki[r], tb.kd[r], tb.n[r], tb.accel[r]
        if su.filters == FILTERS_TABLE and i != st.filt[b]:     # the filter of another row: its coefficients
            st.fb[b, :, :] = tb.fb[i]
            st.fa[b, :, :] = tb.fa[i]
            st.fbsum[b, :] = tb.fbsum[i]
            st.fasum[b, :] = tb.fasum[i]
            st.filt[b] = i
    else:
        kp, ki, kd = interp_k(value, tb.xs, tb.kp), interp_k(value, tb.xs, tb.ki), interp_k(value, tb.xs, tb.kd)
        n, acc = interp_k(value, tb.xs, tb.n), interp_k(value, tb.xs, tb.accel)
    if not su.accel:
        acc = 0.0
    e0 = -float(obs[oc.err[0]])
    e1 = -float(obs[oc.err[1]])
    if acc != 0.0:
        e0 = e0 + acc * G0 * su.signs[0] * float(obs[oc.acc[0]])
        e1 = e1 + acc * G0 * su.signs[1] * float(obs[oc.acc[1]])
    if su.filters == FILTERS_NONE or not on:
        st.filtering[b] = False
    else:
        if not st.filtering[b]:                        # switched on: the filters start in steady state
            _filter_reset(st, b, 0, e0)
            _filter_reset(st, b, 1, e1)
            st.filtering[b] = True
        e0 = _filter_update(st, b, 0, e0)
        e1 = _filter_update(st, b, 1, e1)
    st.gimbal[b, 0] = _pid_update(su, st, b, 0, e0, on, kp, ki, kd, n)
    st.gimbal[b, 1] = _pid_update(su, st, b, 1, e1, on, kp, ki, kd, n)


@nb.njit(cache=True)
def pid_act_k(tb, su, oc, st, rows, obs, value, out):
    """The actions ``out`` (k, 2) float32 of the rows ``rows`` (k,) for their observations ``obs`` (k, n_obs)
    and the scheduling values ``value`` (n,) of every row: gimbal / limit, clipped to [-1, 1]."""
    for j in range(rows.size):
        b = rows[j]
        pid_row_k(tb, su, oc, st, b, obs[j], value[b])
        for ax in range(2):
            out[j, ax] = np.float32(clip_k(st.gimbal[b, ax] / su.limit, -1.0, 1.0))
