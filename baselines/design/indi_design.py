"""The ``indi`` schedule (:mod:`lvgym.baselines.indi`): control power over the flight and, per row, the gains and
the structural filter chosen on the linear loop (:mod:`.indiloop`).

``lvgym design indi --vehicle smile`` writes ``results/schedules/smile_indi.yaml``
(``--overwrite``: the shipped ``baselines/schedules/smile_indi.yaml``) and its margin table ``*_margins.md``.

What is designed, per row (a frozen flight time, its operating points flown with the privileged reference, no wind,
as :mod:`.pdrelief` and ``lvgym design auto`` fly them):

* the control power ``G = s T l / J`` [1/s^2] of the rigid body (:func:`.linearize.rigid_terms`), also every
  ``power_step`` seconds of the burning flight: the law interpolates that table over flight time;
* the filter ``H``: a second-order low-pass, a notch on the first bending mode where it lies below the Nyquist
  frequency (its frequency from the non-rigid linearisation, :func:`.flightloop.mode_frequencies`) and,
  optionally, a notch on the slosh band (the geometric mean of its lowest and highest pendulum frequency);
  the synchronisation sections on the actuator position (:class:`..indikernel.SyncSections`: the IMU's
  anti-aliasing filter, design data of the env's IMU, and the two-sample mean);
* the rate and attitude gains ``k_q``, ``k_theta``;
* the load-relief gain ``k_a`` (``--k-accel``, the same on every row): not on the linear loop, which leaves the
  accelerometers out, but on validation flights of the v2 SMILE suites (docs/indi.md).

The search: every candidate of :data:`GRID` is assessed on the row's rigid and non-rigid loop
(:func:`.indiloop.row_margins` on a coarse grid of :data:`SEARCH_POINTS` frequencies); its shortfall against
:class:`Requirements` (6 dB and 30 deg on both loops, closed-loop stable, the first bending mode 6 dB below unit
loop gain, the gyro noise's command rate at most 20 % of the servo's rate limit) is summed in units of each
requirement; the row takes the candidate of least shortfall, among equals (all met) the stiffest (largest
``k_q``, then ``k_theta``). The chosen row is assessed again on the dense grid for the table.
"""

from __future__ import annotations

import itertools
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.commandline import arg

from ..indikernel import INDIFilter, SyncSections
from .flightloop import mode_frequencies
from .indiloop import INDIRow, loop_plants, row_margins
from .linearize import operating_point, reused_flights, rigid_terms
from .target import burn_phases, privileged_flyer

__all__ = ["GRID", "Requirements", "control_power_table", "design_row", "design_schedule", "shortfall"]

SCHEDULES = Path(__file__).resolve().parents[1] / "schedules"
#: the candidates of every row: rate gain [1/s], attitude gain [1/s], low-pass [rad/s], slosh notch on
GRID = {"k_rate": (2.0, 3.0, 4.0, 6.0), "k_attitude": (1.5, 2.5, 3.5), "lowpass_radps": (2.5,),
        "slosh_notch": (True,)}
SEARCH_POINTS = 3000
#: the load-relief gain [rad/s per m/s^2] of every row: chosen on validation seeds 0-99 of the v2 SMILE suites
#: (docs/indi.md), not on the linear loop (which leaves the accelerometers out)
DEFAULT_K_ACCEL = 0.03
DEFAULT_TIMES = (3.0, 10.0, 15.0, 20.0, 24.4, 28.8, 32.4, 36.0, 42.5, 54.5, 62.0, 69.5)


@dataclass(frozen=True)
class Requirements:
    """The shipped classical designs' rules (docs/baselines.md, docs/flex-design.md): gain and phase margins of
    the rigid and non-rigid loops [dB, deg], the first bending mode's attenuation below unit gain [dB], the gyro
    noise's commanded gimbal rate over the rate limit [-]."""

    gm_db: float = 6.0
    pm_deg: float = 30.0
    bending_db: float = 6.0
    noise_rate_fraction: float = 0.2


def shortfall(m: dict[str, dict[str, Any]], rq: Requirements) -> float:
    """The sum of the relative shortfalls of ``m`` (``rigid`` and ``nonrigid`` margins) against ``rq``; 10 per
    unstable loop (0: every requirement met)."""
    s = 0.0
    for name in ("rigid", "nonrigid"):
        a = m[name]
        if not a["closed_loop_stable"]:
            s += 10.0
            continue
        s += max(0.0, 1.0 - a["gain_margin_db"] / rq.gm_db) + max(0.0, 1.0 - abs(a["phase_margin_deg"]) / rq.pm_deg)
        if a["phase_margin_deg"] < 0.0:
            s += 1.0
    n = m["nonrigid"]
    for db in n.get("bending_db", [])[:1]:
        s += max(0.0, (db + rq.bending_db) / rq.bending_db)
    s += max(0.0, n.get("noise_rate_fraction", 0.0) / rq.noise_rate_fraction - 1.0)
    return s


def _filter(lowpass: float, modes: dict[str, list[float]], slosh_notch: bool, dt: float) -> INDIFilter:
    nyq = math.pi / dt
    bend = [w for w in modes.get("bending", []) if w < 0.95 * nyq]
    slosh = modes.get("slosh", [])
    centre = math.sqrt(min(slosh) * max(slosh)) if (slosh_notch and slosh) else None
    return INDIFilter(lowpass_radps=lowpass, bending_radps=bend[0] if bend else None, slosh_radps=centre)


def design_row(op_rigid: Any, op_nonrigid: Any, sync: SyncSections, rq: Requirements = Requirements(),
               grid: dict[str, tuple] | None = None, k_accel: float = 0.0) -> dict[str, Any]:
    """The row at the operating points ``op_rigid``, ``op_nonrigid`` of one flight time (module docstring);
    ``k_accel`` [rad/s per m/s^2]: the load-relief gain the row carries (not in the linear loop)."""
    terms = rigid_terms(op_rigid)
    power = terms["vectored_thrust"] * terms["arm"] / terms["inertia"]
    modes = mode_frequencies(op_nonrigid)
    dt = float(op_rigid.task.control_dt_s)
    w = np.geomspace(1e-3, 0.9999 * math.pi / dt, SEARCH_POINTS)
    best: tuple | None = None
    pr, pn = loop_plants(op_rigid), loop_plants(op_nonrigid)
    for kq, kth, wl, notch in itertools.product(*(grid or GRID).values()):
        row = INDIRow(power, kq, kth, _filter(wl, modes, notch, dt), sync=sync)
        m = {"rigid": row_margins(row, op_rigid, noise=False, w=w, plants=pr),
             "nonrigid": row_margins(row, op_nonrigid, modes=modes, w=w, plants=pn)}
        key = (round(shortfall(m, rq), 6), -kq, -kth, wl)
        if best is None or key < best[0]:
            best = (key, row)
    row = best[1]
    m = {"rigid": row_margins(row, op_rigid, noise=False, plants=pr),
         "nonrigid": row_margins(row, op_nonrigid, modes=modes, plants=pn)}
    return {"time_s": float(op_rigid.t), "control_power_per_s2": power, "k_rate": row.k_rate,
            "k_attitude": row.k_attitude, "k_accel": k_accel, "filter": row.filt.as_dict(), "modes_radps": modes,
            "shortfall": shortfall(m, rq), "margins": m}


def control_power_table(vehicle: Any, step: float = 1.0) -> list[list[float]]:
    """``[[t, G], ...]``: the rigid control power [1/s^2] every ``step`` seconds of the burning flight (where the
    engine thrusts)."""
    fly = privileged_flyer()
    out = []
    with reused_flights():
        for a, b in burn_phases(vehicle, "v1"):
            for t in np.arange(a, b + 1e-9, step):
                terms = rigid_terms(operating_point(vehicle, float(t), "rigid", "v1", policy=fly))
                power = terms["vectored_thrust"] * terms["arm"] / terms["inertia"]
                if power > 0.0:                       # a phase's end may fall at the burn-out (no thrust)
                    out.append([round(float(t), 3), round(power, 5)])
    return out


def design_schedule(vehicle: Any = "smile", times: tuple[float, ...] = DEFAULT_TIMES, log: Any = print,
                    k_accel: float = DEFAULT_K_ACCEL) -> dict[str, Any]:
    """The schedule document of ``vehicle`` (module docstring); ``k_accel``: the load-relief gain of every row."""
    fly = privileged_flyer()
    rows = []
    t0 = time.time()
    with reused_flights():
        ops = {}
        for model in ("rigid", "nonrigid"):
            for t in times:
                ops[model, t] = operating_point(vehicle, t, model, "v1", policy=fly)
        imu = ops["rigid", times[0]].sim.imu
        sync = SyncSections() if imu is None else SyncSections(antialias_radps=2.0 * math.pi * float(imu.antialias_hz))
        for t in times:
            r = design_row(ops["rigid", t], ops["nonrigid", t], sync, k_accel=k_accel)
            rows.append(r)
            log(f"t = {t:g} s: k_q {r['k_rate']:g}, k_theta {r['k_attitude']:g}, "
                f"low-pass {r['filter']['lowpass_radps']:g} rad/s, slosh notch {r['filter']['slosh_radps'] is not None}, "
                f"shortfall {r['shortfall']:.3f} "
                f"({time.time() - t0:.0f} s)")
    dt = float(ops["rigid", times[0]].task.control_dt_s)
    return {"vehicle": str(vehicle), "protocol": "v1", "control_dt_s": dt,
            "requirements": Requirements().__dict__, "sync": {"antialias_radps": sync.antialias_radps,
                                                              "antialias_damping": sync.antialias_damping,
                                                              "average": sync.average},
            "control_power": control_power_table(vehicle), "rows": _plain(rows)}


def _plain(x: Any) -> Any:
    """``x`` with numpy numbers and tuples as plain YAML values (floats rounded to 6 significant digits)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (float, np.floating)):
        return float(f"{float(x):.6g}") if math.isfinite(x) else float(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


def margin_table(doc: dict[str, Any]) -> str:
    """The schedule's margins as a Markdown table."""
    lines = ["| t [s] | G [1/s^2] | k_q [1/s] | k_theta [1/s] | low-pass [rad/s] | bending notch [rad/s] | slosh notch "
             "[rad/s] | rigid GM up/down [dB], PM [deg] | non-rigid GM up/down [dB], PM [deg] | bending 1 [dB] | "
             "noise [%] | meets |", "|" + "---:|" * 11 + "---|"]
    for r in doc["rows"]:
        m, f = r["margins"], r["filter"]

        def mm(a: dict) -> str:
            s = f"{a['gain_margin_db']:.1f} / {a['gain_reduction_margin_db']:.1f}, {a['phase_margin_deg']:.1f}"
            return s + ("" if a["closed_loop_stable"] else " (unstable)")
        bend = m["nonrigid"].get("bending_db", [])
        lines.append(f"| {r['time_s']:g} | {r['control_power_per_s2']:.2f} | {r['k_rate']:g} | {r['k_attitude']:g} | "
                     f"{f['lowpass_radps']:g} | "
                     f"{'-' if f['bending_radps'] is None else format(f['bending_radps'], '.1f')} | "
                     f"{'-' if f['slosh_radps'] is None else format(f['slosh_radps'], '.1f')} | {mm(m['rigid'])} | "
                     f"{mm(m['nonrigid'])} | {bend[0]:.1f} | {100 * m['nonrigid']['noise_rate_fraction']:.1f} | "
                     f"{'yes' if r['shortfall'] == 0 else 'no'} |" if bend else "")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``lvgym design indi --help``)."""

    vehicle: str = "smile"
    """the vehicle whose schedule is designed (smile)"""
    out: str | None = None
    """YAML file (default results/schedules/<vehicle>_indi.yaml)"""
    overwrite: bool = False
    """write the shipped baselines/schedules/<vehicle>_indi.yaml"""
    k_accel: float = arg(DEFAULT_K_ACCEL, lo=0.0, hi=1.0)
    """load-relief gain [rad/s per m/s^2]"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design indi [--vehicle smile] [--out PATH] [--overwrite]``."""
    from lvgym.commandline import parse

    a = parse(Args, argv, "lvgym design indi", __doc__)
    out = Path(a.out) if a.out else (SCHEDULES if a.overwrite else Path("results/schedules")) / f"{a.vehicle}_indi.yaml"
    doc = design_schedule(a.vehicle, k_accel=a.k_accel)
    out.parent.mkdir(parents=True, exist_ok=True)
    head = (f"# indi schedule of {a.vehicle}, made by: "
            f"lvgym design indi --vehicle {a.vehicle}"
            f"{' --overwrite' if a.overwrite else ''}\n# Gains: k_rate, k_attitude [1/s]; control power [1/s^2]; "
            "filter frequencies [rad/s].\n")
    out.write_text(head + yaml.safe_dump(doc, sort_keys=False, width=120))
    table = f"# indi margins: {a.vehicle} (protocol v1)\n\n" + margin_table(doc)
    out.with_name(out.stem + "_margins.md").write_text(table)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
