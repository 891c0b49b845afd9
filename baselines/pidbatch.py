"""The PID family for the rows of a batched env (:class:`PIDBatch`): :meth:`.pid.PIDPolicy.batch`.

Built once from a policy object (a :class:`.pid.PIDPolicy` of fixed gains or a
:class:`.pid.GainScheduledPIDPolicy`: ``pid``, ``pid-thesis``, ``gs-pid``, ``gs-pid-thesis``,
``gs-pid-flex``), it steps every row in one call of the compiled :func:`.pidkernel.pid_act_k`, the per-row
policy's operations in the per-row policy's order. The structural filters of a nearest-row schedule
(every flex schedule; one filter per row or up to :data:`.pidkernel.FILTERS_MAX` in series) are discretised
once per schedule row here; those of a linearly interpolated
schedule change with every value of the scheduling variable and are discretised in Python
(:meth:`.filters.StructuralFilter.discrete`, the per-row policy's own call) whenever a row's filter changes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .filters import Filter
from .pidkernel import (COEFFS, FILTER_ROW, FILTERS_NONE, FILTERS_ROWS, FILTERS_TABLE, GAINS, PID_ROW, SECTIONS,
                        SECTIONS_PER_FILTER, VAR_FIXED, VAR_MACH, VAR_VALUE, ObsColumns, PIDSetup, PIDState, PIDTable,
                        pid_act_k)

__all__ = ["PIDBatch", "coefficients", "new_state", "obs_columns", "tables"]

#: the info key of each scheduling variable read from the info (Mach comes from the observation)
_INFO_KEY = {"mass": "mass", "time": "time"}


def obs_columns(policy: Any) -> ObsColumns:
    """Where ``policy`` (a :class:`.pid.PIDPolicy`) reads its observation entries."""
    acc = np.asarray(policy._i_acc if policy._i_acc is not None else [-1, -1], dtype=np.int64)
    att = np.asarray(policy._i_att if policy._i_att is not None else [-1, -1], dtype=np.int64)
    return ObsColumns(np.asarray(policy._i_err, dtype=np.int64), acc, int(policy._i_on), int(policy._i_mach), -1, att)


def coefficients(filt: Filter, dt: float, out: np.ndarray | None = None) -> np.ndarray:
    """The discrete sections of ``filt`` (one filter or a series) at ``dt`` [s]
    (:meth:`.filters.StructuralFilter.discrete`, the per-row policy's call) packed by :data:`.pidkernel.COEFFS`
    into ``out`` (a new vector by default; the sections beyond the filter's left as they are); the sums as
    :meth:`.filters.FilterChain.reset` takes them (``b.sum()``, ``a.sum()``)."""
    out = COEFFS.zeros() if out is None else out
    sections = filt.discrete(dt)
    if len(sections) > SECTIONS:
        raise ValueError(f"a structural filter of {len(sections)} sections: the kernel runs at most {SECTIONS}")
    b, a = COEFFS.view(out, "b"), COEFFS.view(out, "a")
    bsum, asum = COEFFS.view(out, "bsum"), COEFFS.view(out, "asum")
    for s, (bz, az) in enumerate(sections):
        b[s], a[s], bsum[s], asum[s] = bz, az, bz.sum(), az.sum()
    return out


def tables(policy: Any) -> tuple[PIDTable, PIDSetup]:
    """The schedule table and the constants of ``policy`` (a PIDPolicy or GainScheduledPIDPolicy)."""
    pid = policy.axes[0]
    schedule = getattr(policy, "schedule", None)
    signs = np.asarray(policy.accel_signs, dtype=float)
    no_filters = np.zeros((1, COEFFS.size))
    if schedule is None:                                   # fixed gains: a table of one row, read as nearest
        gains = GAINS.pack({"kp": pid.kp, "ki": pid.ki, "kd": pid.kd, "n": pid.n, "accel": policy.accel_gain,
                            "attitude": policy.attitude_gain})
        tb = PIDTable(np.zeros(1), np.zeros(1), np.zeros(1, np.int64), gains.reshape(-1, 1), no_filters)
        return tb, PIDSetup(pid.dt, policy.limit, VAR_FIXED, True, policy.accel_gain != 0.0, FILTERS_NONE, signs,
                            policy.attitude_gain != 0.0, 0)
    x, xs, cols = schedule._table
    rank = np.empty(x.size, np.int64)
    rank[np.argsort(x)] = np.arange(x.size)
    gains = np.zeros((GAINS.size, x.size))
    for name, col in (("kp", "kp"), ("ki", "ki"), ("kd", "kd"), ("n", "n"), ("accel", "accel_gain"),
                      ("attitude", "attitude_gain")):
        gains[GAINS.index(name)] = cols.get(col, 0.0)
    nearest = schedule.interpolation == "nearest"
    if schedule.filters is None:
        coeffs, filters = no_filters, FILTERS_NONE
    elif nearest:
        coeffs, filters = np.array([coefficients(f, pid.dt) for f in schedule.filters]), FILTERS_TABLE
    else:
        coeffs, filters = no_filters, FILTERS_ROWS
    variable = VAR_MACH if schedule.variable == "mach" else VAR_VALUE
    tb = PIDTable(x, xs, rank, np.ascontiguousarray(gains), coeffs)
    return tb, PIDSetup(pid.dt, policy.limit, variable, nearest, schedule.accel_gain is not None, filters, signs,
                        schedule.attitude_gain is not None, SECTIONS_PER_FILTER * schedule.filter_count)


def new_state(n: int) -> PIDState:
    """The state of ``n`` rows, as after :meth:`PIDBatch.reset` (no filter in use yet; the coefficient
    sums 1, so that a row without filters divides by nothing else)."""
    pid = PID_ROW.pack({"filt": -1.0}, n)
    filters = FILTER_ROW.pack({"bsum": 1.0, "asum": 1.0}, n)
    return PIDState(pid, filters)


class PIDBatch:
    """``n`` rows of a PID-family ``policy`` (:meth:`.pid.PIDPolicy.batch` says which), stepped together;
    the batched interface of :mod:`.batch`. :attr:`gimbal` (n, 2) [rad]: each row's last command (the
    policy's ``last_gimbal``)."""

    def __init__(self, policy: Any, n: int) -> None:
        self.name, self.n = policy.name, int(n)
        self.schedule = getattr(policy, "schedule", None)
        self.dt = float(policy.dt)
        self.tb, self.su = tables(policy)
        self.oc = obs_columns(policy)
        self.st = new_state(self.n)
        self._filters: list[Filter | None] = [None] * self.n     # FILTERS_ROWS: each row's filter
        self._none = np.zeros(self.n)
        self._key = _INFO_KEY.get(self.schedule.variable) if self.schedule is not None else None

    @property
    def gimbal(self) -> np.ndarray:
        return PID_ROW.view(self.st.pid, "gimbal")

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode (:meth:`.pid.PIDPolicy.reset`: the PIDs and the filters' start;
        the filter in use stays, as the policy's chains keep theirs)."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        filt = self.st.pid[w, PID_ROW.index("filt")]
        self.st.pid[w] = PID_ROW.zeros()
        self.st.pid[w, PID_ROW.index("filt")] = filt

    def values(self, info: dict[str, Any]) -> np.ndarray:
        """Each row's scheduling value (n,) from the batched ``info`` (mass [kg] or time [s]), or zeros."""
        if self.su.variable != VAR_VALUE:
            return self._none
        return np.asarray(info[self._key], dtype=np.float64)

    def prepare(self, rows: np.ndarray, obs: np.ndarray, value: np.ndarray) -> None:
        """Before the kernel: the filter of each row of a linearly interpolated schedule with filters, at its
        value of the scheduling variable (discretised when it changed)."""
        if self.su.filters != FILTERS_ROWS:
            return
        coeffs = self.st.filters[:, FILTER_ROW.slice("coeffs")]
        for j, b in enumerate(rows):
            v = float(obs[j, self.oc.mach]) * 10.0 if self.su.variable == VAR_MACH else float(value[b])
            filt = self.schedule.filter_at(v)
            if filt != self._filters[b]:
                coeffs[b] = coefficients(filt, self.dt)
                self._filters[b] = filt

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations (len(rows), n_obs)."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations).reshape(rows.size, -1)
        value = self.values(info)
        self.prepare(rows, obs, value)
        out = np.empty((rows.size, 2), np.float32)
        pid_act_k(self.tb, self.su, self.oc, self.st, rows, obs, value, out)
        return out
