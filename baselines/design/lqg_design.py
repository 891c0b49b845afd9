"""LQG rate loops designed on the flight computer's non-rigid plant, per plane, at frozen flight times.

``lvgym design lqg --vehicle smile [--integral attitude] [--out results/schedules] [--overwrite]``
(``python -m lvgym.baselines.design.lqg_design``)

``--integral attitude`` designs ``lqi`` (docs/lqi.md): the pure integral of the attitude error in place of the
rate's leaky one (:mod:`.lqg_row`), the search over :data:`LQI_GRID` with each row's estimator and mode weights
those of the shipped ``lqg`` row, written as ``<vehicle>_lqi.npz``.

Each row's law is :mod:`.lqg_row`'s (plant with the delay as a state, LQR on the rate error and its leaky
integral, steady-state Kalman filter of the v1 gyro, the compensator and its margins with the loop broken
at the plant input). Here: the weights searched per row (:func:`search_row`) against the margin targets
(:class:`MarginTargets`) on the rigid and non-rigid plants and on robustness plants (the ends of the row's
interval, the slosh dispersed: :func:`dispersed`), the figure of merit (:func:`gust_response`), the rows'
intervals (:func:`row_intervals`), and the schedule's files (:func:`save_schedule`, :func:`margin_table`).
docs/lqg.md gives the reasoning and the numbers.
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

import control
import numpy as np
import scipy.linalg as sla

from lvgym.commandline import arg
from lvgym.errors import ConfigError, check_number

from .flightloop import mode_frequencies
from .linearize import OperatingPoint, operating_point, reused_flights
from .lqg_row import (LQGWeights, RowDesign, check_integral, closed_loop, closed_loop_growth, delayed_plant, design_row,
                      frequency_grid, gain_at, integral_input, loop_plant, loop_response, margins_from_response,
                      open_loop, plant_labels, plant_responses)
from .target import fly_option, vehicle_option

SCHEDULES = Path(__file__).resolve().parents[1] / "schedules"
#: the schedule rows [s] of SMILE v1: the boost (burnout 43 s) and the upper stage (ignition 54 s)
SMILE_ROWS_S = (3.0, 10.0, 20.0, 28.8, 36.0, 41.0, 56.0, 62.0, 68.0)
PLANE_NAMES = ("pitch", "yaw")


# ---------------------------------------------------------------------------- the search
@dataclass(frozen=True)
class MarginTargets:
    """What a row must meet (issue 17's margin checks): rigid and non-rigid loops closed-loop stable
    with gain margin >= ``gm_db`` [dB] and phase margin >= ``pm_deg`` [deg] at every gain crossover
    (the smallest in magnitude counts), the bending modes above the first attenuated to
    ``|L| <= -attenuation_db`` [dB], and the non-rigid loop stable at the ends of the row's interval
    with ``neighbour_gm_db`` and ``neighbour_pm_deg`` (the plant has moved away from the design's
    model there: its slosh frequencies by about 1 rad/s)."""

    gm_db: float = 6.0
    pm_deg: float = 30.0
    attenuation_db: float = 6.0
    neighbour_gm_db: float = 3.0
    neighbour_pm_deg: float = 15.0

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, check_number(f"targets.{f.name}", getattr(self, f.name), 0.0, 180.0))


#: the weights tried at every row (q_rate = 1; docs/lqg.md): integral, gimbal and mode-rate weights, gimbal
#: and mode-rate process noise
SEARCH_GRID = {"q_int": (10.0, 100.0), "r_gimbal": (1.0, 3.0, 10.0, 30.0, 300.0), "w_gimbal": (1e-8, 1e-7),
               "q_modes": (1e-5, 1e-4, 1e-3), "w_modes": (1e-5, 1e-4, 1e-3, 1e-2)}
#: the weights tried at every row of the attitude integral's design (``lqi``): the attitude weight takes the
#: values of lqg's ``q_int`` (the rate's integral is the attitude change), its integral's [1/(rad s)^2] and the
#: gimbal's lqg's; the estimator's and the modes' weights are the row's lqg weights (:func:`design_schedule`)
LQI_GRID = {"q_attitude": (10.0, 100.0), "q_int": (1.0, 10.0, 100.0), "r_gimbal": (1.0, 3.0, 10.0, 30.0, 300.0)}
_SEARCH_W = np.logspace(-5, math.log10(math.pi / 0.02 * 0.9999), 5000)


def assess(d: RowDesign, plants: dict[str, control.StateSpace], modes: dict[str, list[float]],
           w: np.ndarray | None = None, plant_responses: dict[str, np.ndarray] | None = None) -> dict[str, Any]:
    """Margins of the row's compensator on each plant of ``plants`` (``rigid``, ``nonrigid``, and
    neighbouring non-rigid plants ``t=<time>``) and the non-rigid loop's gain [dB] at the slosh and
    bending frequencies [rad/s] of ``modes``. ``plant_responses``: the plants' responses on ``w``, if
    already computed (the loop's is the product with the compensator's)."""
    comp = d.compensator()
    w = frequency_grid(d.dt) if w is None else np.asarray(w, float)
    out: dict[str, Any] = {}
    for name, g in plants.items():
        lr = loop_response(comp, g, w, None if plant_responses is None else plant_responses[name])
        L = open_loop(comp, g)
        growth = closed_loop_growth(L)
        out[name] = {**margins_from_response(lr, w), "closed_loop_stable": growth < 1e-4,
                     "max_pole_real_per_s": growth}
        if name == "nonrigid":
            out["slosh_db"] = gain_at(L, modes["slosh"])
            out["bending_db"] = gain_at(L, modes["bending"])
    return out


def shortfall(a: dict[str, Any], tg: MarginTargets) -> float:
    """How far an :func:`assess` result is from the targets (0: met), in units of the targets: the sum
    of the relative shortfalls of each loop's gain and phase margin (the neighbours' against their own
    targets) and of the attenuation of the higher bending modes, plus 10 per unstable loop."""
    s = 0.0
    for name, m in a.items():
        if not isinstance(m, dict):
            continue
        if not m["closed_loop_stable"]:
            s += 10.0
            continue
        gm, pm = (tg.gm_db, tg.pm_deg) if name in ("rigid", "nonrigid") else (tg.neighbour_gm_db, tg.neighbour_pm_deg)
        s += max(0.0, 1.0 - m["gain_margin_db"] / gm) if gm > 0 else 0.0
        s += max(0.0, 1.0 - abs(m["phase_margin_deg"]) / pm) if pm > 0 else 0.0
    for db in a.get("bending_db", [])[1:]:
        s += max(0.0, (db + tg.attenuation_db) / max(tg.attenuation_db, 1.0))
    return s


def gust_response(d: RowDesign, op: OperatingPoint, plane: str) -> float:
    """The figure of merit among designs that meet the targets: the H2 norm [rad/s per (m/s)] of the
    closed loop (the row's compensator on the plant of ``op``) from a white disturbance of the lateral
    velocity of the plane (``v_z`` pitch, ``v_y`` yaw: what a gust does to the angle of attack) to the
    gyro rate; a lightly damped weathercock mode makes it large. The square root of
    ``C_cl P C_cl^T`` with ``P = A_cl P A_cl^T + B_cl B_cl^T``."""
    A, B, C, _ = delayed_plant(op, plane)
    labels = plant_labels(op, plane)
    Bd = np.zeros((A.shape[0], 1))
    Bd[labels.index(PLANE_VELOCITY[plane]), 0] = 1.0
    Cl = C if d.integral == "rate" else np.vstack([C, integral_input(C, labels, d.integral)])
    Acl, _ = closed_loop(A, B, Cl, d.compensator())
    nk = Acl.shape[0] - A.shape[0]
    Bcl = np.vstack([Bd, np.zeros((nk, 1))])
    Ccl = np.hstack([C, np.zeros((1, nk))])
    if np.abs(np.linalg.eigvals(Acl)).max() >= 1.0:
        return math.inf
    P = sla.solve_discrete_lyapunov(Acl, Bcl @ Bcl.T)
    return float(math.sqrt(max((Ccl @ P @ Ccl.T).item(), 0.0)))


#: the lateral velocity state of each plane (the gust's entry for :func:`gust_response`)
PLANE_VELOCITY = {"pitch": "v_z", "yaw": "v_y"}


def dispersed(op: OperatingPoint, frequency_scale: float, damping_scale: float) -> OperatingPoint:
    """``op`` with its pendulums' frequencies scaled by ``frequency_scale`` (lengths / f^2 and the damper
    frequency x f, as the env's ``slosh_frequency`` dispersion) and their damping ratios by
    ``damping_scale`` (the ``slosh_damping`` dispersion)."""
    lay = op.sim.dynamics.layout
    p = op.p.copy()
    for j in range(op.sim.dynamics.n_slosh):
        p[lay.slosh_param(j, "length")] /= frequency_scale ** 2
        p[lay.slosh_param(j, "omega")] *= frequency_scale
        p[lay.slosh_param(j, "zeta")] *= damping_scale
    return replace(op, p=p)


#: the dispersed plants every row must stay stable on (:func:`dispersed`: slosh frequency, damping): the
#: env's slosh-frequency dispersion at 2 sigma (x N(1, 5 %)) with the low end of its damping dispersion
#: (x [0.5, 2])
DISPERSED_SLOSH = ((0.9, 0.5), (1.1, 0.5))


def search_row(op_nonrigid: OperatingPoint, op_rigid: OperatingPoint, neighbours: dict[str, OperatingPoint],
               plane: str, tg: MarginTargets = MarginTargets(), grid: dict = SEARCH_GRID,
               log=print, integral: str = "rate",
               base: LQGWeights = LQGWeights()) -> tuple[RowDesign, dict[str, Any], list[dict]]:
    """Every combination of the weights of ``grid`` (the others ``base``'s) at one row, with the integral
    ``integral`` (:data:`.lqg_row.INTEGRALS`): among the designs whose loops are
    stable on the rigid, the non-rigid and the ``neighbours``' non-rigid plants (name -> operating
    point: the ends of the row's interval, the dispersed plants) and meet ``tg``, the one of the
    smallest rigid gust response (:func:`gust_response`); if none meets them, the one of smallest
    :func:`shortfall`. Returns the design, its assessment on the full frequency grid and the
    table of every candidate."""
    check_integral(integral)
    modes = mode_frequencies(op_nonrigid, plane)
    plants = {"rigid": loop_plant(op_rigid, plane, integral), "nonrigid": loop_plant(op_nonrigid, plane, integral)}
    plants.update({name: loop_plant(op, plane, integral) for name, op in neighbours.items()})
    responses = {k: plant_responses(g, _SEARCH_W) for k, g in plants.items()}
    table, cands = [], []
    keys = list(grid)
    for vals in np.array(np.meshgrid(*[grid[k] for k in keys], indexing="ij")).reshape(len(keys), -1).T:
        w = replace(base, **dict(zip(keys, (float(v) for v in vals))))
        try:
            d = design_row(op_nonrigid, plane, w, integral)
        except (ValueError, np.linalg.LinAlgError) as exc:
            table.append({**asdict(w), "error": str(exc)})
            continue
        comp = d.compensator()
        unstable = [k for k, g in plants.items() if closed_loop_growth(open_loop(comp, g)) >= 1e-4]
        if unstable:                                   # cheap rejection: no margins of an unstable loop
            table.append({**asdict(w), "shortfall": 10.0 * len(unstable), "unstable": unstable})
            cands.append((10.0 * len(unstable), 0.0, len(cands), d, None))
            continue
        a = assess(d, plants, modes, _SEARCH_W, responses)
        sf = shortfall(a, tg)
        h2 = gust_response(d, op_rigid, plane)
        table.append({**asdict(w), "shortfall": sf, "gust_h2": h2})
        cands.append((sf, h2, len(cands), d, a))
    if not cands:
        raise RuntimeError(f"no design of the grid could be computed at t = {op_nonrigid.t:g} s ({plane})")
    cands.sort(key=lambda c: (c[0] > 0, c[0] if c[0] > 0 else c[1], c[2]))
    d = cands[0][3]
    final = assess(d, plants, modes)
    final["gust_h2"] = gust_response(d, op_rigid, plane)
    att = f"q_attitude {d.weights.q_attitude:g}, " if integral == "attitude" else ""
    log(f"  {plane} t = {d.t:5.1f} s: {att}q_int {d.weights.q_int:g}, r {d.weights.r_gimbal:g}, "
        f"w {d.weights.w_gimbal:g}, "
        f"q_modes {d.weights.q_modes:g}, w_modes {d.weights.w_modes:g}: shortfall {shortfall(final, tg):.3f}, "
        f"{sum(1 for c in cands if c[0] == 0)} of {len(table)} designs meet the targets")
    return d, final, table


# ---------------------------------------------------------------------------- the schedule
#: SMILE v1's thrusting phases with the controller on [s]: from controller start to burnout, and from
#: stage-2 ignition to the mission's end, each trimmed by 0.5 s at its burnout, ignition and end
SMILE_PHASES_S = ((2.0, 42.5), (54.5, 69.5))


def row_intervals(rows: tuple[float, ...], phases: tuple[tuple[float, float], ...]) -> list[tuple[float, float]]:
    """Each row's interval of use [s]: from the midpoint with the previous row of its phase (or the
    phase's start) to the midpoint with the next (or the phase's end)."""
    out = []
    for t in rows:
        ph = [p for p in phases if p[0] <= t <= p[1]]
        if not ph:
            raise ConfigError("rows", t, f"a flight time inside a thrusting phase {list(phases)}")
        lo, hi = ph[0]
        same = sorted(r for r in rows if lo <= r <= hi)
        i = same.index(t)
        out.append((lo if i == 0 else 0.5 * (same[i - 1] + t), hi if i == len(same) - 1 else 0.5 * (t + same[i + 1])))
    return out


def _op(vehicle: Any, t: float, model: str, upper_after_s: float, fly: Any = None, **options: Any) -> OperatingPoint:
    """The v1 operating point: flown with ``fly`` (a policy factory) when given; else past
    ``upper_after_s`` with the rigid gain-scheduled PID (the zero action tumbles the SMILE v1 upper stage),
    before it with the gimbal centred."""
    if fly is not None:
        return operating_point(vehicle, t, model, protocol="v1", policy=fly, **options)
    if t > upper_after_s:
        from ..pid import smile_scheduled_pid
        return operating_point(vehicle, t, model, protocol="v1", policy=lambda env: smile_scheduled_pid(env, "smile"),
                               **options)
    return operating_point(vehicle, t, model, protocol="v1", **options)


def row_neighbours(vehicle: Any, t: float, interval: tuple[float, float], op_nonrigid: OperatingPoint,
                   upper_after_s: float, fly: Any = None, **options: Any) -> dict[str, OperatingPoint]:
    """The robustness plants a row must stay stable on: the non-rigid points at the ends of its
    ``interval`` [s] (those more than 0.05 s from ``t``) and the row's own with its slosh dispersed
    (:data:`DISPERSED_SLOSH`)."""
    near = {f"t={x:.1f}": _op(vehicle, x, "nonrigid", upper_after_s, fly, **options)
            for x in interval if abs(x - t) > 0.05}
    near.update({f"slosh f x{f:g} zeta x{z:g}": dispersed(op_nonrigid, f, z) for f, z in DISPERSED_SLOSH})
    return near


@reused_flights()
def design_schedule(vehicle: Any = "smile", rows: tuple[float, ...] | None = None,
                    phases: tuple[tuple[float, float], ...] | None = None, tg: MarginTargets = MarginTargets(),
                    grid: dict = SEARCH_GRID, planes: tuple[str, ...] = PLANE_NAMES, log=print, fly: str = "auto",
                    integral: str = "rate", base: tuple[LQGWeights, ...] | None = None,
                    **options: Any) -> dict[str, Any]:
    """Design every row and plane (:func:`search_row`); the neighbours of a row are the non-rigid plants
    at the ends of its interval (:func:`row_intervals`) and at the row with its slosh dispersed
    (:data:`DISPERSED_SLOSH`). ``vehicle``: ``smile`` (rows and phases default to SMILE v1's) or any
    vehicle a v1 env flies, a shipped name or a vehicle file (:func:`.target.design_env`; ``options``: env
    keywords), with its ``rows`` and thrusting ``phases`` [s] (a file's default: :func:`.target.burn_phases`
    and :func:`.target.file_times`). ``fly``: how the operating points are
    reached (:data:`.target.FLY_MODES`): ``centred`` (SMILE: its upper stage with the shipped rigid
    ``gs-pid`` schedule, as the shipped design), ``pid`` (a rigid PID schedule designed first at the rows,
    :func:`.tune.schedule` with ``fly="rows"``), ``privileged`` (the privileged reference) or a schedule
    file; ``auto``: ``centred`` for a shipped vehicle, ``pid`` for a file. A document not flown as the shipped design records how in
    ``operating_points``. ``integral``: the rate's leaky integral (``lqg``) or the attitude's pure one (``lqi``);
    ``base``: per row, the weights the ``grid`` leaves as they are (default :class:`.lqg_row.LQGWeights`')."""
    from .target import burn_phases, check_fly, check_vehicle, describe, file_times, fly_mode, is_shipped
    from .target import flyer as fly_with
    from .target import schedule_flyer

    vehicle = check_vehicle(vehicle, "v1")
    if vehicle == "smile":
        rows = SMILE_ROWS_S if rows is None else rows
        phases = SMILE_PHASES_S if phases is None else phases
    elif not is_shipped(vehicle):            # a file: its burning flight (target.burn_phases, target.file_times)
        phases = burn_phases(vehicle, "v1", "phases") if phases is None else phases
        rows = file_times(vehicle, protocol="v1", option="rows") if rows is None else rows
    elif rows is None or phases is None:
        raise ConfigError("phases" if rows is not None else "rows", None,
                          f"the rows and thrusting phases [s] of vehicle {vehicle!r} (SMILE v1's are the defaults)")
    rows = tuple(rows)
    check_integral(integral)
    if base is not None and len(base) != len(rows):
        raise ConfigError("base", len(base), f"one LQGWeights per row ({len(rows)})")
    intervals = row_intervals(rows, tuple(phases))
    upper_after = phases[0][1] + 0.5
    fly = fly_mode(check_fly(fly), vehicle)
    fly = "pid" if fly == "rows" else fly
    flyer, rigid_doc = None, None
    if fly == "pid":
        from .tune import schedule as rigid_schedule

        log("the rigid PID schedule that flies to the rows (lvgym design pid):")
        rigid_doc = rigid_schedule(vehicle, tuple(sorted({*rows, *(x for iv in intervals for x in iv)})),
                                   log=log, protocol="v1", fly="rows", **options)
        flyer = schedule_flyer({k: rigid_doc[k] for k in ("variable", "rows")})
    else:
        flyer = fly_with(fly)
    how = describe(fly) if fly != "centred" or vehicle != "smile" else \
        "gimbal centred up to the first stage's burnout, then the shipped rigid gs-pid schedule 'smile'"
    log(f"operating points: {how}")
    out: dict[str, Any] = {"vehicle": vehicle, "rows": [], "targets": asdict(tg),
                           "grid": {k: list(v) for k, v in grid.items()}, "integral": integral}
    if fly != "centred" or vehicle != "smile" or options:
        out["operating_points"] = {"flown_with": how, **({"env_options": dict(options)} if options else {}),
                                   **({"rigid_pid_rows": [{k: r[k] for k in ("time_s", "mass_kg", "kp", "ki", "kd", "n")}
                                                          for r in rigid_doc["rows"]]} if rigid_doc else {})}
    for j, (t, (lo, hi)) in enumerate(zip(rows, intervals)):
        log(f"t = {t:g} s (used {lo:g}-{hi:g} s)")
        row_base = LQGWeights() if base is None else base[j]
        op_n = _op(vehicle, t, "nonrigid", upper_after, flyer, **options)
        op_r = _op(vehicle, t, "rigid", upper_after, flyer, **options)
        near = row_neighbours(vehicle, t, (lo, hi), op_n, upper_after, flyer, **options)
        entry: dict[str, Any] = {"time_s": float(op_n.t), "interval_s": [lo, hi]}
        chosen = None
        for plane in planes:                 # the first plane's search; the others fly its weights (axisymmetric)
            g = grid if chosen is None else {k: (v,) for k, v in asdict(chosen).items()}
            try:
                d, a, table = search_row(op_n, op_r, near, plane, tg, g, log, integral, row_base)
            except RuntimeError:
                if g is grid:
                    raise
                log(f"  {plane}: the first plane's weights give no design here; the plane's own search")
                d, a, table = search_row(op_n, op_r, near, plane, tg, grid, log, integral, row_base)
            chosen = chosen or d.weights
            entry[plane] = {"design": d, "assessment": a, "search": table,
                            "modes_radps": mode_frequencies(op_n, plane)}
        out["rows"].append(entry)
    return out


def save_schedule(doc: dict[str, Any], path: Path) -> None:
    """The schedule's matrices as ``.npz`` (keys ``<plane>_<row>_<name>``, the rows' ``time_s`` and
    ``switch_s``, the interval ends)."""
    arrays: dict[str, np.ndarray] = {"time_s": np.array([r["time_s"] for r in doc["rows"]]),
                                     "interval_s": np.array([r["interval_s"] for r in doc["rows"]]),
                                     "planes": np.array([p for p in PLANE_NAMES if p in doc["rows"][0]])}
    for i, r in enumerate(doc["rows"]):
        for plane in arrays["planes"]:
            d: RowDesign = r[str(plane)]["design"]
            pre = f"{plane}_{i}_"
            for name in ("A", "B", "C", "Kx", "M"):
                arrays[pre + name] = getattr(d, name)
            arrays[pre + "Ki"] = np.array(d.Ki)
            arrays[pre + "a"] = np.array(d.a)
            arrays[pre + "dt"] = np.array(d.dt)
            arrays[pre + "labels"] = np.array(d.state_labels)
            arrays[pre + "integral"] = np.array(d.integral)
            arrays[pre + "weights"] = np.array([getattr(d.weights, f.name) for f in fields(LQGWeights)])
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, **arrays)


def _m(m: dict[str, Any]) -> str:
    st = "stable" if m["closed_loop_stable"] else "UNSTABLE"
    return (f"{m['gain_margin_db']:.1f} / {m['gain_reduction_margin_db']:.1f} / {m['phase_margin_deg']:.1f} at "
            f"{m['gain_crossover_radps']:.3g} / {st}")


def _slosh(gains_db: list[float]) -> str:
    """The largest loop gain at a slosh mode [dB], or ``-`` for a vehicle without slosh (a solid motor)."""
    return f"{max(gains_db):.1f}" if gains_db else "-"


def margin_table(doc: dict[str, Any]) -> str:
    """The margins per row and plane as a Markdown table (the attitude integral's: ``q_attitude`` first)."""
    att = doc.get("integral", "rate") == "attitude"
    lines = [f"| t [s] | plane | {'q_attitude, ' if att else ''}q_int, r_gimbal, w_gimbal, q_modes, w_modes | rigid GM / GRM [dB] / PM [deg] at [rad/s] / CL | "
             "non-rigid GM / GRM / PM at / CL | slosh max dB | bending dB | gust H2 | robustness plants (non-rigid): interval ends, "
             "slosh dispersed |",
             "|---:|---|---|---|---|---:|---|---:|---|"]
    for r in doc["rows"]:
        for plane in PLANE_NAMES:
            if plane not in r:
                continue
            d, a = r[plane]["design"], r[plane]["assessment"]
            ends = "; ".join(f"{k}: {_m(v)}" for k, v in a.items()
                             if isinstance(v, dict) and k not in ("rigid", "nonrigid"))
            wt = d.weights
            lines.append(f"| {r['time_s']:g} | {plane} | {f'{wt.q_attitude:g}, ' if att else ''}{wt.q_int:g}, {wt.r_gimbal:g}, {wt.w_gimbal:g}, {wt.q_modes:g}, {wt.w_modes:g} "
                         f"| {_m(a['rigid'])} | {_m(a['nonrigid'])} | {_slosh(a['slosh_db'])} | "
                         f"{', '.join(f'{x:.1f}' for x in a['bending_db'])} | {a['gust_h2']:.4f} | {ends} |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``lvgym design lqg --help``)."""

    vehicle: str = arg("smile", check=vehicle_option, metavar="NAME|PATH")
    """the vehicle: smile (SMILE v1, the rows and phases below by default) or the path of a vehicle YAML
    file flown in SMILE's v1 env (docs/vehicles.md; by default its burning flight's phases and 8 rows over
    them)"""
    out: str = "results/schedules"
    """folder of <vehicle>_lqg.npz and <vehicle>_lqg_margins.md (a file: its stem)"""
    overwrite: bool = False
    """write into the shipped baselines/schedules instead of --out"""
    rows: list[float] | None = arg(None, lo=0.0, hi=3600.0)
    """flight times [s] of the rows (default: SMILE v1's, 3 10 20 28.8 36 41 56 62 68; a file's: 8 equal
    parts of its burning flight)"""
    phases: list[float] | None = arg(None, lo=0.0, hi=3600.0, metavar="START END")
    """the thrusting phases with the controller on [s], pairs START END (default: SMILE v1's, 2 42.5 54.5 69.5)"""
    integral: str = arg("rate", choices=("rate", "attitude"))
    """what the integral integrates: rate (the rate error, leaky: lqg, <vehicle>_lqg.npz) or attitude (the
    strapdown attitude error, pure: lqi, <vehicle>_lqi.npz; searched over LQI_GRID with each row's estimator
    and mode weights those of the vehicle's lqg schedule, which must have the same rows)"""
    fly: str = arg("auto", check=fly_option, metavar="MODE|SCHEDULE")
    """how the operating points are reached: centred (SMILE: gimbal centred, its upper stage with gs-pid),
    pid (a rigid PID schedule designed first at the rows), privileged (the privileged reference, which needs
    no design), a schedule file, or auto (centred for a shipped
    vehicle, pid for a file)"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design lqg`` (``python -m lvgym.baselines.design.lqg_design``): design and write the schedule."""
    from lvgym.commandline import command_name, fail, parse

    from .target import burn_phases, file_times, is_shipped, stem

    prog = "python -m lvgym.baselines.design.lqg_design"
    a = parse(Args, argv, prog, __doc__)
    smile = a.vehicle == "smile"
    try:
        if a.phases is not None and len(a.phases) % 2:
            raise ConfigError("--phases", a.phases, "pairs START END [s]")
        file = not smile and not is_shipped(a.vehicle)
        phases = (tuple(zip(a.phases[::2], a.phases[1::2])) if a.phases else
                  SMILE_PHASES_S if smile else burn_phases(a.vehicle, "v1", "--phases") if file else None)
        rows = (tuple(a.rows) if a.rows else SMILE_ROWS_S if smile else
                file_times(a.vehicle, option="--rows") if file else None)
        if rows is None or phases is None:
            raise ConfigError("--rows" if rows is None else "--phases", None,
                              f"required for vehicle {a.vehicle} (SMILE v1's and a file's have defaults)")
        try:
            row_intervals(rows, phases)                  # every row in a thrusting phase, before the design
        except ConfigError as exc:
            raise ConfigError("--rows", exc.value, exc.allowed) from None
    except ConfigError as exc:
        fail(command_name(prog), exc)
    out = SCHEDULES if a.overwrite else Path(a.out)
    name = stem(a.vehicle)
    lqi = a.integral == "attitude"
    kind = "lqi" if lqi else "lqg"
    try:
        base, grid = (lqg_weights(out, name, rows), LQI_GRID) if lqi else (None, SEARCH_GRID)
    except ConfigError as exc:
        fail(command_name(prog), exc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = design_schedule(a.vehicle, rows, phases, grid=grid, fly=a.fly, integral=a.integral, base=base)
    save_schedule(doc, out / f"{name}_{kind}.npz")
    again = (f"lvgym design lqg --vehicle {a.vehicle}" + ("" if not a.rows else " --rows " + " ".join(f"{t:g}" for t in rows))
             + ("" if not a.phases else " --phases " + " ".join(f"{t:g}" for p in phases for t in p))
             + ("" if a.fly == "auto" else f" --fly {a.fly}") + (" --integral attitude" if lqi else ""))
    flown = f"Operating points: {doc['operating_points']['flown_with']}. " if "operating_points" in doc else ""
    what = ("LQI schedule (the pure integral of the attitude error; estimator and mode weights lqg's row's, "
            "the search over q_attitude, q_int and r_gimbal)" if lqi else "LQG schedule")
    head = (f"# {what} of {name} v1: margins per row\n\nWritten by `{again}`. {flown}Loop broken at the plant "
            "input; GM / GRM: gain and gain-reduction margin, "
            "PM: phase margin at the gain crossover of smallest |PM|, CL: closed-loop stability; slosh and "
            "bending: the non-rigid loop's |L| at each mode (bending modes above Nyquist folded). Targets: "
            f"{doc['targets']}.\n\n")
    (out / f"{name}_{kind}_margins.md").write_text(head + margin_table(doc))
    print(margin_table(doc))
    print(f"wrote {out / f'{name}_{kind}.npz'} and {out / f'{name}_{kind}_margins.md'}")
    return 0


def lqg_weights(folder: Path, name: str, rows: tuple[float, ...]) -> tuple[LQGWeights, ...]:
    """The pitch weights of each row of the vehicle's lqg schedule (``<name>_lqg.npz`` in ``folder``, else the
    shipped one): the attitude integral's design keeps their estimator and mode weights. Its rows must be
    ``rows`` [s] (to 0.5 s: a row's time is where its flight reached it)."""
    from ..lqg import LQGSchedule

    path = folder / f"{name}_lqg.npz"
    try:
        sched = LQGSchedule.load(path if path.exists() else f"{name}_lqg")
    except FileNotFoundError:
        raise ConfigError("--integral", "attitude", f"a {name}_lqg.npz schedule first (lvgym design lqg --vehicle "
                          "...): the attitude integral's design keeps its estimator and mode weights") from None
    have = [r.time_s for r in sched.rows["pitch"]]
    if len(have) != len(rows) or any(abs(x - t) > 0.5 for x, t in zip(have, rows)):
        raise ConfigError("--rows", list(rows), f"the rows of {sched.source} ({[round(x, 2) for x in have]})")
    if not all(r.weights for r in sched.rows["pitch"]):
        raise ConfigError("--integral", "attitude", f"a lqg schedule with its weights ({sched.source} has none)")
    return tuple(LQGWeights(*r.weights) for r in sched.rows["pitch"])


if __name__ == "__main__":
    sys.exit(main())
