"""Tune PID rate gains on the linearised rigid vehicle and write a gain schedule.

``lvgym design pid --vehicle smile`` (``python -m lvgym.baselines.design.tune``) writes
``results/schedules/smile.yaml`` (or ``--out``); the shipped schedules that ``gs-pid`` reads
(``baselines/schedules/``) are replaced only with ``--overwrite`` (``lvgym design pid --vehicle smile
--overwrite``).

At each flight time of the schedule: linearise the rigid vehicle (:func:`.linearize.linearize`), put the
servo, the zero-order hold of the control period and the discrete PID in the loop, and place the gain
crossover at the target bandwidth with the target phase margin (thesis 6.3.1: 75 rad/s and 35 deg at
28.8 s). The PID has three gains and the two targets fix two: the integral zero is put a third of
the crossover (``Ki = Kp * w_c / ki_ratio``) and Kp, Kd solve ``C(jw_c) G(jw_c) = -exp(j PM)``. When
the target cannot be met (a gain would be negative, or the closed loop is unstable), the crossover is
lowered step by step to the highest that meets the phase margin; the achieved numbers are written
beside the targets. Each row also carries the loop's margins with the rigid and the non-rigid
(slosh and bending) linearisation.
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import control
import numpy as np
import yaml

from lvgym.commandline import arg

from .linearize import linearize, loop, margins, operating_point, reused_flights
from .target import fly_option, is_shipped, stem, vehicle_option
from ..pid import SCHEDULES

#: flight times of the schedule per vehicle [s] (smile: those of Table 6.10) and their env options
VEHICLE_TIMES = {"smile": (3.0, 15.0, 28.8, 40.0, 46.0), "stratos3": (2.0, 6.0, 10.0, 14.0, 18.0),
                 "slender": (1.0, 3.0, 5.0, 7.0, 9.0)}


def _freq(sys_: control.LTI, w: float) -> complex:
    return complex(sys_(np.exp(1j * w * sys_.dt)) if sys_.dt else sys_(1j * w))


def place(plant: control.StateSpace, wc: float, pm_deg: float, dt: float | None = 0.02, n: float = 500.0,
          ki_ratio: float = 3.0, servo: tuple[float, float] = (15.0, 0.7)) -> tuple[float, float, float, float] | None:
    """Gains (kp, ki, kd, n) putting the loop's gain crossover at ``wc`` [rad/s] with phase margin
    ``pm_deg``, or None when that needs a negative gain."""
    g = loop(plant, (1.0, 0.0, 0.0, None), dt, servo)          # servo * plant (discretised) with C = 1
    G = _freq(g, wc)
    target = -np.exp(1j * math.radians(pm_deg)) / G            # required C(jw_c)
    if dt:
        z = np.exp(1j * wc * dt)
        I = dt * z / (z - 1)
        D = n * (z - 1) / ((1 + n * dt) * z - 1)
    else:
        s = 1j * wc
        I, D = 1 / s, n * s / (s + n)
    a = 1 + (wc / ki_ratio) * I                                 # C = kp a + kd D
    M = np.array([[a.real, D.real], [a.imag, D.imag]])
    kp, kd = np.linalg.solve(M, [target.real, target.imag])
    if kp < 0 or kd < 0:
        return None
    return float(kp), float(kp * wc / ki_ratio), float(kd), float(n)


def tune(plant: control.StateSpace, bandwidth: float = 75.0, pm_deg: float = 35.0, dt: float | None = 0.02,
         n: float = 500.0, ki_ratio: float = 3.0, servo: tuple[float, float] = (15.0, 0.7),
         min_gm_db: float = 0.0, drift_tol: float = 0.02) -> dict[str, Any]:
    """Gains for the target, or for the highest crossover below it (log steps of 2 %) that meets the phase
    margin with a gain margin of at least ``min_gm_db`` and a closed loop whose poles are stable except
    for a drift slower than ``drift_tol`` [1/s] (a doubling time of 35 s at 0.02: after staging the
    small upper stage has an unstable drift pole pair near the origin, 0.0075 1/s for SMILE at 46 s,
    that a rate loop without attitude feedback does not stabilise and need not over a minute)."""
    w = bandwidth
    while w > 0.05 * bandwidth:
        gains = place(plant, w, pm_deg, dt, n, ki_ratio, servo)
        if gains is not None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                m = margins(loop(plant, gains, dt, servo))
            if m["max_pole_real_per_s"] < drift_tol and m["gain_margin_db"] >= min_gm_db:
                return {"gains": gains, "crossover_radps": w, "target_met": w == bandwidth, **m}
        w /= 1.02
    raise RuntimeError(f"no PID meets a {pm_deg} deg phase margin above {0.05 * bandwidth:.3g} rad/s")


def loop_margins(plant: control.StateSpace, gains, dt: float | None = 0.02, servo=(15.0, 0.7)) -> dict[str, float]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return margins(loop(plant, gains, dt, servo))


def _rounded(m: dict) -> dict:
    return {k: (round(v, 5 if k.startswith("max_pole") else 2) if isinstance(v, float) else v) for k, v in m.items()}


def default_times(vehicle: Any, table: dict[str, tuple[float, ...]], option: str = "times",
                  protocol: str = "v1") -> tuple[float, ...]:
    """The rows' flight times of a shipped ``vehicle`` in ``table`` (another shipped vehicle: SMILE's); a
    vehicle file's: :func:`.target.file_times` in ``protocol``'s env (``option``: the option that gives them
    instead, named in an error)."""
    from .target import file_times, is_shipped

    if is_shipped(vehicle) and vehicle in table:
        return table[vehicle]
    if is_shipped(vehicle):
        return table["smile"]
    return file_times(vehicle, protocol=protocol, option=option)


@reused_flights()
def schedule(vehicle: Any = "smile", times=None, bandwidth: float = 75.0, pm_deg: float = 35.0, dt: float = 0.02,
             n: float = 500.0, ki_ratio: float = 3.0, log=print, protocol: str = "v0", fly: str = "auto",
             **options: Any) -> dict[str, Any]:
    """Tune at each time and return the schedule document (variable: vehicle mass). ``vehicle``: a shipped
    name or a vehicle file (:func:`.target.design_env`; ``options``: env keywords), flown in ``protocol``'s
    env. ``fly``: how each row's operating point is reached (:data:`.target.FLY_MODES`): ``centred`` (the
    gimbal at zero), ``rows`` (the schedule of the rows tuned so far, so a vehicle unstable without
    control reaches every row: rows are tuned in time order, the first flown centred), ``privileged`` (the
    privileged reference, which needs no design) or a schedule file;
    ``auto`` (and ``pid``) is ``centred`` for a shipped vehicle (its schedules unchanged) and ``rows`` for a
    file. A document of a flight not flown centred records how in ``operating_points``."""
    from .target import check_fly, check_vehicle, describe, fly_mode, flyer, schedule_flyer

    vehicle = check_vehicle(vehicle, protocol)
    fly = fly_mode(check_fly(fly), vehicle)
    fly = "rows" if fly == "pid" else fly
    times = default_times(vehicle, VEHICLE_TIMES) if times is None else tuple(sorted(times))
    log(f"operating points: {describe(fly)}")
    rows: list[dict[str, Any]] = []
    skipped: list[dict[str, Any]] = []
    for t in times:
        policy = None
        if fly == "rows" and rows:
            policy = schedule_flyer({"variable": "mass", "rows": rows})
        elif fly != "rows":
            policy = flyer(fly)
        op = operating_point(vehicle, t, "rigid", protocol=protocol, policy=policy, **options)
        tl = op.sim.timeline
        if op.condition("thrust") <= 0.0:
            log(f"t = {t:g} s: no thrust (coast), skipped")
            continue
        mass = float(tl.interp("mass", [t])[0])
        rigid = linearize(op=op)
        try:
            res = tune(rigid, bandwidth, pm_deg, dt, n, ki_ratio)
        except RuntimeError as exc:               # e.g. an aerodynamically unstable vehicle beyond a Mach
            unstable = np.linalg.eigvals(rigid.A).real.max()
            log(f"t = {t:g} s: skipped, {exc} (fastest open-loop pole of the rigid plant {unstable:+.3g} 1/s)")
            skipped.append({"time_s": float(t), "reason": str(exc),
                            "max_open_loop_pole_real_per_s": round(float(unstable), 5)})
            continue
        gains = res["gains"]
        mr = loop_margins(rigid, gains, dt)
        try:
            nonrigid = linearize(op=operating_point(vehicle, t, "nonrigid", protocol=protocol, policy=policy, **options))
            mn = loop_margins(nonrigid, gains, dt)
        except RuntimeError as exc:                # the non-rigid flight ended before t (flown by the rows so far)
            if policy is None:
                raise
            log(f"t = {t:g} s: the non-rigid flight did not reach the row ({exc}); its margins left out")
            mn = {"gain_margin_db": float("nan"), "phase_margin_deg": float("nan"), "closed_loop_stable": None,
                  "not_reached": str(exc)}
        row = {"time_s": float(t), "mass_kg": round(mass, 1), "kp": round(gains[0], 4), "ki": round(gains[1], 4),
               "kd": round(gains[2], 4), "n": gains[3], "crossover_radps": round(res["crossover_radps"], 2),
               "target_met": bool(res["target_met"]),
               "rigid": _rounded(mr), "nonrigid": _rounded(mn)}
        rows.append(row)
        log(f"t = {t:5.1f} s  m = {mass:8.1f} kg  Kp {gains[0]:.4f}  Ki {gains[1]:.4f}  Kd {gains[2]:.4f}  "
            f"w_c {res['crossover_radps']:.1f} rad/s  rigid GM {mr['gain_margin_db']:.1f} dB PM "
            f"{mr['phase_margin_deg']:.1f} deg  nonrigid GM {mn['gain_margin_db']:.1f} dB PM "
            f"{mn['phase_margin_deg']:.1f} deg stable {mn['closed_loop_stable']}")
    doc = {"vehicle": vehicle, "source": "python -m lvgym.baselines.design.tune (rigid linearisation, discrete loop)",
           "variable": "mass", "target": {"bandwidth_radps": bandwidth, "phase_margin_deg": pm_deg,
                                          "control_dt_s": dt, "ki_ratio": ki_ratio},
           "rows": rows, "skipped": skipped}
    if fly != "centred" or protocol != "v0" or options:        # the shipped schedules' documents unchanged
        doc["operating_points"] = {"protocol": protocol, "flown_with": describe(fly),
                                   **({"env_options": {k: v for k, v in options.items()}} if options else {})}
    return doc


#: where a tuned schedule goes unless --out says otherwise
RESULTS = Path("results") / "schedules"


def output_path(vehicle: str, out: str | None, overwrite: bool, stem: str | None = None) -> Path:
    """The file a run writes: ``out``, else the shipped schedule with ``overwrite``, else
    ``results/schedules/<stem>.yaml`` (``stem`` defaults to the vehicle). A shipped schedule (a file in
    ``baselines/schedules/``) is never written without ``overwrite``: a ``ConfigError`` naming ``--out``
    instead."""
    from lvgym.errors import ConfigError

    stem = stem or vehicle
    if out is None:
        return SCHEDULES / f"{stem}.yaml" if overwrite else RESULTS / f"{stem}.yaml"
    path = Path(out)
    shipped = path.resolve().parent == SCHEDULES.resolve()
    if shipped and path.exists() and not overwrite:
        raise ConfigError("--out", out, "not a shipped schedule (gs-pid reads it): add --overwrite to replace it, "
                          f"or write elsewhere (default {RESULTS / (stem + '.yaml')})")
    if path.is_dir():
        raise ConfigError("--out", out, "a YAML file path, not a folder")
    return path


def write_schedule(out: Path, title: str, command: str, units: str, doc: dict[str, Any]) -> None:
    """Write a schedule document to ``out`` (atomically, its folder made) under two comment lines: ``title``,
    regenerated by ``command`` (``--overwrite`` or ``--out`` added as ``out`` says), and the gains' units."""
    from lvgym.benchmark.results import atomic_write_text

    command += " --overwrite" if out.parent.resolve() == SCHEDULES.resolve() else f" --out {out}"
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, f"# {title}, regenerated by: {command}\n# Gains: {units}.\n"
                      + yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=120))


@dataclass
class Args:
    """Command-line arguments (``lvgym design pid --help``)."""

    vehicle: str = arg("smile", check=vehicle_option, metavar="NAME|PATH")
    """the vehicle whose schedule is tuned: a shipped vehicle (smile, stratos3, slender) or the path of a
    vehicle YAML file (docs/vehicles.md; default --times: 8 equal parts of its burning flight)"""
    protocol: str = arg("v0", choices=("v0", "v1"))
    """the protocol whose env flies the vehicle to each row (a file: in SMILE's env of it)"""
    fly: str = arg("auto", check=fly_option, metavar="MODE|SCHEDULE")
    """how each row's operating point is reached: centred (gimbal at zero), rows (the schedule of the rows
    tuned so far), privileged (the privileged reference, which needs no design), a schedule file, or auto (centred for a shipped vehicle, rows for a file)"""
    out: str | None = None
    """YAML file (default results/schedules/<vehicle>.yaml; with --overwrite: the shipped
    baselines/schedules/<vehicle>.yaml)"""
    overwrite: bool = False
    """allow replacing a shipped schedule (gs-pid reads them)"""
    times: list[float] | None = arg(None, nargs="*", lo=0.0, hi=3600.0)
    """flight times of the rows [s] (default: the vehicle's, VEHICLE_TIMES)"""
    bandwidth: float = arg(75.0, lo=0.0, lo_open=True, hi=1e4)
    """target gain crossover [rad/s]"""
    phase_margin: float = arg(35.0, lo=0.0, lo_open=True, hi=90.0)
    """target phase margin [deg]"""
    dt: float = arg(0.02, lo=0.0, hi=1.0)
    """control period [s] (0: continuous)"""
    n: float = arg(500.0, lo=0.0, lo_open=True, hi=1e6)
    """derivative filter coefficient [rad/s]"""
    ki_ratio: float = arg(3.0, lo=0.0, lo_open=True, hi=1e6)
    """crossover over the integral zero"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design pid`` (``python -m lvgym.baselines.design.tune``): tune and write the schedule."""
    from lvgym.commandline import command_name, fail, parse
    from lvgym.errors import ConfigError

    a = parse(Args, argv, "python -m lvgym.baselines.design.tune", __doc__)
    try:                                             # refused before the (slow) tuning
        out = output_path(stem(a.vehicle), a.out, a.overwrite)
        times = default_times(a.vehicle, VEHICLE_TIMES, "--times") if not a.times else a.times
    except ConfigError as exc:
        fail(command_name("python -m lvgym.baselines.design.tune"), exc)
    doc = schedule(a.vehicle, times, a.bandwidth, a.phase_margin, a.dt or None, a.n, a.ki_ratio, protocol=a.protocol,
                   fly=a.fly)
    if len(doc["rows"]) < 1:
        print(f"no flight time of {a.vehicle} could be tuned; nothing written", file=sys.stderr)
        return 1
    again = (f"lvgym design pid --vehicle {a.vehicle}" + ("" if a.protocol == "v0" else f" --protocol {a.protocol}")
             + ("" if a.fly == "auto" else f" --fly {a.fly}")
             + ("" if not a.times else " --times " + " ".join(f"{t:g}" for t in a.times)))
    write_schedule(out, f"Gain schedule of {a.vehicle}", again, "rad of gimbal per rad/s of rate error (kp), per "
                   "rad (ki), per rad/s^2 (kd); n [rad/s]", doc)
    shipped = out.parent.resolve() == SCHEDULES.resolve() or not is_shipped(a.vehicle)
    print(f"wrote {out}" + ("" if shipped else
                            f" (the shipped schedule that gs-pid reads is {SCHEDULES / (a.vehicle + '.yaml')}; "
                            "replace it with --overwrite)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())

