"""Design of ``gs-pid-flex``: a gain-scheduled PID with structural filters, designed on the non-rigid
linear model of protocol v1's flight loop, at frozen flight times (docs/flex-design.md).

``lvgym design pid-flex --vehicle smile`` (``python -m lvgym.baselines.design.flexdesign``) writes
``results/schedules/smile_flex.yaml`` (the schedule, its margins and its frozen-time checks) and ``smile_flex_margins.md`` (the margin table); the
shipped schedule (``baselines/schedules/smile_flex.yaml``, the one ``gs-pid-flex`` flies) is replaced
only with ``--overwrite``.

At every schedule row the plant is :func:`.flightloop.flight_plant`: the commanded gimbal to the sampled
gyro at the control period, with the servo, the bending slope at the IMU, the gyro's filters, the hold
and the one-period computational delay, rigid and non-rigid. The controller is
``C(z) = PID(z) F(z)``: the backward-Euler PID of :mod:`.pid` (unfiltered derivative) times the
:class:`.filters.StructuralFilter` chain (lead-lag, low-pass, a notch on the first bending mode when it
lies below the Nyquist frequency). Each row flies its own stretch of the flight, from the midpoint to the
row before to the midpoint to the row after (the policy takes the nearest row on mass). Its nine
parameters minimise the energy of the rate's response to a disturbance at the plant input,
``sum |G / (1 + C G)|^2 dw`` over the frequency grid (the mean of the rigid and the non-rigid plant at
the row's time), under the constraints of :class:`Requirements` on the plants at the row's time and at
both ends of its stretch (penalties), by Nelder-Mead from the previous row's design and from seeded
random starts. Every row is then checked exactly with :func:`.linearize.margins` on the
python-control loops, in pitch and yaw, on all those plants. With ``--load-objective qalpha|accel`` each row's
load relief (its accelerometer gain and integral) is chosen by the design on the relieved loop
(:mod:`.loadobjective`).
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass
from typing import Any, Callable

import control
import numpy as np

from lvgym.commandline import arg
from lvgym.errors import ConfigError

from ..filters import Filter, StructuralFilter
from .flexproblem import (PARAMETERS, START, Requirements, RowProblem, _controller_poly, _from_unit,  # noqa: F401
                          _to_unit, controller, controller_tf, design_row, folded, notch_frequency, open_loop_growth)
from .flextable import margin_table, row_line
from .flightloop import flight_plant, frequency_response, mode_frequencies
from .linearize import margins, operating_point, reused_flights
from .loadobjective import OBJECTIVES, check_load_options, effective_plant, load_plant, load_row
from .noise import command_noise_rate, gyro_noise
from .target import fly_option, stem, vehicle_option

#: the flight times of the schedule per vehicle [s]: SMILE v1 boost (burnout 43 s) and upper stage
#: (ignition 54 s, mission 70 s); Stratos III (30 s); the slender vehicle (10 s)
FLEX_TIMES = {"smile": (3.0, 10.0, 15.0, 20.0, 24.4, 28.8, 32.4, 36.0, 42.5, 54.1, 62.0, 69.5),
              "stratos3": (2.0, 6.0, 10.0, 14.0, 18.0, 24.0, 29.0),
              "slender": (1.0, 3.0, 5.0, 7.0, 9.0)}


#: the optimiser's iterations per start (Nelder-Mead, :func:`.flexproblem.design_row`) of the shipped designs
MAXITER = 3000


def row_plants(vehicle: Any, t: float, policy: Callable | None, load: bool = False,
               **options: Any) -> tuple[dict, dict, dict]:
    """Pitch and yaw ``flight_plant`` of the rigid and non-rigid v1 vehicle (a shipped name or a vehicle
    file; ``options``: env keywords) at ``t`` [s], flown there with ``policy`` (None: the zero action),
    the non-rigid modes, and the thrust [N], the mass [kg] and the gyro's noise with the servo's rate
    limit (:func:`.noise.gyro_noise`) there; ``load``: also ``load`` (the :func:`.loadobjective.load_plant`
    of each plane and model), ``qbar_pa`` and ``airspeed_mps`` there."""
    plants: dict[str, dict[str, control.StateSpace]] = {"pitch": {}, "yaw": {}}
    loads: dict[str, dict[str, control.StateSpace]] = {"pitch": {}, "yaw": {}}
    thrust, air = None, {}
    for model in ("rigid", "nonrigid"):
        op = operating_point(vehicle, t, model, protocol="v1", policy=policy, **options)
        thrust = op.condition("thrust")
        for plane in plants:
            plants[plane][model] = flight_plant(op, plane)
            if load:
                loads[plane][model] = load_plant(op, plane)
        if load:
            air = {"load": loads, "qbar_pa": op.condition("qbar"), "airspeed_mps": op.condition("airspeed")}
        if model == "nonrigid":
            modes = mode_frequencies(op)
            mass = float(op.sim.timeline.interp("mass", [op.t])[0])
            noise = gyro_noise(op)
    return plants, modes, {"thrust_n": thrust, "mass_kg": mass, "noise": noise, **air}


#: the requirements a row can miss, as :func:`check_loops` names them
MISSES = ("rigid gain margin", "rigid phase margin", "flex gain margin", "flex phase margin", "bending attenuation",
          "drift", "sensor noise")


def check_loops(plants: dict[str, dict[str, control.StateSpace]], gains, filt: Filter,
                modes: dict[str, list[float]], req: Requirements,
                noise: tuple[float, float] | None = None) -> dict[str, Any]:
    """Exact margins (:func:`.linearize.margins`) of ``C(z) G(z)`` for every plane and model; for each
    slosh and bending mode the peak of the modes' part of the pitch loop, ``C (G_nonrigid - G_rigid)``,
    near the frequency at which the sampler sees it (+-3 % for slosh, +-15 % for bending), and so how
    it is stabilised ('gain': at least ``req.attenuation_db`` below 0 dB; 'phase': held by the
    non-rigid margins); whether the row meets ``req``, and ``misses``: the requirements it does not meet,
    in the order of :data:`MISSES`. Each loop also records ``open_loop_pole_per_s``, the plant's own
    fastest growth rate [1/s] (the vehicle's drift with the gimbal held) and, with ``noise`` (the gyro's
    noise per sample [rad/s], the servo's rate limit [rad/s]), ``noise_rate_fraction``: the gimbal rate
    it commands as a fraction of that limit (:func:`.noise.command_noise_rate`)."""
    dt = float(plants["pitch"]["rigid"].dt)
    C = control.ss(controller_tf(gains, filt, dt))
    out: dict[str, Any] = {}
    missed: set[str] = set()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for plane, pl in plants.items():
            for model, g in pl.items():
                m = margins(control.series(g, C))
                m["open_loop_pole_per_s"] = open_loop_growth(g.A, dt)
                key = "rigid" if model == "rigid" else "flex"
                gm, pm = (req.rigid_gm_db, req.rigid_pm_deg) if model == "rigid" else (req.flex_gm_db, req.flex_pm_deg)
                miss = ([] if m["gain_margin_db"] >= gm - 0.05 and m["gain_reduction_margin_db"] <= -gm + 0.05
                        else [f"{key} gain margin"])
                miss += [] if abs(m["phase_margin_deg"]) >= pm - 0.5 else [f"{key} phase margin"]
                miss += [] if m["max_pole_real_per_s"] < req.drift_per_s else ["drift"]
                if noise is not None and noise[0] > 0.0:
                    m["noise_rate_fraction"] = command_noise_rate(C, g, *noise)
                    limit = req.noise_rate_fraction
                    miss += [] if limit is None or m["noise_rate_fraction"] <= limit * 1.005 else ["sensor noise"]
                m["meets"] = not miss
                missed.update(miss)
                out[f"{model}_{plane}"] = m
        modal = control.series(plants["pitch"]["nonrigid"] - plants["pitch"]["rigid"], C)   # the modes' part
        mode_gain = []
        for kind in ("slosh", "bending"):
            for i, wm in enumerate(modes.get(kind, [])):
                f = folded(wm, dt)
                band = np.linspace(0.85 * f, 1.15 * f, 301) if kind == "bending" else np.linspace(0.97 * f, 1.03 * f, 61)
                db = float(20 * np.log10(np.abs(frequency_response(modal, band)).max()))
                gain_stab = db <= -req.attenuation_db
                if kind == "bending" and (i > 0 or req.bending1 == "gain") and not gain_stab:
                    missed.add("bending attenuation")        # must be gain-stabilised
                mode_gain.append({"mode": kind, "radps": round(wm, 2), "seen_at_radps": round(f, 2),
                                  "loop_gain_db": round(db, 2),
                                  "stabilised": "gain" if gain_stab else "phase"})
    out["modes"] = mode_gain
    out["misses"] = [k for k in MISSES if k in missed]
    out["meets"] = not missed
    return out


def _rounded(m: dict) -> dict:
    return {k: (round(v, 5 if k.endswith("_per_s") or k.startswith("noise") else 2) if isinstance(v, float) else v)
            for k, v in m.items()}


def schedule_policy(rows: list[dict[str, Any]]) -> Callable:
    """A factory ``env -> policy`` of the schedule made of ``rows`` so far (to fly to the next row)."""
    from ..pid import GainSchedule, GainScheduledPIDPolicy

    sched = GainSchedule.from_dict({"variable": "mass", "interpolation": "nearest", "rows": [dict(r) for r in rows]})
    return lambda env: GainScheduledPIDPolicy(sched, env=env, name="gs-pid-flex")


def _checked(case: tuple, t: float, gains, filt: StructuralFilter, req: Requirements) -> dict[str, Any]:
    plants, modes, info = case
    chk = check_loops(plants, gains, filt, modes, req, info.get("noise"))
    return {"time_s": float(t), "mass_kg": round(info["mass_kg"], 2), "meets": chk["meets"], "misses": chk["misses"],
            "margins": {k: _rounded(v) for k, v in chk.items() if k not in ("modes", "meets", "misses")},
            "modes": chk["modes"]}


def relief_row(problem_cases: list, req: Requirements, plain: dict[str, Any], ki_scale: float,
               also: list[dict[str, float]] = (), noise: tuple[float, float] = (0.0, 1.0)) -> dict[str, Any]:
    """The load-relief design of a row whose plain design is ``plain`` (:func:`.flexproblem.design_row`'s
    result on the same ``problem_cases``): the integral gain held at ``ki_scale`` times the plain
    design's (the attitude hold given up: :mod:`.pid`, "Load relief"), the other eight parameters
    designed again on the loop so relieved, from the plain design and from each parameter set of
    ``also``, against every requirement but the drift, which may be as fast as the vehicle's own and
    no faster (:data:`.flexproblem.DRIFT_MODES`); ``noise``: as :class:`.flexproblem.RowProblem` takes it."""
    ki = ki_scale * plain["values"]["ki"]
    problem = RowProblem(problem_cases, req, fixed={"ki": ki}, drift="vehicle", noise=noise)
    return design_row(problem, [dict(w, ki=ki) for w in [plain["values"], *also]], np.random.default_rng(0), starts=0)


def plain_schedule(schedule: Any) -> Any:
    """The :class:`.pid.GainSchedule` of the plain designs (integral kept, no accelerometer term) that the
    rows of a load-relief :class:`.pid.GainSchedule` ``schedule`` record under ``plain``
    (:func:`design_schedule`), scheduled as ``schedule`` is."""
    from ..pid import GainSchedule

    rows = schedule.meta.get("rows", [])
    missing = [r.get("time_s") for r in rows if "plain" not in r]
    if missing or not rows:
        raise ValueError(f"rows at t = {missing} s have no 'plain' entry: a load-relief schedule written by "
                         "python -m lvgym.baselines.design.flexdesign --load-relief records one in every row")
    return GainSchedule.from_dict({"variable": schedule.variable, "interpolation": schedule.interpolation, "rows": [
        {"time_s": r["time_s"], "mass_kg": r["mass_kg"], **{k: r["plain"][k] for k in ("kp", "ki", "kd", "filter")}}
        for r in rows]})


def _load_cases(cases: list, planes: tuple[str, ...]) -> list:
    """The :class:`.loadobjective.LoadProblem` cases of a row's ``cases`` ((time, :func:`row_plants`
    result) pairs, flown with ``load``) in the order of its gyro loops."""
    return [(c[2]["load"][p], c[1], c[2]["qbar_pa"], c[2]["airspeed_mps"], p) for _, c in cases for p in planes]


def _relieved(case: tuple, gain: float) -> tuple:
    """A :func:`row_plants` result (flown with ``load``) whose plants are the relieved loop's
    (:func:`.loadobjective.effective_plant` with the load-relief gain ``gain``)."""
    plants = {p: {m: effective_plant(g, gain, p) for m, g in pl.items()} for p, pl in case[2]["load"].items()}
    return plants, case[1], case[2]


@reused_flights()
def design_schedule(vehicle: Any = "smile", times=None, req: Requirements | None = None, starts: int = 2,
                    seed: int = 0, log=print, relief: tuple[float, float] | None = None,
                    planes: tuple[str, ...] = ("pitch",), fly: str = "auto", maxiter: int = MAXITER,
                    load_objective: str | None = None, load_weight: float = 10.0, **options: Any) -> dict[str, Any]:
    """Design every row of ``vehicle``'s schedule in time order. Each row flies the stretch between the
    midpoints to its neighbours in the same burn (the policy switches rows at the mass midpoints,
    ``interpolation: nearest``), and is designed to meet the requirements at its own time and at both
    ends of its stretch; the end's plants are flown to with the rows before it (the right end: with
    a first design of the row from its time and left end, which the final design then starts from).
    ``relief = (ki_scale, accel_gain)``: every row, once designed, flies with its integral gain scaled
    and the load-relief gain ``accel_gain`` [rad/s per m/s^2] (the later rows are flown to so); its other
    parameters are designed again on the loop so relieved (:func:`relief_row`), and it is checked so
    (the rate loop's margins; the accelerometer path is not in the linear plant). Its ``plain`` entry
    records the design it came from (gains, filter, and on the optimiser's grid: whether it met every
    requirement, its slowest divergence [1/s] and its smallest gain margin [dB], worst over the
    stretch). ``planes``:
    the planes whose loops the optimiser holds to the requirements (the pitch loop's disturbance response
    is the objective; every row is checked in both planes whatever it is). ``vehicle``: a shipped name or a
    vehicle file (:func:`.target.design_env`; ``times`` then required; ``options``: env keywords).
    ``fly``: how a row with no designed row before it (the first) is flown to: ``centred``, ``pid`` (a
    rigid PID schedule at the same times designed first, :func:`.tune.schedule` with ``fly="rows"``) or a
    schedule file; ``privileged``: every operating point with the privileged reference; ``auto``: ``centred``
    for a shipped vehicle (its schedules unchanged), ``pid`` for a file. ``maxiter``: the optimiser's
    iterations per start (fewer: a faster, less converged design). A document not flown centred records how
    in ``operating_points``. ``load_objective`` (``qalpha`` or ``accel``; None, the default: none): every row,
    once designed plainly, is designed again with its load-relief gain and integral chosen by the design
    (:func:`.loadobjective.load_row`: ``log J + load_weight log load`` under the requirements, the drift as
    fast as the vehicle's own allowed) and checked on the relieved loop (:func:`.loadobjective.effective_plant`);
    its ``load`` entry records the load measure and ``J`` of the design and of the plain one, its ``plain``
    entry the plain design as a ``relief`` row's. Returns the schedule document."""
    from .target import check_fly, check_vehicle, describe, fly_mode, flyer, schedule_flyer
    from .tune import default_times

    check_load_options(load_objective, load_weight)
    if load_objective is not None and relief is not None:
        raise ConfigError("load_objective", load_objective, "None with relief (--load-relief gives the relief; "
                          "--load-objective chooses it)")
    load = load_objective is not None
    vehicle = check_vehicle(vehicle, "v1")
    fly = fly_mode(check_fly(fly), vehicle)
    fly = "pid" if fly == "rows" else fly
    if not planes or any(p not in ("pitch", "yaw") for p in planes) or planes[0] != "pitch":
        raise ValueError(f"planes = {planes!r}: ('pitch',) or ('pitch', 'yaw')")
    req = req or Requirements()
    times = tuple(sorted(default_times(vehicle, FLEX_TIMES) if times is None else times))
    first, rigid_doc = None, None
    if fly == "pid":
        from .tune import schedule as rigid_schedule

        log("the rigid PID schedule that flies to the first row (lvgym design pid):")
        rigid_doc = rigid_schedule(vehicle, times, log=log, protocol="v1", fly="rows", **options)
        if not rigid_doc["rows"]:
            raise RuntimeError(f"no rigid PID row of {vehicle} could be tuned at {list(times)} s")
        first = schedule_flyer({k: rigid_doc[k] for k in ("variable", "rows")})
    else:
        first = flyer(fly)
    how = describe(fly) if fly == "privileged" else f"the gs-pid-flex rows designed so far; before the first: {describe(fly)}"
    log(f"operating points: {how}")
    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    skipped: list[dict[str, Any]] = []
    warm, left = None, None
    for k, t in enumerate(times):
        own = row_plants(vehicle, t, schedule_policy(rows) if rows and fly != "privileged" else first, load, **options)
        if own[2]["thrust_n"] <= 0.0:
            log(f"t = {t:g} s: no thrust (coast), skipped")
            skipped.append({"time_s": float(t), "reason": "coast"})
            warm, left = None, None
            continue
        notch = notch_frequency(own[1], float(own[0]["pitch"]["rigid"].dt))
        cases = [(t, own)] + ([left] if left is not None else [])
        loops = [(c[0][p], c[1]) for _, c in cases for p in planes]
        noise = own[2]["noise"]
        plain = design_row(RowProblem(loops, req, noise=noise), warm, rng, starts, maxiter)
        e = plain if relief is None else relief_row(loops, req, plain, relief[0], noise=noise)
        if load:
            e = load_row(_load_cases(cases, planes), req, plain, load_objective, load_weight, noise=noise, maxiter=maxiter)
        gain = relief[1] if relief is not None else e["values"]["accel_gain"] if load else None
        right = None
        if k + 1 < len(times):
            t_r = 0.5 * (t + times[k + 1])
            gains, filt = controller(e["values"], notch)
            first_rows = rows + [{"time_s": t, "mass_kg": own[2]["mass_kg"], "kp": gains[0], "ki": gains[1], "kd": gains[2],
                             "filter": filt.as_dict(), **({} if gain is None else {"accel_gain": gain})}]
            try:
                case = row_plants(vehicle, t_r, first if fly == "privileged" else schedule_policy(first_rows), load,
                                  **options)
                right = (t_r, case) if case[2]["thrust_n"] > 0.0 else None
            except RuntimeError as exc:                  # the flight ended before the stretch's end
                log(f"t = {t_r:g} s: not reached ({exc}); the row is designed without its right end")
        if right is not None:
            cases.append(right)
            loops = [(c[0][p], c[1]) for _, c in cases for p in planes]
            before = e["values"]                         # the row's design on its time and left end
            plain = design_row(RowProblem(loops, req, noise=noise), plain["values"], rng, starts=0, maxiter=maxiter)
            e = plain if relief is None else relief_row(loops, req, plain, relief[0], [e["values"]], noise=noise)
            if load:
                e = load_row(_load_cases(cases, planes), req, plain, load_objective, load_weight, [before],
                             noise=noise, maxiter=maxiter)
                gain = e["values"]["accel_gain"]
        warm = plain["values"]
        gains, filt = controller(e["values"], notch)
        checks = [_checked(_relieved(c, gain) if load else c, tc, gains, filt, req) for tc, c in cases]
        row = {"time_s": float(t), "mass_kg": round(own[2]["mass_kg"], 2), "kp": float(gains[0]),
               "ki": float(gains[1]), "kd": float(gains[2]), "filter": filt.as_dict(),
               **({} if gain is None else {"accel_gain": float(gain)}),
               "meets": all(c["meets"] for c in checks),
               "misses": [m for m in MISSES if any(m in c["misses"] for c in checks)],
               "objective": round(float(e["J"]), 4),
               "stretch_s": [round(min(tc for tc, _ in cases), 3), round(max(tc for tc, _ in cases), 3)],
               "margins": checks[0]["margins"], "modes": checks[0]["modes"], "ends": checks[1:]}
        if load:
            row["load"] = {"objective": load_objective, "value": round(float(e["load"]), 4),
                           "plain": round(float(e["load_plain"]), 4), "J": round(float(e["J"]), 4),
                           "J_plain": round(float(e["J_plain"]), 4)}
        if relief is not None or load:                 # the design the relieved row came from
            pg, pf = controller(plain["values"], notch)
            row["plain"] = {"kp": float(pg[0]), "ki": float(pg[1]), "kd": float(pg[2]), "filter": pf.as_dict(),
                            "feasible": bool(plain["feasible"]),
                            "max_pole_real_per_s": round(max(plain[m][3] for m in ("rigid", "nonrigid")), 5),
                            "gain_margin_db": round(min(plain[m][0] for m in ("rigid", "nonrigid")), 2)}
        rows.append(row)
        log(row_line(row) + "".join(f"\n    end {row_line(c)}" for c in checks[1:]))
        left = right
    doc = {"vehicle": vehicle, "protocol": "v1",
           "source": "python -m lvgym.baselines.design.flexdesign (non-rigid v1 flight loop, discrete)",
           "variable": "mass", "interpolation": "nearest", "requirements": asdict(req),
           "design": {"starts": starts, "seed": seed, "planes": list(planes),
                      **({} if maxiter == MAXITER else {"maxiter": maxiter}), **({} if relief is None else
                                                         {"ki_scale": relief[0], "accel_gain": relief[1]}),
                      **({} if not load else {"load_objective": load_objective, "load_weight": load_weight})},
           "rows": rows, "skipped": skipped}
    if fly != "centred" or options:                     # the shipped schedules' documents unchanged
        doc["operating_points"] = {"flown_with": how,
                                   **({"env_options": dict(options)} if options else {}),
                                   **({"rigid_pid_rows": [{k: r[k] for k in ("time_s", "mass_kg", "kp", "ki", "kd", "n")}
                                                          for r in rigid_doc["rows"]]} if rigid_doc else {})}
    return doc


@dataclass
class Args:
    """Command-line arguments (``lvgym design pid-flex --help``)."""

    vehicle: str = arg("smile", check=vehicle_option, metavar="NAME|PATH")
    """the vehicle whose schedule is designed: a shipped vehicle (smile, stratos3, slender) or the path of a
    vehicle YAML file, flown in SMILE's v1 env (docs/vehicles.md; default --times: 8 equal parts of its burning
    flight)"""
    fly: str = arg("auto", check=fly_option, metavar="MODE|SCHEDULE")
    """how the first row's operating points are reached (the later rows: with the rows designed so far):
    centred (gimbal at zero), pid (a rigid PID schedule designed first at the same times), privileged (every
    row's with the privileged reference, which needs no design), a schedule file, or auto (centred for a shipped vehicle, pid for a file)"""
    out: str | None = None
    """YAML file (default results/schedules/<vehicle>_flex.yaml; with --overwrite: the shipped
    baselines/schedules/<vehicle>_flex.yaml)"""
    overwrite: bool = False
    """allow replacing a shipped schedule (gs-pid-flex reads it)"""
    times: list[float] | None = arg(None, nargs="*", lo=0.0, lo_open=True, hi=3600.0)
    """flight times of the rows [s] (default: the vehicle's, FLEX_TIMES)"""
    starts: int = arg(2, lo=0, hi=100)
    """random starts of the optimiser per row (besides the warm one)"""
    seed: int = 0
    """seed of the random starts"""
    maxiter: int = arg(MAXITER, lo=10, hi=100000)
    """the optimiser's iterations per start (fewer: faster, less converged)"""
    load_relief: tuple[float, float] | None = arg(None, lo=0.0, hi=1.0, metavar=("KI_SCALE", "ACCEL_GAIN"))
    """load relief: scale every row's integral gain by KI_SCALE and add ACCEL_GAIN [rad/s per m/s^2]"""
    planes: list[str] = arg(default_factory=lambda: ["pitch"], choices=("pitch", "yaw"))
    """planes the optimiser holds to the requirements: pitch, or pitch yaw"""
    load_objective: str | None = arg(None, choices=OBJECTIVES)
    """a load objective the design chooses each row's load relief by (accel_gain and ki): qalpha (the RMS of
    q alpha in 1 m/s of lateral Dryden turbulence) or accel (of the accelerometer's lateral specific force);
    default none (docs/flex-design.md, "The load objective")"""
    load_weight: float = arg(10.0, lo=0.0, lo_open=True, hi=100.0)
    """with --load-objective: the weight of the load measure against the disturbance objective (the design
    minimises log J + WEIGHT log load)"""
    noise_rate: float | None = arg(None, lo=0.0, lo_open=True, hi=100.0, metavar="FRACTION")
    """hold the gimbal rate the gyro's noise commands to this fraction of the servo's rate limit (RMS;
    default: reported, not required; docs/flex-design.md)"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design pid-flex`` (``python -m lvgym.baselines.design.flexdesign``): design and write the schedule."""
    import sys

    import yaml

    from lvgym.benchmark.results import atomic_write_text
    from lvgym.commandline import command_name, fail, parse

    from .tune import SCHEDULES, default_times, output_path

    prog = "python -m lvgym.baselines.design.flexdesign"
    a = parse(Args, argv, prog, __doc__)
    name = stem(a.vehicle)
    try:                                             # refused before the (slow) design
        out = output_path(name, a.out, a.overwrite, stem=f"{name}_flex")
        times = default_times(a.vehicle, FLEX_TIMES, "--times") if not a.times else a.times
        if a.load_objective is not None and a.load_relief is not None:
            raise ConfigError("--load-objective", a.load_objective, "not with --load-relief (which gives the relief "
                              "--load-objective chooses)")
    except ConfigError as exc:
        fail(command_name(prog), exc)
    planes = tuple(dict.fromkeys(["pitch", *a.planes]))
    doc = design_schedule(a.vehicle, times, Requirements(noise_rate_fraction=a.noise_rate), starts=a.starts,
                          seed=a.seed, relief=a.load_relief, planes=planes, fly=a.fly, maxiter=a.maxiter,
                          load_objective=a.load_objective, load_weight=a.load_weight)
    if not doc["rows"]:
        print(f"no flight time of {a.vehicle} could be designed; nothing written", file=sys.stderr)
        return 1
    shipped = out.parent.resolve() == SCHEDULES.resolve()
    again = (f"lvgym design pid-flex --vehicle {a.vehicle} --starts {a.starts}"
             + ("" if a.load_relief is None else " --load-relief {:g} {:g}".format(*a.load_relief))
             + ("" if not a.times else " --times " + " ".join(f"{t:g}" for t in a.times))
             + ("" if planes == ("pitch",) else " --planes " + " ".join(planes))
             + ("" if a.noise_rate is None else f" --noise-rate {a.noise_rate:g}")
             + ("" if a.load_objective is None else f" --load-objective {a.load_objective}"
                + ("" if a.load_weight == 10.0 else f" --load-weight {a.load_weight:g}"))
             + ("" if a.fly == "auto" else f" --fly {a.fly}")
             + ("" if a.maxiter == MAXITER else f" --maxiter {a.maxiter}")
             + (" --overwrite" if shipped else f" --out {out}"))
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, f"# gs-pid-flex schedule of {a.vehicle}, regenerated by: {again}\n"
                      "# Gains: rad of gimbal per rad/s of filtered rate error (kp), per rad (ki), per rad/s^2 (kd); "
                      "filter frequencies [rad/s].\n"
                      + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120))
    table = out.with_name(out.stem + "_margins.md")
    atomic_write_text(table, margin_table(doc))
    bad = [r["time_s"] for r in doc["rows"] if not r["meets"]]
    print(f"wrote {out} and {table}" + (f"; requirements NOT met at t = {bad} s" if bad else "; every row meets the requirements"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
