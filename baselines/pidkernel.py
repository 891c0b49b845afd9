"""The compiled act of the PID family (:mod:`.pid`: fixed gains, a gain schedule, structural filters, load
relief, the attitude channel) for any number of rows: the inner loop of :class:`.pid.PIDLaw`, one row after
the other, each row's operations its own (so a batch of one gives the bits of the same row of any batch,
``tests/test_policy_batch.py``). The blocks:

* :class:`ObsColumns`: where the observation holds what the laws read (from the env's observation layout);
* :class:`PIDTable`: the schedule's breakpoints and columns (layout :data:`GAINS`; a fixed-gain policy is
  a one-row table) and the discrete structural filters of each row (layout :data:`COEFFS`: the sections
  of up to :data:`FILTERS_MAX` filters in series, :attr:`PIDSetup.sections` of them in use);
* :class:`PIDSetup`: the constants (control period, gimbal limit, how the schedule is read);
* :class:`PIDState`: each row's state as two packed vectors, the PIDs' (:data:`PID_ROW`) and the
  filters' (:data:`FILTER_ROW`). A kernel takes a row's vectors once and indexes them by their layouts'
  offsets (numba counts a reference at every look-up of an array in a named block).

:func:`interp_k` is ``np.interp`` of one value (numpy's ``arr_interp``: the interval by search, the
slope, the retry from the right end when the left gives NaN); :func:`nearest_k` is
:meth:`.gainschedule.GainSchedule._nearest` (``argmin`` of the distance, the first of equals).

The row layouts::

{PID_ROW}

{FILTER_ROW}
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba as nb
import numpy as np

from lvgym.envs.layouts import G0
from lvgym.packing import Field, Packed

__all__ = ["COEFFS", "FILTERS_MAX", "FILTERS_NONE", "FILTERS_ROWS", "FILTERS_TABLE", "FILTER_ROW", "GAINS", "ObsColumns",
           "PID_ROW", "PIDSetup", "PIDState", "PIDTable", "SECTIONS", "SECTIONS_PER_FILTER", "TAPS", "VAR_FIXED",
           "VAR_MACH", "VAR_VALUE", "clip_k", "coefficients", "filter_reset_k", "filter_row", "filter_update_k", "fixed_tables", "interp_k", "nearest_k", "new_state",
           "obs_columns", "pid_act_k", "pid_row_k", "schedule_tables"]

#: how a row's scheduling variable is read (:attr:`PIDSetup.variable`): fixed gains (no variable), a value
#: per row handed in (``info["mass"]`` or ``info["time"]``), the observation's Mach entry times 10
VAR_FIXED, VAR_VALUE, VAR_MACH = 0, 1, 2
#: where the structural filter's coefficients come from (:attr:`PIDSetup.filters`): no filters, the
#: schedule row in use (a nearest-row schedule), each row's own (set from Python, a linear schedule)
FILTERS_NONE, FILTERS_TABLE, FILTERS_ROWS = 0, 1, 2
#: sections of a structural filter (lead-lag, low-pass, notch: :meth:`.filters.StructuralFilter.discrete`),
#: the most filters in series a row holds (a schedule with more is refused, :class:`.pid.PIDLaw`),
#: so the most sections, and coefficients per section's numerator and denominator
SECTIONS_PER_FILTER, FILTERS_MAX, TAPS = 3, 4, 3
SECTIONS = SECTIONS_PER_FILTER * FILTERS_MAX
AXES = 2

#: a schedule row's gains (the columns of :attr:`PIDTable.gains`)
GAINS = Packed("PID gains", [
    Field("kp", 1, "rad per rad/s", "proportional gain"),
    Field("ki", 1, "rad per rad", "integral gain"),
    Field("kd", 1, "rad per rad/s^2", "derivative gain"),
    Field("n", 1, "rad/s", "derivative filter coefficient (inf: unfiltered)"),
    Field("accel", 1, "rad/s per m/s^2", "load-relief gain (0: none)"),
    Field("attitude", 1, "rad/s per rad", "attitude gain (0: none)"),
])

#: the discrete structural filters of a row in series: each section's ``b``, ``a`` in ``z`` and their sums (the
#: first :attr:`PIDSetup.sections` sections in use)
COEFFS = Packed("structural filter coefficients", [
    Field("b", SECTIONS * TAPS, "-", "numerator of each section (b0, b1, b2)", shape=(SECTIONS, TAPS)),
    Field("a", SECTIONS * TAPS, "-", "denominator of each section (1, a1, a2)", shape=(SECTIONS, TAPS)),
    Field("bsum", SECTIONS, "-", "sum of each section's numerator (a restart's steady state: x bsum / asum)"),
    Field("asum", SECTIONS, "-", "sum of each section's denominator"),
])

#: a row's PIDs (both axes, pitch then yaw)
PID_ROW = Packed("PID row", [
    Field("integral", AXES, "rad", "integral term per axis"),
    Field("deriv", AXES, "rad", "filtered derivative term per axis"),
    Field("e_prev", AXES, "rad/s", "the last error per axis (where has_prev)"),
    Field("has_prev", AXES, "-", "1: e_prev holds a sample (0 after a reset and while off)"),
    Field("saturated", AXES, "-", "1: the last command was clipped"),
    Field("filtering", 1, "-", "1: the structural filters run (since the controller switched on)"),
    Field("filt", 1, "-", "the schedule row whose filter is in use (-1: none yet)"),
    Field("gimbal", AXES, "rad", "the last command per axis (the policy's last_gimbal)"),
])

#: a row's structural filters: the sections' states per axis and the coefficients in use
FILTER_ROW = Packed("structural filter row", [
    Field("s1", AXES * SECTIONS, "-", "first state of each section, per axis", shape=(AXES, SECTIONS)),
    Field("s2", AXES * SECTIONS, "-", "second state of each section, per axis", shape=(AXES, SECTIONS)),
    Field("coeffs", COEFFS.size, "-", "the filter in use (layout COEFFS)", sub=COEFFS),
])

__doc__ = __doc__.format(PID_ROW=PID_ROW.table(), FILTER_ROW=FILTER_ROW.table())
#: entries of a filter's coefficients (a compiled constant)
N_COEFFS = COEFFS.size

G = GAINS.at
C = COEFFS.at
P = PID_ROW.at
F = FILTER_ROW.at


class ObsColumns(NamedTuple):
    """Indices into an observation row: ``err`` (2,) the pitch and yaw rate errors, ``acc`` (2,) the
    accelerometers of load relief (``accel_z``, ``accel_y``; -1 where the observation has none), ``on`` the
    controller-on flag, ``mach`` Mach / 10, ``ref`` the pitch rate reference (-1: none), ``att`` (2,) the
    pitch and yaw attitude errors (-1 where the observation has none)."""

    err: np.ndarray
    acc: np.ndarray
    on: int
    mach: int
    ref: int
    att: np.ndarray


class PIDTable(NamedTuple):
    """A gain schedule of ``m`` rows: ``x`` (m,) its breakpoints in the schedule's order, ``xs`` (m,) the
    same ascending, ``rank`` (m,) the ascending position of each breakpoint, ``gains`` (GAINS.size, m) the
    columns (layout :data:`GAINS`) in ascending order; ``coeffs`` (m, COEFFS.size) the discrete structural
    filter of each row (layout :data:`COEFFS`)."""

    x: np.ndarray
    xs: np.ndarray
    rank: np.ndarray
    gains: np.ndarray
    coeffs: np.ndarray


class PIDSetup(NamedTuple):
    """The constants: ``dt`` [s] the control period, ``limit`` [rad] the gimbal limit (the PID's output
    limits and the action's scale), ``variable`` (:data:`VAR_FIXED` ...), ``nearest`` (the nearest row, else
    linear interpolation), ``accel`` (the schedule has a load-relief column), ``filters``
    (:data:`FILTERS_NONE` ...), ``signs`` (2,) the load-relief signs per axis, ``attitude`` (the schedule
    has an attitude column), ``sections`` the filter sections in use (3 per filter in series)."""

    dt: float
    limit: float
    variable: int
    nearest: bool
    accel: bool
    filters: int
    signs: np.ndarray
    attitude: bool
    sections: int


class PIDState(NamedTuple):
    """The state of ``n`` rows: ``pid`` (n, PID_ROW.size), ``filters`` (n, FILTER_ROW.size)."""

    pid: np.ndarray
    filters: np.ndarray


def obs_columns(layout: Any) -> ObsColumns:
    """Where an observation of ``layout`` (an env's ``observation_layout``) holds what the PID family reads:
    the rate errors, the controller flag and Mach; the accelerometers and the attitude errors where it has them
    (-1 otherwise); no pitch rate reference (-1: AAC's :class:`.aac.AACLaw` reads its own)."""
    names = layout.names
    acc = [layout.index("accel_z"), layout.index("accel_y")] if "accel_z" in names else [-1, -1]
    att = ([layout.index("pitch_attitude_error"), layout.index("yaw_attitude_error")]
           if "pitch_attitude_error" in names else [-1, -1])
    return ObsColumns(np.asarray([layout.index("pitch_rate_error"), layout.index("yaw_rate_error")], dtype=np.int64),
                      np.asarray(acc, dtype=np.int64), int(layout.index("controller_on")),
                      int(layout.index("mach_over_10")), -1, np.asarray(att, dtype=np.int64))


def coefficients(filt: Any, dt: float, out: np.ndarray | None = None) -> np.ndarray:
    """The discrete sections of ``filt`` (one filter or a series) at ``dt`` [s]
    (:meth:`.filters.StructuralFilter.discrete`) packed by :data:`COEFFS` into ``out`` (a new vector by default;
    the sections beyond the filter's left as they are), with the sums a restart in the steady state divides by
    (``b.sum()``, ``a.sum()``)."""
    out = COEFFS.zeros() if out is None else out
    sections = filt.discrete(dt)
    if len(sections) > SECTIONS:
        raise ValueError(f"a structural filter of {len(sections)} sections: the kernel runs at most {SECTIONS}")
    b, a = COEFFS.view(out, "b"), COEFFS.view(out, "a")
    bsum, asum = COEFFS.view(out, "bsum"), COEFFS.view(out, "asum")
    for s, (bz, az) in enumerate(sections):
        b[s], a[s], bsum[s], asum[s] = bz, az, bz.sum(), az.sum()
    return out


def fixed_tables(kp: float, ki: float, kd: float, n: float, dt: float, limit: float,
                 signs: np.ndarray) -> tuple[PIDTable, PIDSetup]:
    """The blocks of fixed gains ``kp``, ``ki``, ``kd``, ``n`` (a table of one row, read as nearest; no
    channels, no filters) at the control period ``dt`` [s] and the gimbal ``limit`` [rad]."""
    gains = GAINS.pack({"kp": kp, "ki": ki, "kd": kd, "n": n, "accel": 0.0, "attitude": 0.0})
    tb = PIDTable(np.zeros(1), np.zeros(1), np.zeros(1, np.int64), gains.reshape(-1, 1), np.zeros((1, COEFFS.size)))
    return tb, PIDSetup(dt, limit, VAR_FIXED, True, False, FILTERS_NONE, signs, False, 0)


def schedule_tables(schedule: Any, dt: float, limit: float, signs: np.ndarray) -> tuple[PIDTable, PIDSetup]:
    """The blocks of a :class:`.gainschedule.GainSchedule` at the control period ``dt`` [s] and the gimbal
    ``limit`` [rad]: its columns in ascending order of the breakpoints and, for a nearest-row schedule with
    filters, each row's discrete filter (a linear schedule's filters change with every value and are
    discretised when a row's changes, :meth:`.pid.PIDLaw.prepare`)."""
    x, xs, cols = schedule._table
    rank = np.empty(x.size, np.int64)
    rank[np.argsort(x)] = np.arange(x.size)
    gains = np.zeros((GAINS.size, x.size))
    for name, col in (("kp", "kp"), ("ki", "ki"), ("kd", "kd"), ("n", "n"), ("accel", "accel_gain"),
                      ("attitude", "attitude_gain")):
        gains[GAINS.index(name)] = cols.get(col, 0.0)
    nearest = schedule.interpolation == "nearest"
    no_filters = np.zeros((1, COEFFS.size))
    if schedule.filters is None:
        coeffs, filters = no_filters, FILTERS_NONE
    elif nearest:
        coeffs, filters = np.array([coefficients(f, dt) for f in schedule.filters]), FILTERS_TABLE
    else:
        coeffs, filters = no_filters, FILTERS_ROWS
    variable = VAR_MACH if schedule.variable == "mach" else VAR_VALUE
    tb = PIDTable(x, xs, rank, np.ascontiguousarray(gains), coeffs)
    return tb, PIDSetup(dt, limit, variable, nearest, schedule.accel_gain is not None, filters, signs,
                        schedule.attitude_gain is not None, SECTIONS_PER_FILTER * schedule.filter_count)


def filter_row(filt: Any, dt: float) -> tuple[np.ndarray, int]:
    """A row's filter state (layout :data:`FILTER_ROW`, states zero) holding ``filt`` (one filter or a series)
    discretised at ``dt`` [s], and its number of sections: what :func:`filter_update_k` and
    :func:`filter_reset_k` run one sample at a time (the law's own filter, for the tests and the design tools)."""
    f = FILTER_ROW.zeros()
    coefficients(filt, dt, f[FILTER_ROW.slice("coeffs")])
    return f, len(filt.discrete(dt))


def new_state(n: int) -> PIDState:
    """The state of ``n`` rows, as after a reset (no filter in use yet; the coefficient sums 1, so that a row
    without filters divides by nothing else)."""
    return PIDState(PID_ROW.pack({"filt": -1.0}, n), FILTER_ROW.pack({"bsum": 1.0, "asum": 1.0}, n))


@nb.njit(cache=True, inline="always")
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


@nb.njit(cache=True, inline="always")
def nearest_k(x, value):
    """The index of the breakpoint of ``x`` nearest ``value`` (the first of equals)."""
    best, dist = 0, abs(x[0] - value)
    for i in range(1, x.size):
        d = abs(x[i] - value)
        if d < dist:
            best, dist = i, d
    return best


@nb.njit(cache=True, inline="always")
def clip_k(x, lo, hi):
    """``np.clip`` of one value (NaN stays NaN)."""
    if np.isnan(x):
        return x
    y = x if x > lo else lo
    return y if y < hi else hi


@nb.njit(cache=True, inline="always")
def filter_reset_k(f, ax, x0, sections):
    """The first ``sections`` sections of the filter row ``f``'s axis ``ax`` in the steady state of the input
    ``x0`` (direct form II transposed, each section's states at the input's steady state)."""
    x = x0
    for s in range(sections):
        b, a = F.b + TAPS * s, F.a + TAPS * s
        y = x * f[F.bsum + s] / f[F.asum + s]
        s2 = f[b + 2] * x - f[a + 2] * y
        f[F.s1 + SECTIONS * ax + s] = f[b + 1] * x - f[a + 1] * y + s2
        f[F.s2 + SECTIONS * ax + s] = s2
        x = y


@nb.njit(cache=True, inline="always")
def filter_update_k(f, ax, x, sections):
    """One sample ``x`` through the first ``sections`` sections of the filter row ``f``'s axis ``ax``
    (direct form II transposed per section)."""
    y = x
    for s in range(sections):
        b, a = F.b + TAPS * s, F.a + TAPS * s
        i1, i2 = F.s1 + SECTIONS * ax + s, F.s2 + SECTIONS * ax + s
        s1, s2 = f[i1], f[i2]
        out = f[b] * y + s1
        f[i1] = f[b + 1] * y - f[a + 1] * out + s2
        f[i2] = f[b + 2] * y - f[a + 2] * out
        y = out
    return y


@nb.njit(cache=True, inline="always")
def _pid_update(su, r, ax, e, on, g):
    """One step of the PID row ``r``'s axis ``ax`` on the error ``e`` with the gains ``g`` (kp, ki, kd, n)
    (the module docstring of :mod:`.pid`)."""
    if not on:
        r[P.deriv + ax], r[P.has_prev + ax], r[P.saturated + ax] = 0.0, 0.0, 0.0
        return 0.0
    kp, ki, kd, n = g
    de = e - r[P.e_prev + ax] if r[P.has_prev + ax] != 0.0 else 0.0
    if np.isinf(n):
        d = kd * de / su.dt
    else:
        d = (r[P.deriv + ax] + kd * n * de) / (1.0 + n * su.dt)
    p = kp * e
    i = r[P.integral + ax] + ki * su.dt * e
    v = p + i + d
    if (v > su.limit and e * ki > 0.0) or (v < -su.limit and e * ki < 0.0):
        i = r[P.integral + ax]                         # clamp: do not integrate further into the limit
        v = p + i + d
    r[P.integral + ax], r[P.deriv + ax], r[P.e_prev + ax], r[P.has_prev + ax] = i, d, e, 1.0
    lo = -su.limit if -su.limit > v else v             # Python's max(v, u_min), min(., u_max)
    u = su.limit if su.limit < lo else lo
    r[P.saturated + ax] = 1.0 if u != v else 0.0
    return u


@nb.njit(cache=True, inline="always")
def pid_row_k(tb, su, oc, r, f, obs, value):
    """One act of a row (its PID row ``r``, filter row ``f``) on its observation ``obs`` (n_obs,) and
    scheduling value ``value`` (mass [kg] or time [s]; unused for fixed gains and Mach): the commands
    [rad] into ``r[P.gimbal:]``."""
    on = float(obs[oc.on]) >= 0.5
    if su.variable == VAR_MACH:
        value = float(obs[oc.mach]) * 10.0
    gains = tb.gains
    if su.nearest:
        i = nearest_k(tb.x, value)
        k = tb.rank[i]
        kp, ki, kd, n, acc = gains[G.kp, k], gains[G.ki, k], gains[G.kd, k], gains[G.n, k], gains[G.accel, k]
        att = gains[G.attitude, k]
        if su.filters == FILTERS_TABLE and i != r[P.filt]:      # the filter of another row: its coefficients
            coeffs = tb.coeffs
            for c in range(N_COEFFS):
                f[F.coeffs + c] = coeffs[i, c]
            r[P.filt] = i
    else:
        xs = tb.xs
        kp, ki, kd = interp_k(value, xs, gains[G.kp]), interp_k(value, xs, gains[G.ki]), interp_k(value, xs, gains[G.kd])
        n, acc = interp_k(value, xs, gains[G.n]), interp_k(value, xs, gains[G.accel])
        att = interp_k(value, xs, gains[G.attitude])
    if not su.accel:
        acc = 0.0
    if not su.attitude:
        att = 0.0
    err, acc_at, att_at = oc.err, oc.acc, oc.att
    e0 = -float(obs[err[0]])
    e1 = -float(obs[err[1]])
    if att != 0.0:                                     # the attitude channel: - k_theta (attitude error)
        e0 = e0 - att * float(obs[att_at[0]])
        e1 = e1 - att * float(obs[att_at[1]])
    if acc != 0.0:
        signs = su.signs
        e0 = e0 + acc * G0 * signs[0] * float(obs[acc_at[0]])
        e1 = e1 + acc * G0 * signs[1] * float(obs[acc_at[1]])
    if su.filters == FILTERS_NONE or not on:
        r[P.filtering] = 0.0
    else:
        if r[P.filtering] == 0.0:                      # switched on: the filters start in steady state
            filter_reset_k(f, 0, e0, su.sections)
            filter_reset_k(f, 1, e1, su.sections)
            r[P.filtering] = 1.0
        e0 = filter_update_k(f, 0, e0, su.sections)
        e1 = filter_update_k(f, 1, e1, su.sections)
    g = (kp, ki, kd, n)
    r[P.gimbal] = _pid_update(su, r, 0, e0, on, g)
    r[P.gimbal + 1] = _pid_update(su, r, 1, e1, on, g)


@nb.njit(cache=True)
def pid_act_k(tb, su, oc, st, rows, obs, value, out):
    """The actions ``out`` (k, 2) float32 of the rows ``rows`` (k,) for their observations ``obs`` (k, n_obs)
    and the scheduling values ``value`` (n,) of every row: gimbal / limit, clipped to [-1, 1]."""
    pid, filters = st.pid, st.filters
    for j in range(rows.size):
        b = rows[j]
        r = pid[b]
        pid_row_k(tb, su, oc, r, filters[b], obs[j], value[b])
        for ax in range(AXES):
            out[j, ax] = np.float32(clip_k(r[P.gimbal + ax] / su.limit, -1.0, 1.0))
