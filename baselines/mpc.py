"""Constrained linear MPC of pitch and yaw on ``lqg``'s rows, scheduled over the flight, as a benchmark policy.

Each row of ``lqg``'s schedule (``baselines/schedules/smile_lqg.npz``, :mod:`.lqg`) holds the delayed
plant ``A, B, C`` of its plane, the Kalman gain ``M`` and the weights its regulator was designed with. The
MPC keeps the filter and the integral of ``lqg`` and replaces the regulator by the QP of
:mod:`.mpcqp`: the same LQ cost over ``horizon`` periods with the row's Riccati solution as terminal
weight, under the gimbal's angle limit and the servo's rate limit (both read from the env). Per plane and
control period, with the gyro sample ``y`` [rad/s] (the observation's rate error)::

    x_f = x_p + M (y - C x_p)              measurement update (the row's steady-state Kalman gain)
    U   = argmin J(U; [x_f, xi])           the QP; u = U_0, |u_k| <= limit, the servo's predicted rate
                                           within its limit (or |u_k - u_k-1| <= rate * dt)
    x_p <- A x_f + B u                     time update with the command sent
    xi  <- a xi - dt y                     leaky integral of the rate error (held as in ``lqg`` while the
                                           command is held by a limit and the integral would push further)

Without active limits the QP's solution is the unconstrained one, whose first move is the row's LQR
command ``-K_x x_f - K_i xi``: the MPC then flies ``lqg``'s law (to rounding; checked in the tests). The
rows are scheduled as in ``lqg`` (:func:`.lqgkernel.row_index`; at a switch the estimate is carried by
state name, the integral and the last command kept); off (``controller_on`` below 0.5) the command is 0
and the law frozen, restarting from zero at each engagement. One batch law, :class:`MPCLaw` (its compiled
period in :mod:`.mpckernel`, OSQP only for the rows whose plan breaks a limit), and its one-row face
:class:`MPCPolicy`. Needs OSQP (``pip install 'lvgym[control]'``).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError, require

from .lqg import PLANES, LQGLaw, LQGRow, LQGSchedule
from .mpckernel import OFF, QP, Limits, MPCState, PlanTables, mpc_finish_k, mpc_plan_k
from .mpcqp import CondensedQP, QPOptions, condense, terminal_weight

__all__ = ["MPCLaw", "MPCPolicy", "plan_tables", "row_qp", "smile_mpc"]


def row_qp(row: LQGRow, limit: float, rate_step: float, options: QPOptions = QPOptions()) -> CondensedQP:
    """The QP of one schedule row (:mod:`.mpcqp`) for the gimbal ``limit`` [rad] and ``rate_step`` [rad per
    period]: the row's regulator problem rebuilt from its weights, checked against its gains; the rate limit
    on the row's ``servo_rate`` state or on the command (``options.rate``)."""
    from .design.lqg_row import LQGWeights, regulator_problem

    if not row.weights:
        raise ConfigError(f"row {row.time_s:g} s.weights", (), "the design's weights (a schedule written by "
                          "lqg_design.save_schedule)")
    Aa, Ba, Q, R, a = regulator_problem(row.A, row.B, row.C, LQGWeights(*row.weights), row.dt, row.labels)
    P, K = terminal_weight(Aa, Ba, Q, R)
    ours, theirs = K[0], np.append(row.Kx[0], row.Ki)
    if abs(a - row.a) > 1e-12 or not np.allclose(ours, theirs, rtol=1e-6, atol=1e-6 * np.abs(theirs).max()):
        raise ConfigError(f"row {row.time_s:g} s.weights", row.weights, "the weights of the row's own gains "
                          f"(their Riccati gain differs from K_x, K_i by {np.abs(ours - theirs).max():.3g})")
    if options.rate == "servo":
        if "servo_rate" not in row.labels:
            raise ConfigError("mpc.rate", "servo", f"'command' (row {row.time_s:g} s has no servo_rate state)")
        H, F, Gr, Pr = condense(Aa, Ba, Q, R, P, options.horizon, row.labels.index("servo_rate"))
        return CondensedQP(H, F, limit, rate_step, options, Gr, Pr, row.dt)
    H, F, _, _ = condense(Aa, Ba, Q, R, P, options.horizon)
    return CondensedQP(H, F, limit, rate_step, options)


def plan_tables(qps: list[CondensedQP], N: int) -> PlanTables:
    """The plans' gains (and the servo's predicted rates) of one plane's schedule rows, padded to ``N`` states
    plus the integral (:class:`.mpckernel.PlanTables`)."""
    R, H = len(qps), qps[0].H.shape[0]
    gain, Pr, Gr = np.zeros((R, H, N + 1)), np.zeros((R, H, N + 1)), np.zeros((R, H, H))
    for i, qp in enumerate(qps):
        nz = qp.gain.shape[1]
        gain[i, :, :nz] = qp.gain
        if qp.servo:
            Pr[i, :, :nz], Gr[i] = qp.Pr, qp.Gr
    return PlanTables(gain, Pr, Gr)


class MPCLaw(BatchLaw):
    """Pitch and yaw MPC (module docstring) for ``n`` rows of the TVC envs. ``env``: the env it flies (gimbal
    limit [rad], rate limit, control period, delay and the observation's layout come from it, checked as
    :class:`.lqg.LQGLaw` checks them); ``schedule``: an :class:`.lqg.LQGSchedule`, a path or a name in
    ``baselines/schedules``; ``horizon`` [periods]; ``rate``: the rate limit on the model's ``servo`` rate or on
    the ``command`` (:class:`.mpcqp.QPOptions`). ``act`` reads ``info["time"]`` of every row. Each period the
    compiled :func:`.mpckernel.mpc_plan_k` plans every row; only a row whose plan breaks a limit calls OSQP,
    with a solver of its own per plane and schedule row (kept, as OSQP's own warm state, over the flights)."""

    def __init__(self, *, env: Any, schedule: LQGSchedule | str | Path = "smile_lqg", name: str = "mpc",
                 horizon: int = 15, rate: str = "servo", n: int = 1) -> None:
        require("osqp", "control", "the mpc policy")
        require("control", "control", "the mpc policy")
        lqg = LQGLaw(env=env, schedule=schedule, name=name)            # its checks of the env and schedule
        self.name, self.schedule, self.limit, self.dt, self.oc = name, lqg.schedule, lqg.limit, lqg.dt, lqg.oc
        self.options = QPOptions(horizon=horizon, rate=rate)
        rate_radps = float(np.radians(float(env.unwrapped.task.gimbal_rate_limit_degps)))
        self.rate_step = rate_radps * self.dt
        self.qps = {p: [row_qp(r, self.limit, self.rate_step, self.options) for r in self.schedule.rows[p]]
                    for p in PLANES}
        self.tables = {p: self.schedule.tables(self.schedule.rows[p]) for p in PLANES}
        self.plans = {p: plan_tables(self.qps[p], self.tables[p].A.shape[1]) for p in PLANES}
        self.limits = Limits(self.options.rate == "servo", self.limit, rate_radps, self.rate_step)
        self.allocate(n)

    def _rows(self, n: int) -> None:
        H = self.options.horizon
        self.states = {p: MPCState(np.zeros((n, self.tables[p].A.shape[1])), np.zeros(n), np.full(n, -1, np.int64),
                                   np.zeros(n, bool), np.zeros(n, bool), np.zeros(n), np.zeros((n, H)), np.zeros(n, bool))
                       for p in PLANES}
        self.solvers: dict[tuple[str, int, int], CondensedQP] = {}
        self.gimbal = np.zeros((n, 2))

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        for st in self.states.values():
            st.row[w], st.x[w], st.xi[w], st.was_on[w], st.saturated[w], st.u[w] = -1, 0.0, 0.0, False, False, 0.0
            st.has_warm[w] = False
        self.gimbal[w] = 0.0

    def _solver(self, plane: str, b: int, i: int) -> CondensedQP:
        key = (plane, b, i)
        if key not in self.solvers:
            self.solvers[key] = copy.copy(self.qps[plane][i])
        return self.solvers[key]

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations and the batched env's
        ``info`` (every row's ``time``)."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.asarray(observations, dtype=float).reshape(rows.size, -1)
        on = obs[:, self.oc.on] >= 0.5
        t = np.asarray(info["time"], dtype=np.float64)[rows]
        for ax, plane in enumerate(PLANES):
            tb, pt, st = self.tables[plane], self.plans[plane], self.states[plane]
            y = np.ascontiguousarray(obs[:, self.oc.err[ax]])
            z0, v = np.zeros((rows.size, tb.A.shape[1] + 1)), np.zeros(rows.size)
            status = np.zeros(rows.size, np.int64)
            mpc_plan_k(tb, pt, self.limits, st, rows, y, t, on, z0, v, status)
            solve = np.flatnonzero(status == QP)
            if solve.size:                           # a limit binds: OSQP for these rows
                u = np.empty(solve.size)
                for k, j in enumerate(solve.tolist()):
                    b = int(rows[j])
                    i = int(st.row[b])
                    nz = tb.dim[i] + 1
                    warm = st.warm[b] if st.has_warm[b] else None
                    U, s = self._solver(plane, b, i).qp(z0[j, :nz], float(st.u[b]), warm)
                    u[k] = U[0]
                    st.has_warm[b] = s is not None
                    if s is not None:
                        st.warm[b] = s
                mpc_finish_k(tb, pt, self.limits, st, rows[solve], y[solve], z0[solve], u, v[solve])
            self.gimbal[rows, ax] = np.where(status == OFF, 0.0, st.u[rows])
        return np.clip(self.gimbal[rows] / self.limit, -1.0, 1.0).astype(np.float32)

    @property
    def qp_counts(self) -> dict[str, int]:
        """OSQP's calls, fallbacks and iterations summed over both planes, every row and schedule row."""
        qps = list(self.solvers.values())
        return {"solves": sum(q.solves for q in qps), "fallbacks": sum(q.fallbacks for q in qps),
                "iterations": sum(q.iterations for q in qps)}


class MPCPolicy(RowFace):
    """Pitch and yaw MPC as a benchmark :class:`~lvgym.benchmark.policy.Policy` of the TVC envs: one row of
    :class:`MPCLaw` (its arguments). ``act`` needs ``info["time"]``."""

    def __init__(self, *, env: Any, schedule: LQGSchedule | str | Path = "smile_lqg", name: str = "mpc",
                 horizon: int = 15, rate: str = "servo") -> None:
        self.law = MPCLaw(env=env, schedule=schedule, name=name, horizon=horizon, rate=rate)


def smile_mpc(env: Any, name: str = "mpc", schedule: str = "smile_lqg", horizon: int = 15,
              rate: str = "servo") -> MPCPolicy:
    """The MPC on the rows of SMILE v1's LQG schedule (``baselines/schedules/smile_lqg.npz``); the env must
    fly the ``smile_v1`` vehicle."""
    vehicle = getattr(env.unwrapped.task, "vehicle", None)
    if vehicle != "smile_v1":
        raise ConfigError("env vehicle", vehicle, "'smile_v1' (the MPC flies the LQG rows designed for SMILE v1, "
                          "lvgym/SmileAscent-v1)")
    return MPCPolicy(env=env, schedule=schedule, name=name, horizon=horizon, rate=rate)


#: its kind in protocol v2's headline (lvgym.benchmark.headline): a classical design
smile_mpc.kind = "classical"  # type: ignore[attr-defined]
