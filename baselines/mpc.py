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
and the law frozen, restarting from zero at each engagement. Needs OSQP (``pip install 'lvgym[control]'``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lvgym.errors import ConfigError, require

from .lqg import PLANES, LQGPolicy, LQGRow, LQGSchedule
from .lqgkernel import row_index
from .mpcqp import CondensedQP, QPOptions, condense, terminal_weight

__all__ = ["MPCLaw", "MPCPolicy", "row_qp", "smile_mpc"]


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


class MPCLaw:
    """One plane's MPC (module docstring) for one episode: ``update(y, t, on) -> u`` [rad] with the gyro
    sample ``y`` [rad/s] at flight time ``t`` [s]. ``qps``: one :class:`.mpcqp.CondensedQP` per row."""

    def __init__(self, rows: tuple[LQGRow, ...], schedule: LQGSchedule, limit: float, rate_step: float,
                 options: QPOptions = QPOptions()) -> None:
        self.rows, self.tables = rows, schedule.tables(rows)
        self.qps = [row_qp(r, limit, rate_step, options) for r in rows]
        self.x = np.zeros(self.tables.A.shape[1])
        self.reset()

    def reset(self) -> None:
        """Restart as at the start of an episode."""
        self.row, self.xi, self.u, self.was_on, self.saturated = -1, 0.0, 0.0, False, False
        self.x[:] = 0.0
        for qp in self.qps:
            qp.reset()

    def update(self, y: float, t: float, on: bool) -> float:
        """The command [rad] for the gyro sample ``y`` [rad/s] at flight time ``t`` [s], the law on if ``on``."""
        if not on:
            self.was_on, self.saturated, self.u = False, False, 0.0
            return 0.0
        if not self.was_on:                                   # engagement: restart from zero
            self.reset()
            self.was_on = True
        i = int(row_index(self.tables, float(t)))
        if i != self.row:
            src = self.tables.carry[self.row, i] if self.row >= 0 else np.full(self.x.size, -1)
            self.x = np.where(src >= 0, self.x[np.maximum(src, 0)], 0.0)
            self.row = i
            self.qps[i].reset()
        r, qp = self.rows[i], self.qps[i]
        m = r.A.shape[0]
        xp = self.x[:m]
        xf = xp + r.M[:, 0] * (y - float(r.C[0] @ xp))
        z0 = np.append(xf, self.xi)
        U = qp.solve(z0, self.u)
        u = float(U[0])
        v = float(qp.gain[0] @ z0)                            # the unconstrained (lqg) command
        self.saturated = abs(u - v) > 1e-9 * qp.limit
        dxi = (r.a - 1.0) * self.xi - r.dt * y
        if not (self.saturated and (v - u) * (qp.gain[0, -1] * dxi) > 0.0):
            self.xi += dxi
        self.x[:m] = r.A @ xf + r.B[:, 0] * u
        self.u = u
        return u


class MPCPolicy:
    """Pitch and yaw MPC (module docstring) as a benchmark :class:`~lvgym.benchmark.policy.Policy` of the
    TVC envs. ``env``: the env it flies (gimbal limit [rad], rate limit, control period, delay and the
    observation's layout come from it, checked as :class:`.lqg.LQGPolicy` checks them); ``schedule``: an
    :class:`.lqg.LQGSchedule`, a path or a name in ``baselines/schedules``; ``horizon`` [periods];
    ``rate``: the rate limit on the model's ``servo`` rate or on the ``command`` (:class:`.mpcqp.QPOptions`).
    ``act`` needs ``info["time"]``."""

    def __init__(self, *, env: Any, schedule: LQGSchedule | str | Path = "smile_lqg", name: str = "mpc",
                 horizon: int = 15, rate: str = "servo") -> None:
        require("osqp", "control", "the mpc policy")
        require("control", "control", "the mpc policy")
        lqg = LQGPolicy(env=env, schedule=schedule, name=name)         # its checks of the env and schedule
        self.name, self.schedule, self.limit, self.dt = name, lqg.schedule, lqg.limit, lqg.dt
        self._i_err, self._i_on = lqg._i_err, lqg._i_on
        self.options = QPOptions(horizon=horizon, rate=rate)
        rate = np.radians(float(env.unwrapped.task.gimbal_rate_limit_degps))     # rad/s
        self.rate_step = float(rate) * self.dt
        self.axes = [MPCLaw(self.schedule.rows[p], self.schedule, self.limit, self.rate_step, self.options)
                     for p in PLANES]
        self.last_gimbal = np.zeros(2)

    def reset(self) -> None:
        for law in self.axes:
            law.reset()
        self.last_gimbal = np.zeros(2)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        on = float(obs[self._i_on]) >= 0.5
        t = float(info["time"])
        self.last_gimbal = np.array([law.update(float(obs[i]), t, on) for law, i in zip(self.axes, self._i_err)])
        return np.clip(self.last_gimbal / self.limit, -1.0, 1.0).astype(np.float32)

    @property
    def qp_counts(self) -> dict[str, int]:
        """OSQP's calls, fallbacks and iterations summed over both planes and every row (since construction)."""
        qps = [qp for law in self.axes for qp in law.qps]
        return {"solves": sum(q.solves for q in qps), "fallbacks": sum(q.fallbacks for q in qps),
                "iterations": sum(q.iterations for q in qps)}


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
