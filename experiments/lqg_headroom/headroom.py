"""How much of the turbulence's rate error a linear design can still remove, and what that costs in margins.

    python -m experiments.lqg_headroom.headroom                        # rows 10, 20, 28.8 and 36 s of the lqg schedule, full grid
    python -m experiments.lqg_headroom.headroom --rows 10 --grid small
    python -m experiments.lqg_headroom.headroom --write-schedule baselines/schedules/smile_lqg_front.npz --slack 2 0.6

The Dryden turbulence causes most of `smile-v1`'s score (``python -m experiments.error_budget.budget``). At a row
of the ``lqg`` schedule (its frozen flight time, the pitch plane; the yaw plane is the same vehicle), this
module closes a family of LQG designs around the row's linear flight loop (:mod:`.lqg_row`: servo, vehicle,
gyro chain, one period of delay) and measures for each:

- ``rate_rms``: the RMS body pitch rate [rad/s] under the v1 turbulence at the row (transverse Dryden
  component, ``moderate``, scale length and intensity of MIL-F-8785C at the row's altitude,
  :func:`row_turbulence`; :func:`dryden_filter`) plus the gyro's angle random walk, on the rigid and
  the non-rigid plants (:func:`turbulence_rms`). The wind enters the loop where it acts, on the
  relative velocity: its input matrix is minus the lateral-velocity column of the plant (every
  lateral-velocity term of the linear model is aerodynamic, :func:`wind_input`);
- the linear margins with the loop broken at the plant input (:func:`loop_summary`): gain margin up
  (``gm``) and down (``grm``) on the rigid and non-rigid plants, the delay margin (``dm``: the smallest
  ``phase / frequency`` over every gain crossover, the phase counted from -180 deg downwards, so a
  crossover of negative phase margin counts the extra lag that wraps it to -540 deg), and the
  design targets of :class:`.lqg_design.MarginTargets` on the row's neighbouring and dispersed plants.

The family is the LQG weights of :class:`.lqg_row.LQGWeights` on :data:`GRIDS`, each designed with and
without the turbulence in its model (``wind_noise``: the Dryden filter's states appended to the plant,
driven in the Kalman filter by ``wind_noise`` times the filter's own process noise, so that the
estimator tracks the wind and the regulator cancels it: :func:`wind_design`; 0: without).

:func:`headroom` answers, against the shipped row: what is the lowest ``rate_rms`` of a design whose every
margin is no worse than the shipped row's, and how much lower does it get when the margins may lose a
little (:data:`SLACKS`: gain margins up and down by ``slack_db``, delay margins to ``dm_fraction`` of the
shipped row's)? The family samples the LQG designs, which hold the optimal linear controller of every
quadratic cost of this linear plant under Gaussian turbulence and noise; it is a sample, not a bound over
every controller. ``--write-schedule`` writes the shipped schedule with each studied row replaced, in
both planes, by the design of lowest RMS within one margin loss (``--slack``; :func:`front_schedule`):
the ``lqg-front`` policy flies it. docs/training.md ("The turbulence against the margins") gives the
numbers.
"""

from __future__ import annotations

import itertools
import math
import sys
import time
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

import control
import numpy as np
import scipy.linalg as sla

from lvgym.commandline import arg, option_number, parse
from lvgym.environment.turbulence import INTENSITIES, dryden_scales
from lvgym.errors import ConfigError

from lvgym.baselines.design.flightloop import flight_plant, mode_frequencies
from lvgym.baselines.lqg import LQGSchedule
from lvgym.baselines.design.lqg_design import (_SEARCH_W, PLANE_VELOCITY, SMILE_PHASES_S, SMILE_ROWS_S, MarginTargets, _op, assess,
                         row_intervals, row_neighbours, shortfall)
from lvgym.baselines.design.lqg_row import (GYRO_ARW_RAD_PER_SQRT_S, LQGWeights, RowDesign, closed_loop, closed_loop_growth, compensator,
                      delayed_plant, design_row, kalman_gain, open_loop, plant_labels, regulator, response)
from lvgym.baselines.design.noise import gyro_noise

PROG = "python -m experiments.lqg_headroom.headroom"
#: the body rate of each plane (what the score integrates)
PLANE_RATE = {"pitch": "omega_y", "yaw": "omega_z"}
#: the weights and the wind model's noise tried: ``full`` for the study, ``small`` for the tests
GRIDS: dict[str, dict[str, tuple[float, ...]]] = {
    "full": {"q_int": (10.0, 100.0, 300.0, 1000.0), "r_gimbal": (3.0, 10.0, 30.0, 100.0), "w_gimbal": (1e-8, 1e-7),
             "q_modes": (1e-5, 1e-4), "w_modes": (1e-3, 1e-2), "wind_noise": (0.0, 0.01, 0.1, 1.0)},
    "small": {"q_int": (100.0, 1000.0), "r_gimbal": (10.0, 30.0), "wind_noise": (0.0, 0.1)},
}
DEFAULT_ROWS = (10.0, 20.0, 28.8, 36.0)
#: the margin loss of ``--write-schedule``'s designs
DEFAULT_SLACK = (2.0, 0.6)
#: margin losses allowed: (gain margins [dB], delay margins kept as a fraction of the shipped row's)
SLACKS = ((0.0, 1.0), (0.5, 0.9), (1.0, 0.8), (2.0, 0.6), (3.0, 0.4))
MARGINS = ("gm_nonrigid", "gm_rigid", "grm_nonrigid", "dm_nonrigid_ms", "dm_rigid_ms")


@dataclass(frozen=True)
class Turbulence:
    """The transverse Dryden turbulence a row flies through: intensity ``sigma`` [m/s], scale length
    ``length`` [m], airspeed ``speed`` [m/s] (the time constant is ``length / speed``), altitude [m]."""

    sigma: float
    length: float
    speed: float
    altitude: float


def row_turbulence(op: Any, intensity: str = "moderate") -> Turbulence:
    """The v1 turbulence at the operating point ``op``: MIL-F-8785C's transverse scale length and intensity
    at its altitude (``lvgym.environment.turbulence.dryden_scales``) and its airspeed."""
    alt = op.condition("altitude")
    lengths, sigmas = dryden_scales(alt, *INTENSITIES[intensity])
    return Turbulence(float(sigmas[1]), float(lengths[1]), op.condition("airspeed"), alt)


def dryden_filter(turb: Turbulence, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A_w, Q_w, C_w)``: the transverse Dryden filter ``(1 + sqrt(3) tau s) / (1 + tau s)^2`` (``tau =
    length / speed``) sampled exactly at ``dt`` [s] (Van Loan), its process noise covariance scaled so that
    the stationary wind ``C_w x_w`` has the variance ``sigma^2``."""
    tau = turb.length / turb.speed
    g = control.ss(control.tf([math.sqrt(3.0) * tau, 1.0], [tau * tau, 2.0 * tau, 1.0]))
    Ac, Bc, Cc = (np.asarray(m, float) for m in (g.A, g.B, g.C))
    n = Ac.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -Ac, Bc @ Bc.T, Ac.T
    E = sla.expm(M * dt)
    Ad = E[n:, n:].T
    Qd = Ad @ E[:n, n:]
    var = (Cc @ sla.solve_discrete_lyapunov(Ad, Qd) @ Cc.T).item()
    return Ad, Qd * turb.sigma ** 2 / var, Cc


def wind_input(A: np.ndarray, labels: tuple[str, ...], plane: str) -> np.ndarray:
    """The input matrix (n, 1) of a wind [m/s] along the plane's lateral axis held over a control period:
    the aerodynamics see ``v - w``, so it is ``-(A[:, v] - e_v)`` for the sampled plant ``A`` (exact for a
    wind held over the period when every term in the lateral velocity ``v`` is aerodynamic)."""
    j = labels.index(PLANE_VELOCITY[plane])
    e = np.zeros(A.shape[0])
    e[j] = 1.0
    return -(A[:, j] - e)[:, None]


def wind_design(op: Any, plane: str, w: LQGWeights, wind_noise: float, turb: Turbulence) -> RowDesign:
    """The LQG design of :func:`.lqg_row.design_row` with the turbulence in its model (module docstring);
    ``wind_noise`` 0 is ``design_row`` itself."""
    if wind_noise == 0.0:
        return design_row(op, plane, w)
    A, B, C, Gw = delayed_plant(op, plane)
    labels = plant_labels(op, plane)
    dt = float(op.task.control_dt_s)
    Aw, Qw, Cw = dryden_filter(turb, dt)
    n, nw = A.shape[0], Aw.shape[0]
    Aa = np.block([[A, wind_input(A, labels, plane) @ Cw], [np.zeros((nw, n)), Aw]])
    Ba, Ca = np.vstack([B, np.zeros((nw, 1))]), np.hstack([C, np.zeros((1, nw))])
    labels_a = tuple(labels) + tuple(f"wind_{i}" for i in range(nw))
    Kx, Ki, a = regulator(Aa, Ba, Ca, w, dt, labels_a)
    extra = np.zeros((n + nw, n + nw))
    extra[n:, n:] = wind_noise * Qw
    arw = float(getattr(op.task, "gyro_arw_rad_per_sqrt_s", GYRO_ARW_RAD_PER_SQRT_S))
    M = kalman_gain(Aa, Ca, np.vstack([Gw, np.zeros((nw, 1))]), w, dt, labels_a, arw, extra)
    return RowDesign(float(op.t), plane, Aa, Ba, Ca, Kx, Ki, M, a, dt, w, labels_a)


def turbulence_rms(d: Any, op: Any, plane: str, turb: Turbulence, noise: bool = True) -> float:
    """RMS body rate [rad/s] of the row's compensator ``d`` (a :class:`.lqg_row.RowDesign`) on the plant of
    ``op`` under the turbulence ``turb`` and, with ``noise``, the gyro's white noise (its angle random walk
    over a control period); inf if the loop is unstable."""
    A, B, C, _ = delayed_plant(op, plane)
    labels = plant_labels(op, plane)
    Aw, Qw, Cw = dryden_filter(turb, d.dt)
    Alk, By = closed_loop(A, B, C, compensator(d))           # the plant's states, then the compensator's
    n, nlk, nw = A.shape[0], Alk.shape[0], Aw.shape[0]
    Bw = np.vstack([wind_input(A, labels, plane), np.zeros((nlk - n, 1))])
    Acl = np.block([[Alk, Bw @ Cw], [np.zeros((nw, nlk)), Aw]])   # the wind filter's states last
    if np.abs(np.linalg.eigvals(Acl)).max() >= 1.0:
        return math.inf
    Q = np.zeros_like(Acl)
    Q[nlk:, nlk:] = Qw
    if noise:
        Bn = np.vstack([By, np.zeros((nw, 1))]) * gyro_noise(op)[0]
        Q = Q + Bn @ Bn.T
    P = sla.solve_discrete_lyapunov(Acl, Q)
    i = labels.index(PLANE_RATE[plane])
    return float(math.sqrt(max(P[i, i], 0.0)))


def delay_margin_s(r: np.ndarray, w: np.ndarray) -> float:
    """The smallest extra delay [s] that brings a gain crossover of the open-loop response ``r`` on ``w``
    [rad/s] to -180 deg (module docstring); inf without a crossover."""
    lm = np.log(np.abs(r))
    out = math.inf
    for i in np.nonzero(np.sign(lm[:-1]) != np.sign(lm[1:]))[0]:
        f = lm[i] / (lm[i] - lm[i + 1])
        z = r[i] + f * (r[i + 1] - r[i])
        wc = float(w[i] + f * (w[i + 1] - w[i]))
        pm = (math.degrees(math.atan2(z.imag, z.real)) + 180.0) % 360.0
        out = min(out, math.radians(pm) / wc)
    return out


@dataclass
class RowLoops:
    """A row's plants: the rigid and non-rigid operating points, every plant of the design targets
    (``rigid``, ``nonrigid``, the interval's ends, the dispersed slosh), their responses on the search
    grid, the modes and the turbulence."""

    t: float
    op_rigid: Any
    op_nonrigid: Any
    plants: dict[str, control.StateSpace]
    responses: dict[str, np.ndarray]
    modes: dict[str, list[float]]
    turbulence: Turbulence


def row_loops(t: float, plane: str = "pitch") -> RowLoops:
    """The plants of the schedule row at ``t`` [s] (one of :data:`.lqg_design.SMILE_ROWS_S`), built as
    :func:`.lqg_design.design_schedule` builds them."""
    if t not in SMILE_ROWS_S:
        raise ConfigError("rows", t, f"a row of the lqg schedule {list(SMILE_ROWS_S)}")
    upper_after = SMILE_PHASES_S[0][1] + 0.5
    interval = dict(zip(SMILE_ROWS_S, row_intervals(SMILE_ROWS_S, SMILE_PHASES_S)))[t]
    op_n, op_r = _op("smile", t, "nonrigid", upper_after), _op("smile", t, "rigid", upper_after)
    ops = {"rigid": op_r, "nonrigid": op_n, **row_neighbours("smile", t, interval, op_n, upper_after)}
    plants = {k: flight_plant(o, plane) for k, o in ops.items()}
    return RowLoops(t, op_r, op_n, plants, {k: response(g, _SEARCH_W) for k, g in plants.items()},
                    mode_frequencies(op_n, plane), row_turbulence(op_n))


def loop_summary(d: Any, loops: RowLoops, plane: str = "pitch",
                 tg: MarginTargets = MarginTargets()) -> dict[str, Any] | None:
    """Margins, targets' shortfall and turbulence RMS of the compensator ``d`` on the row's plants; None
    if a loop is unstable."""
    comp = compensator(d)
    if any(closed_loop_growth(open_loop(comp, g)) >= 1e-4 for g in loops.plants.values()):
        return None
    a = assess(d, loops.plants, loops.modes, _SEARCH_W, loops.responses)
    kr = -response(comp, _SEARCH_W)
    out = {"shortfall": shortfall(a, tg)}
    for model, op in (("rigid", loops.op_rigid), ("nonrigid", loops.op_nonrigid)):
        out[f"rate_rms_{model}"] = turbulence_rms(d, op, plane, loops.turbulence)
        out[f"gm_{model}"] = a[model]["gain_margin_db"]
        out[f"grm_{model}"] = a[model]["gain_reduction_margin_db"]
        out[f"dm_{model}_ms"] = 1000.0 * delay_margin_s(kr * loops.responses[model], _SEARCH_W)
    return out


def no_worse(m: dict[str, Any], base: dict[str, Any], slack_db: float = 0.0, dm_fraction: float = 1.0,
             tol: float = 1e-6) -> bool:
    """Every margin of :data:`MARGINS` no worse than the shipped row's, less ``slack_db`` [dB] on the gain
    margins (up, and down: as far from 0 dB) and with ``dm_fraction`` of its delay margins, within a
    relative ``tol`` (the shipped weights designed again give the shipped row to rounding)."""
    ok = True
    for k in MARGINS:
        b = base[k]
        if k.startswith("grm"):
            ok &= m[k] <= b + slack_db + tol * abs(b)
        elif k.startswith("dm"):
            ok &= m[k] >= dm_fraction * b - tol * abs(b)
        else:
            ok &= m[k] >= b - slack_db - tol * abs(b)
    return bool(ok)


def candidates(grid: dict[str, tuple[float, ...]], shipped: LQGWeights) -> list[tuple[LQGWeights, float]]:
    """Every (weights, wind_noise) of ``grid``; weights it does not vary stay the shipped row's."""
    keys = list(grid)
    out = []
    for vals in itertools.product(*(grid[k] for k in keys)):
        v = dict(zip(keys, vals))
        noise = float(v.pop("wind_noise", 0.0))
        out.append((replace(shipped, **v), noise))
    return out


def shipped_row(t: float, plane: str = "pitch", schedule: str = "smile_lqg") -> RowDesign:
    """The shipped schedule's row at ``t`` [s] as a :class:`.lqg_row.RowDesign` (its matrices as
    shipped, with the weights it was designed with)."""
    sched = LQGSchedule.load(schedule)
    rows = [r for r in sched.rows[plane] if abs(r.time_s - t) < 1e-6]
    if not rows:
        raise ConfigError("rows", t, f"a row of {schedule} {[r.time_s for r in sched.rows[plane]]}")
    with np.load(sched.source) as z:
        i = [float(x) for x in z["time_s"]].index(rows[0].time_s)
        values = [float(x) for x in z[f"{plane}_{i}_weights"]]
    r = rows[0]
    w = LQGWeights(**dict(zip([f.name for f in fields(LQGWeights)], values)))
    return RowDesign(r.time_s, plane, r.A, r.B, r.C, r.Kx, r.Ki, r.M, r.a, r.dt, w, r.labels)


def headroom(t: float, grid: dict[str, tuple[float, ...]], plane: str = "pitch", log=print) -> dict[str, Any]:
    """The row's study (module docstring): the shipped row's figures (``base``), every stable candidate
    (``designs``) and, per :data:`SLACKS` entry, the candidate of lowest ``rate_rms_nonrigid`` whose margins
    are within it (``best``: ``slack_db``, ``dm_fraction``, ``n`` candidates within, ``design``)."""
    loops = row_loops(t, plane)
    row = shipped_row(t, plane)
    base = loop_summary(row, loops, plane)
    if base is None:
        raise RuntimeError(f"the shipped row at {t:g} s is unstable on its own plants")
    designs = []
    for w, noise in candidates(grid, row.weights):
        try:
            d = wind_design(loops.op_nonrigid, plane, w, noise, loops.turbulence)
        except (ValueError, np.linalg.LinAlgError):
            continue
        m = loop_summary(d, loops, plane)
        if m is not None:
            designs.append({**asdict(w), "wind_noise": noise, **m,
                            "ratio_nonrigid": m["rate_rms_nonrigid"] / base["rate_rms_nonrigid"],
                            "ratio_rigid": m["rate_rms_rigid"] / base["rate_rms_rigid"]})
    best = []
    for slack_db, dm_fraction in SLACKS:
        within = [d for d in designs if no_worse(d, base, slack_db, dm_fraction)]
        best.append({"slack_db": slack_db, "dm_fraction": dm_fraction, "n": len(within),
                     "design": min(within, key=lambda d: d["ratio_nonrigid"]) if within else None})
    log(f"t = {t:g} s: {loops.turbulence.altitude:.0f} m, {loops.turbulence.speed:.0f} m/s, sigma "
        f"{loops.turbulence.sigma:.2f} m/s; {len(designs)} stable designs, {best[0]['n']} with margins no worse")
    return {"t": t, "turbulence": asdict(loops.turbulence), "base": base, "designs": designs, "best": best}


def headroom_table(results: list[dict[str, Any]]) -> str:
    """Markdown: per row, the shipped row's turbulence RMS and margins, and the lowest RMS ratio (non-rigid;
    the design's weights) within each margin loss of :data:`SLACKS`."""
    def label(s: dict[str, Any]) -> str:
        return "no worse" if s["slack_db"] == 0 and s["dm_fraction"] == 1 else \
            f"-{s['slack_db']:g} dB, DM x{s['dm_fraction']:g}"
    head = ["row [s]", "shipped: RMS [rad/s]; GM n / GM r / GRM n [dB]; DM n / r [ms]", "designs"] + \
        [label(s) for s in results[0]["best"]] if results else []
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in results:
        b = r["base"]
        cells = [f"{r['t']:g}", f"{b['rate_rms_nonrigid']:.4f}; {b['gm_nonrigid']:.1f} / {b['gm_rigid']:.1f} / "
                 f"{b['grm_nonrigid']:.1f}; {b['dm_nonrigid_ms']:.0f} / {b['dm_rigid_ms']:.0f}", str(len(r["designs"]))]
        for s in r["best"]:
            d = s["design"]
            cells.append("-" if d is None else f"{d['ratio_nonrigid']:.3f} (q_int {d['q_int']:g}, r {d['r_gimbal']:g}, "
                                               f"wind {d['wind_noise']:g})")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def front_schedule(results: list[dict[str, Any]], slack_db: float, dm_fraction: float, path: str | Path,
                   schedule: str = "smile_lqg") -> dict[float, dict[str, Any]]:
    """Write (``.npz``, as :func:`.lqg_design.save_schedule`) the shipped ``schedule`` with the row of every
    :func:`headroom` result replaced, in both planes, by its design of lowest non-rigid ``rate_rms`` whose
    margins are within ``slack_db`` / ``dm_fraction`` of the shipped row's (the yaw plane designed with the
    same weights on its own plant); the other rows as shipped. Returns the chosen design of each row."""
    sched = LQGSchedule.load(schedule)
    with np.load(sched.source) as z:
        arrays = {k: z[k] for k in z.files}
    times = [float(x) for x in arrays["time_s"]]
    chosen: dict[float, dict[str, Any]] = {}
    for r in results:
        within = [d for d in r["designs"] if no_worse(d, r["base"], slack_db, dm_fraction)]
        best = min(within, key=lambda d: d["ratio_nonrigid"])          # the shipped row's own weights are within
        w = LQGWeights(**{f.name: best[f.name] for f in fields(LQGWeights)})
        i = int(np.argmin([abs(x - r["t"]) for x in times]))
        loops_op = _op("smile", r["t"], "nonrigid", SMILE_PHASES_S[0][1] + 0.5)
        for plane in arrays["planes"]:
            d = wind_design(loops_op, str(plane), w, best["wind_noise"], row_turbulence(loops_op))
            pre = f"{plane}_{i}_"
            arrays.update({pre + k: getattr(d, k) for k in ("A", "B", "C", "Kx", "M")})
            arrays.update({pre + "Ki": np.array(d.Ki), pre + "a": np.array(d.a), pre + "dt": np.array(d.dt),
                           pre + "labels": np.array(d.state_labels),
                           pre + "weights": np.array([getattr(w, f.name) for f in fields(LQGWeights)])})
        chosen[r["t"]] = best
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, **arrays)
    return chosen


def _schedule_rows(option: str, rows: list[float]) -> list[float]:
    """``--rows``: rows of the lqg schedule."""
    for t in rows:
        if t not in SMILE_ROWS_S:
            raise ConfigError(option, t, f"rows of the lqg schedule {list(SMILE_ROWS_S)}")
    return rows


def _slack(option: str, slack: tuple[float, float]) -> tuple[float, float]:
    """``--slack DB FRACTION``: a gain-margin loss in [0, 40] dB and a delay-margin fraction in [0, 1]."""
    return (float(option_number(option, slack[0], 0.0, 40.0)), float(option_number(option, slack[1], 0.0, 1.0)))


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.lqg_headroom.headroom --help``)."""

    rows: list[float] = arg(default_factory=lambda: list(DEFAULT_ROWS), lo=0.0, hi=100.0, check=_schedule_rows,
                            metavar="T")
    """rows of the lqg schedule [s]"""
    grid: str = arg("full", choices=tuple(sorted(GRIDS)))
    """the weights searched"""
    out: str | None = None
    """write the designs of every row as JSON here"""
    write_schedule: str | None = arg(None, metavar="PATH")
    """write the schedule with each row's best design within --slack here (.npz)"""
    slack: tuple[float, float] = arg(DEFAULT_SLACK, check=_slack, metavar=("DB", "FRACTION"))
    """the margin loss of --write-schedule: gain margins [dB], delay margins kept"""


def main(argv: list[str] | None = None) -> list[dict[str, Any]]:
    """Search every row, print the table; write the designs and the schedule if asked."""
    args = parse(Args, argv, PROG, __doc__)
    rows, (slack_db, dm_fraction) = args.rows, args.slack
    t0 = time.perf_counter()
    results = [headroom(t, GRIDS[args.grid], log=lambda s: print(s, file=sys.stderr)) for t in rows]
    print(headroom_table(results))
    print(f"{sum(len(r['designs']) for r in results)} designs in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    if args.out:
        from lvgym.benchmark.results import atomic_write_text, json_text
        atomic_write_text(args.out, json_text(results))
    if args.write_schedule:
        chosen = front_schedule(results, slack_db, dm_fraction, args.write_schedule)
        for t, d in chosen.items():
            print(f"{t:g} s: q_int {d['q_int']:g}, r_gimbal {d['r_gimbal']:g}, w_gimbal {d['w_gimbal']:g}, q_modes "
                  f"{d['q_modes']:g}, w_modes {d['w_modes']:g}, wind_noise {d['wind_noise']:g}: RMS x "
                  f"{d['ratio_nonrigid']:.3f}", file=sys.stderr)
        print(f"schedule written to {args.write_schedule}", file=sys.stderr)
    return results


if __name__ == "__main__":
    main()
