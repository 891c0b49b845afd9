"""The PID family for the rows of a batched env (:class:`PIDBatch`): :meth:`.pid.PIDPolicy.batch`.

Built once from a policy object (a :class:`.pid.PIDPolicy` of fixed gains or a
:class:`.pid.GainScheduledPIDPolicy`: ``pid``, ``pid-thesis``, ``gs-pid``, ``gs-pid-thesis``,
``gs-pid-flex``), it steps every row in one call of the compiled :func:`.pidkernel.pid_act_k`, the per-row
policy's operations in the per-row policy's order. The structural filters of a nearest-row schedule
(every flex schedule) are discretised once per schedule row here; those of a linearly interpolated
schedule change with every value of the scheduling variable and are discretised in Python
(:meth:`.filters.StructuralFilter.discrete`, the per-row policy's own call) whenever a row's filter changes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .filters import StructuralFilter
from .pidkernel import (FILTERS_NONE, FILTERS_ROWS, FILTERS_TABLE, VAR_FIXED, VAR_MACH, VAR_VALUE, ObsColumns,
                        PIDSetup, PIDState, PIDTable, pid_act_k)

__all__ = ["PIDBatch", "new_state", "obs_columns", "tables"]

#: the info key of each scheduling variable read from the info (Mach comes from the observation)
_INFO_KEY = {"mass": "mass", "time": "time"}


def obs_columns(policy: Any) -> ObsColumns:
    """Where ``policy`` (a :class:`.pid.PIDPolicy`) reads its observation entries."""
    acc = np.asarray(policy._i_acc if policy._i_acc is not None else [-1, -1], dtype=np.int64)
    return ObsColumns(np.asarray(policy._i_err, dtype=np.int64), acc, int(policy._i_on), int(policy._i_mach), -1)


def _filter_blocks(filters: list[StructuralFilter], dt: float) -> tuple[np.ndarray, ...]:
    """``fb``, ``fa`` (m, S, 3), ``fbsum``, ``fasum`` (m, S) of ``filters`` discretised at ``dt`` [s]."""
    coeffs = [f.discrete(dt) for f in filters]
    S = len(coeffs[0])
    fb, fa, fbsum, fasum = np.zeros((len(filters), S, 3)), np.zeros((len(filters), S, 3)), \
        np.zeros((len(filters), S)), np.zeros((len(filters), S))
    for i, sections in enumerate(coeffs):
        _write(sections, fb[i], fa[i], fbsum[i], fasum[i])
    return fb, fa, fbsum, fasum


def _write(sections: list, fb: np.ndarray, fa: np.ndarray, fbsum: np.ndarray, fasum: np.ndarray) -> None:
    """One filter's discrete sections into its coefficient rows (the sums as ``FilterChain.reset`` takes them)."""
    for s, (bz, az) in enumerate(sections):
        fb[s], fa[s], fbsum[s], fasum[s] = bz, az, bz.sum(), az.sum()


def tables(policy: Any) -> tuple[PIDTable, PIDSetup]:
    """The schedule table and the constants of ``policy`` (a PIDPolicy or GainScheduledPIDPolicy)."""
    pid = policy.axes[0]
    schedule = getattr(policy, "schedule", None)
    signs = np.asarray(policy.accel_signs, dtype=float)
    if schedule is None:                                   # fixed gains: a table of one row, read as nearest
        one = lambda v: np.array([float(v)])               # noqa: E731
        tb = PIDTable(one(0.0), one(0.0), np.zeros(1, np.int64), one(pid.kp), one(pid.ki), one(pid.kd), one(pid.n),
                      one(policy.accel_gain), *_no_filters())
        return tb, PIDSetup(pid.dt, policy.limit, VAR_FIXED, True, policy.accel_gain != 0.0, FILTERS_NONE, signs)
    x, xs, cols = schedule._table
    rank = np.empty(x.size, np.int64)
    rank[np.argsort(x)] = np.arange(x.size)
    accel = cols.get("accel_gain", np.zeros(x.size))
    nearest = schedule.interpolation == "nearest"
    if schedule.filters is None:
        blocks, filters = _no_filters(), FILTERS_NONE
    elif nearest:
        blocks, filters = _filter_blocks(list(schedule.filters), pid.dt), FILTERS_TABLE
    else:
        blocks, filters = _no_filters(len(schedule.filter_at(schedule.points[0]).discrete(pid.dt))), FILTERS_ROWS
    tb = PIDTable(x, xs, rank, cols["kp"], cols["ki"], cols["kd"], cols["n"], accel, *blocks)
    variable = VAR_MACH if schedule.variable == "mach" else VAR_VALUE
    return tb, PIDSetup(pid.dt, policy.limit, variable, nearest, schedule.accel_gain is not None, filters, signs)


def _no_filters(S: int = 0) -> tuple[np.ndarray, ...]:
    return np.zeros((1, S, 3)), np.zeros((1, S, 3)), np.ones((1, S)), np.ones((1, S))


def new_state(n: int, S: int) -> PIDState:
    """The state of ``n`` rows with filters of ``S`` sections, as after :meth:`PIDBatch.reset`."""
    z2 = lambda: np.zeros((n, 2))                      # noqa: E731
    return PIDState(z2(), z2(), z2(), np.zeros((n, 2), bool), np.zeros((n, 2), bool), np.zeros(n, bool),
                    np.zeros((n, 2, S)), np.zeros((n, 2, S)), np.zeros((n, S, 3)), np.zeros((n, S, 3)),
                    np.ones((n, S)), np.ones((n, S)), np.full(n, -1, np.int64), z2())


class PIDBatch:
    """``n`` rows of a PID-family ``policy`` (:meth:`.pid.PIDPolicy.batch` says which), stepped together; the batched interface
    of :mod:`.batch`. ``gimbal`` (n, 2) [rad]: each row's last command (the policy's ``last_gimbal``)."""

    def __init__(self, policy: Any, n: int) -> None:
        self.name, self.n = policy.name, int(n)
        self.schedule = getattr(policy, "schedule", None)
        self.dt = float(policy.dt)
        self.tb, self.su = tables(policy)
        self.oc = obs_columns(policy)
        self.st = new_state(self.n, self.tb.fb.shape[1])
        self._filters: list[StructuralFilter | None] = [None] * self.n     # FILTERS_ROWS: each row's filter
        self._none = np.zeros(self.n)
        self._key = _INFO_KEY.get(self.schedule.variable) if self.schedule is not None else None

    @property
    def gimbal(self) -> np.ndarray:
        return self.st.gimbal

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode (:meth:`.pid.PIDPolicy.reset`: the PIDs and the filters' start)."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        st = self.st
        st.integral[w], st.deriv[w], st.e_prev[w], st.has_prev[w], st.saturated[w] = 0.0, 0.0, 0.0, False, False
        st.filtering[w], st.gimbal[w] = False, 0.0

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
        st = self.st
        for j, b in enumerate(rows):
            v = float(obs[j, self.oc.mach]) * 10.0 if self.su.variable == VAR_MACH else float(value[b])
            filt = self.schedule.filter_at(v)
            if filt != self._filters[b]:
                _write(filt.discrete(self.dt), st.fb[b], st.fa[b], st.fbsum[b], st.fasum[b])
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
