"""A privileged linear bound: how far below lqg could a controller that knows the state and the wind go, on the
linear flight loop, at the same actuator activity?

    python -m experiments.protocol_v2_design.privileged                     # rows 10, 20 and 28.8 s of lqg
    python -m experiments.protocol_v2_design.privileged --rows 28.8

At each row, on the non-rigid pitch plant of ``lqg`` (``lqg_row.delayed_plant``: servo, vehicle with slosh
and bending, gyro filters, hold and v1's one period of delay) in v1's Dryden turbulence at the row's altitude
and airspeed (``experiments.lqg_headroom.headroom``: the wind enters where the aerodynamics see it):

- ``lqg``: the shipped row's compensator on the gyro sample (no gyro noise here: the turbulence alone);
- ``LQR``: full state feedback, the wind unknown (the LQR on the plant alone);
- ``FI``: full information, the plant's state and the Dryden filter's state (the wind now and its
  dynamics) fed back: the H2-optimal controller of a privileged agent without preview.

Both LQRs weigh the body rate against the commanded gimbal rate (the previous command is a state, the
command's change the input) and the command's level; they are reported at the weights whose RMS commanded
rate equals lqg's and whose RMS command is at most lqg's, the lowest body rate among those: the best a
privileged agent reaches with the actuator activity lqg spends (stationary covariances, no simulation; no
margin is asked of it). The figures are
RMS: body rate [deg/s], command [deg], commanded rate ``(u[k] - u[k-1]) / dt`` [deg/s].
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import control
import numpy as np
import scipy.linalg as sla
from lvgym.baselines.design.lqg_design import SMILE_PHASES_S, _op
from lvgym.baselines.design.lqg_row import (
    closed_loop,
    compensator,
    delayed_plant,
    plant_labels,
)

from experiments.lqg_headroom.headroom import (
    PLANE_RATE,
    dryden_filter,
    row_turbulence,
    shipped_row,
    wind_input,
)
from lvgym.commandline import arg, parse

__all__ = ["constrained", "lqg_figures", "lqr_figures", "matched", "privileged_rows", "stationary"]

PROG = "python -m experiments.protocol_v2_design.privileged"


def stationary(Acl: np.ndarray, Q: np.ndarray, Cy: np.ndarray, Cu: np.ndarray, dt: float) -> tuple[float, float, float]:
    """RMS of ``y = Cy x``, of ``u = Cu x`` and of ``(u[k] - u[k-1]) / dt`` for ``x[k+1] = Acl x[k] + w``,
    ``cov w = Q`` (inf when unstable)."""
    if np.abs(np.linalg.eigvals(Acl)).max() >= 1.0:
        return math.inf, math.inf, math.inf
    P = sla.solve_discrete_lyapunov(Acl, Q)
    vy = (Cy @ P @ Cy.T).item()
    vu = (Cu @ P @ Cu.T).item()
    cu = (Cu @ Acl @ P @ Cu.T).item()                 # cov(u[k+1], u[k])
    return math.sqrt(max(vy, 0.0)), math.sqrt(max(vu, 0.0)), math.sqrt(max(2.0 * (vu - cu), 0.0)) / dt


@cache
def _plant(t: float, plane: str = "pitch"):
    op = _op("smile", t, "nonrigid", SMILE_PHASES_S[0][1] + 0.5)
    A, B, C, _ = delayed_plant(op, plane)
    labels = plant_labels(op, plane)
    turb = row_turbulence(op)
    dt = float(op.task.control_dt_s)
    Aw, Qw, Cw = dryden_filter(turb, dt)
    return op, A, B, C, labels, turb, dt, Aw, Qw, Cw


def lqg_figures(t: float, plane: str = "pitch") -> dict[str, float]:
    """The shipped lqg row at ``t`` in the turbulence: RMS rate, command and commanded rate (deg, deg/s)."""
    _, A, B, C, labels, turb, dt, Aw, Qw, Cw = _plant(t, plane)
    comp = compensator(shipped_row(t, plane))
    Alk, _ = closed_loop(A, B, C, comp)
    n, nlk, nw = A.shape[0], Alk.shape[0], Aw.shape[0]
    Bw = np.vstack([wind_input(A, labels, plane), np.zeros((nlk - n, 1))])
    Acl = np.block([[Alk, Bw @ Cw], [np.zeros((nw, nlk)), Aw]])
    Q = np.zeros_like(Acl)
    Q[nlk:, nlk:] = Qw
    Ck, Dk = (np.asarray(m, float) for m in (comp.C, comp.D))
    Cu = np.hstack([Dk @ C, Ck, np.zeros((1, nw))])           # u = Dk y + Ck x_c
    Cy = np.zeros((1, Acl.shape[0]))
    Cy[0, labels.index(PLANE_RATE[plane])] = 1.0
    y, u, du = stationary(Acl, Q, Cy, Cu, dt)
    return {"t": t, "alt_km": turb.altitude / 1e3, "sigma": turb.sigma, "length": turb.length,
            "rate": math.degrees(y), "cmd": math.degrees(u), "cmd_rate": math.degrees(du)}


def lqr_figures(t: float, r: float, wind_known: bool, q_u: float = 0.0, plane: str = "pitch") -> dict[str, float]:
    """Full state feedback (``wind_known``: with the Dryden filter's state) weighing the body rate against the
    commanded rate: the state carries the previous command ``u[k-1]`` and the input is the change ``v = u[k] -
    u[k-1]``; the cost per step is ``omega^2 + q_u u[k-1]^2 + r (v / dt)^2`` (rad, s)."""
    _, A, B, _, labels, _, dt, Aw, Qw, Cw = _plant(t, plane)
    n, nw = A.shape[0], Aw.shape[0]
    nx = n + 1 + nw                                   # plant, previous command, wind filter
    Aa = np.zeros((nx, nx))
    Aa[:n, :n] = A
    Aa[:n, n:n + 1] = B
    Aa[n, n] = 1.0
    Aa[:n, n + 1:] = wind_input(A, labels, plane) @ Cw
    Aa[n + 1:, n + 1:] = Aw
    Ba = np.zeros((nx, 1))
    Ba[:n] = B
    Ba[n] = 1.0
    i = labels.index(PLANE_RATE[plane])
    Cy = np.zeros((1, nx))
    Cy[0, i] = 1.0
    Q = Cy.T @ Cy + 1e-10 * np.eye(nx)
    Q[n, n] += q_u
    R = np.array([[r / dt ** 2]])
    if wind_known:
        K = np.asarray(control.dlqr(Aa, Ba, Q, R)[0], float)
    else:
        m = n + 1
        K = np.hstack([np.asarray(control.dlqr(Aa[:m, :m], Ba[:m], Q[:m, :m], R)[0], float), np.zeros((1, nw))])
    Acl = Aa - Ba @ K
    Qn = np.zeros_like(Acl)
    Qn[n + 1:, n + 1:] = Qw
    Cu = np.zeros((1, nx))
    Cu[0, n] = 1.0
    Cu = Cu - K                                       # u[k] = u[k-1] + v[k]
    y, u, du = stationary(Acl, Qn, Cy, Cu, dt)
    return {"r": r, "rate": math.degrees(y), "cmd": math.degrees(u), "cmd_rate": math.degrees(du)}


def matched(t: float, wind_known: bool, target_deg_s: float, q_u: float = 0.0, lo: float = 1e-10, hi: float = 1e4,
            iters: int = 30) -> dict[str, float]:
    """:func:`lqr_figures` at the weight whose RMS commanded rate is ``target_deg_s`` (bisection in log r)."""
    a, b = math.log(lo), math.log(hi)
    best = lqr_figures(t, math.exp(b), wind_known, q_u)
    for _ in range(iters):
        m = 0.5 * (a + b)
        f = lqr_figures(t, math.exp(m), wind_known, q_u)
        if f["cmd_rate"] > target_deg_s:
            a = m
        else:
            b = m
        best = f
    return {**best, "q_u": q_u}


def constrained(t: float, wind_known: bool, cmd_deg: float, cmd_rate_deg_s: float, iters: int = 30) -> dict[str, float]:
    """The weights ``(r, q_u)`` at which the RMS commanded rate is ``cmd_rate_deg_s`` and the RMS command at most
    ``cmd_deg``: :func:`matched` at the smallest ``q_u`` (bisection in log ``q_u`` over 1e-6 .. 1e6) whose command
    is within ``cmd_deg`` (``q_u = 0`` when that one is)."""
    f0 = matched(t, wind_known, cmd_rate_deg_s, 0.0)
    if f0["cmd"] <= cmd_deg:
        return f0
    a, b = math.log(1e-6), math.log(1e6)
    best = matched(t, wind_known, cmd_rate_deg_s, 1e6)
    for _ in range(iters):
        m = 0.5 * (a + b)
        f = matched(t, wind_known, cmd_rate_deg_s, math.exp(m))
        if f["cmd"] <= cmd_deg:
            b, best = m, f
        else:
            a = m
    return best


def privileged_rows(rows: Sequence[float]) -> list[dict[str, float]]:
    """Per row: lqg's figures and the LQR's and the FI controller's at lqg's commanded rate with a command no
    larger (RMS) than lqg's (:func:`constrained`)."""
    out = []
    for t in rows:
        base = lqg_figures(t)
        rec = {**base}
        for name, known in (("lqr", False), ("fi", True)):
            rec.update({f"{name}_{k}": v for k, v in constrained(t, known, base["cmd"], base["cmd_rate"]).items()})
        out.append(rec)
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.privileged --help``)."""

    rows: list[float] = arg(default_factory=lambda: [10.0, 20.0, 28.8], metavar="T")
    """rows of the lqg schedule [s]"""


def main(argv: Sequence[str] | None = None) -> int:
    a = parse(Args, argv, PROG, __doc__)
    recs = privileged_rows(a.rows)
    w = sys.stdout.write
    w("| row [s] | altitude [km] | Dryden sigma [m/s], L [m] | controller | r, q_u | body rate RMS [deg/s] | of lqg's | "
      "command RMS [deg] | commanded rate RMS [deg/s] |\n|---:|---:|---|---|---:|---:|---:|---:|---:|\n")
    for r in recs:
        w(f"| {r['t']:g} | {r['alt_km']:.1f} | {r['sigma']:.2f}, {r['length']:.0f} | lqg (shipped) | - | {r['rate']:.3f} | 1.00 "
          f"| {r['cmd']:.3f} | {r['cmd_rate']:.2f} |\n")
        for name, label in (("lqr", "LQR, state known"), ("fi", "FI, state and wind known")):
            w(f"|  |  |  | {label} | {r[name + '_r']:.2g}, {r[name + '_q_u']:g} | {r[name + '_rate']:.3f} | {r[name + '_rate'] / r['rate']:.2f} "
              f"| {r[name + '_cmd']:.3f} | {r[name + '_cmd_rate']:.2f} |\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
