"""Bode and Nichols charts of a gain schedule's open loops, rigid and non-rigid, margins marked.

``lvgym design charts --vehicle smile --protocol v1 --schedule smile [--out results/charts]``
(``python -m lvgym.baselines.design.charts``)

At each row of the schedule (``baselines/schedules/<schedule>.yaml`` or a path) the vehicle is linearised
at the row's flight time (:func:`.linearize.operating_point` of the protocol's env), the flight
computer's plant is built (:func:`.flightloop.flight_plant`: servo, vehicle, slope at the IMU, gyro
filters, hold, delay) and the row's discrete PID closes it, behind the row's structural filters when the
schedule has them (a ``gs-pid-flex`` schedule: lead, low-pass and notch,
:class:`~lvgym.baselines.filters.StructuralFilter`, or several such filters in series,
:class:`~lvgym.baselines.filters.FilterSeries`, as the flex design and the flight apply them), and with the
row's attitude channel when the schedule has one (``attitude_gain`` k_theta: the error
``-(rate + k_theta theta)``, the attitude ``theta`` modelled as the trapezoidal integral of the sampled rate,
``dt/2 (z + 1)/(z - 1)``, which the strapdown attitude of the flight observation is up to the gyro's
sampling). The accelerometer channel (``accel_gain``) is not in the charts: they show the loop without load
relief. Per row one figure ``loop_<t>s.png``: the
open loop's magnitude and phase against frequency up to the Nyquist frequency of the control rate, and its
Nichols chart, for the rigid and the non-rigid model, with the gain and phase margins of
:func:`.linearize.margins` written in the legend and the crossovers marked. A row in a coast (no thrust)
is skipped with a message. ``margins.json`` beside the figures holds the numbers.
"""

from __future__ import annotations

import json
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import control
import numpy as np

from lvgym.commandline import arg

from .flightloop import flight_plant, frequency_response, mode_frequencies
from .linearize import margins, operating_point, pid_tf
from .target import vehicle_option
from ..filters import Filter, filter_count
from ..pid import GainSchedule


def attitude_tf(attitude_gain: float, dt: float) -> control.TransferFunction:
    """``1 + k_theta dt/2 (z + 1)/(z - 1)``: the rate measurement's path through the error with the attitude
    channel ``attitude_gain`` k_theta [rad/s per rad] (the attitude as the trapezoidal integral of the
    sampled rate, at the period ``dt`` [s])."""
    z = control.tf([1.0, 0.0], [1.0], dt)
    return 1 + attitude_gain * 0.5 * dt * (z + 1) / (z - 1)


def open_loop(op, gains: tuple[float, float, float, float], plane: str = "pitch",
              filt: Filter | None = None, attitude_gain: float = 0.0) -> control.StateSpace:
    """The discrete open loop ``C(z) G(z)`` of the flight computer's plant at ``op`` with the PID
    ``gains`` (kp, ki, kd, n) at the env's control period (negative feedback of the gyro rate), behind the
    structural filter or filters in series ``filt`` when given, with the attitude channel ``attitude_gain``
    [rad/s per rad] (:func:`attitude_tf`) when not 0."""
    g = flight_plant(op, plane)
    c = pid_tf(*gains, dt=g.dt)
    if filt is not None:
        c = c * filt.tf(g.dt)
    if attitude_gain:
        c = c * attitude_tf(attitude_gain, g.dt)
    return control.series(g, control.ss(c))


def row_loops(vehicle: Any, protocol: str, t: float, gains, policy: Any = None, filt: Filter | None = None,
              attitude_gain: float = 0.0, **options: Any) -> dict[str, Any] | None:
    """Open loops, margins and plant modes at flight time ``t`` [s], or None in a coast; the operating
    points flown with ``policy`` (None: the gimbal centred; :func:`.linearize.operating_point`); ``filt``:
    the row's structural filter (one, or several in series); ``attitude_gain``: the row's attitude channel
    [rad/s per rad]."""
    out: dict[str, Any] = {}
    for model in ("rigid", "nonrigid"):
        op = operating_point(vehicle, t, model, protocol=protocol, policy=policy, **options)
        if op.condition("thrust") <= 0.0:
            return None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            L = open_loop(op, gains, filt=filt, attitude_gain=attitude_gain)
            out[model] = {"loop": L, "margins": margins(L)}
        if model == "nonrigid":
            out["modes_radps"] = mode_frequencies(op)
    return out


def _chart(t: float, loops: dict[str, Any], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dt = loops["rigid"]["loop"].dt
    w = np.logspace(-1, math.log10(math.pi / dt), 3000)
    fig, (a_mag, a_nic) = plt.subplots(1, 2, figsize=(12, 4.5))
    a_ph = a_mag.twinx()
    for model, color in (("rigid", "C0"), ("nonrigid", "C3")):
        r = frequency_response(loops[model]["loop"], w)
        mag = 20 * np.log10(np.abs(r))
        ph = np.degrees(np.unwrap(np.angle(r)))
        ph -= 360.0 * np.round((ph[np.argmin(np.abs(mag))] + 180.0) / 360.0)     # -180 near the crossover
        m = loops[model]["margins"]
        label = (f"{model}: GM {m['gain_margin_db']:.1f} dB, PM {m['phase_margin_deg']:.1f} deg at "
                 f"{m['gain_crossover_radps']:.1f} rad/s, {'stable' if m['closed_loop_stable'] else 'UNSTABLE'}")
        a_mag.semilogx(w, mag, color=color, label=label)
        a_ph.semilogx(w, ph, color=color, ls=":", lw=0.8)
        a_nic.plot(ph, mag, color=color, label=model)
        if np.isfinite(m["gain_crossover_radps"]):
            a_mag.axvline(m["gain_crossover_radps"], color=color, lw=0.5, ls="--")
    for kind, style in (("slosh", "g"), ("bending", "m")):
        for f in loops["modes_radps"][kind]:
            if f < math.pi / dt:
                a_mag.axvline(f, color=style, lw=0.4, alpha=0.6)
    a_mag.axhline(0.0, color="k", lw=0.5)
    a_mag.set_xlabel("frequency [rad/s] (green: slosh, magenta: bending)")
    a_mag.set_ylabel("|L| [dB] (solid)")
    a_ph.set_ylabel("phase [deg] (dotted)")
    a_mag.legend(fontsize=7, loc="lower left")
    a_mag.set_title(f"open loop at {t:g} s")
    for c in range(-3, 2):
        a_nic.axvline(-180.0 + 360.0 * c, color="0.7", lw=0.5)
    a_nic.plot([-180.0], [0.0], "k+", ms=12)
    a_nic.axhline(0.0, color="k", lw=0.5)
    a_nic.set_xlabel("phase [deg]")
    a_nic.set_ylabel("|L| [dB]")
    a_nic.set_ylim(-60, 40)
    a_nic.set_title("Nichols chart (+: the critical point)")
    a_nic.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def charts(vehicle: Any, protocol: str, schedule: str, out: Path, log=print, fly: str = "auto",
           **options: Any) -> dict[str, Any]:
    """Write the charts of every row of ``schedule`` into ``out``; returns the margins per row.
    ``vehicle``: a shipped name or a vehicle file (:func:`.target.design_env`; ``options``: env keywords).
    ``fly``: how the rows' operating points are reached: ``centred``, ``schedule`` (the charted schedule
    itself flies the vehicle), another schedule file; ``auto``: ``centred`` for a shipped vehicle,
    ``schedule`` for a file. ``margins.json`` says how (``operating_points``) when not centred."""
    from .target import check_fly, check_vehicle, describe, is_shipped, schedule_flyer

    vehicle = check_vehicle(vehicle, protocol)
    sched = GainSchedule.load(schedule)
    if fly == "auto":
        fly = "centred" if is_shipped(vehicle, protocol) else "schedule"
    policy = None
    if fly == "schedule":
        policy, how = schedule_flyer(sched), f"the charted schedule {schedule}"
    else:
        fly = check_fly(fly)
        if fly not in ("centred", "rows", "pid"):
            policy = schedule_flyer(fly)
        elif fly != "centred":
            raise ValueError(f"fly = {fly!r}: 'auto', 'centred', 'schedule' or a schedule file")
        how = describe(fly)
    log(f"operating points: {how}")
    out.mkdir(parents=True, exist_ok=True)
    doc: dict[str, Any] = {"vehicle": vehicle, "protocol": protocol, "schedule": str(schedule), "rows": []}
    if policy is not None or options:
        doc["operating_points"] = {"flown_with": how, **({"env_options": dict(options)} if options else {})}
    for row, value in zip(sched.meta["rows"], sched.points):
        t = float(row["time_s"])
        filt, k_theta = sched.filter_at(value), sched.attitude_gain_at(value)
        loops = row_loops(vehicle, protocol, t, sched.gains(value), policy, filt, k_theta, **options)
        if loops is None:
            log(f"t = {t:g} s: no thrust (coast), skipped")
            continue
        _chart(t, loops, out / f"loop_{t:g}s.png")
        entry = {"time_s": t, "filtered": filt is not None, "filters": filter_count(filt), "attitude_gain": k_theta,
                 **{m: {k: (round(v, 3) if isinstance(v, float) else v)
                                     for k, v in loops[m]["margins"].items()} for m in ("rigid", "nonrigid")},
                 "modes_radps": {k: [round(f, 2) for f in v] for k, v in loops["modes_radps"].items()}}
        doc["rows"].append(entry)
        r, n = entry["rigid"], entry["nonrigid"]
        log(f"t = {t:5.1f} s  rigid GM {r['gain_margin_db']:6.2f} dB PM {r['phase_margin_deg']:6.1f} deg "
            f"{'stable' if r['closed_loop_stable'] else 'UNSTABLE'}   nonrigid GM {n['gain_margin_db']:6.2f} dB "
            f"PM {n['phase_margin_deg']:6.1f} deg {'stable' if n['closed_loop_stable'] else 'UNSTABLE'}")
    (out / "margins.json").write_text(json.dumps(doc, indent=1))
    return doc


def _protocols() -> tuple[str, ...]:
    from .target import ENV_IDS

    return tuple(sorted(ENV_IDS))


def _fly(option: str, value: str) -> str:
    """``--fly``: auto, centred, schedule or a readable gain schedule."""
    return value if value in ("auto", "centred", "schedule") else _readable(option, value)


def _readable(option: str, schedule: str) -> str:
    """``--schedule``: a gain schedule that loads."""
    from lvgym.errors import ConfigError

    try:
        GainSchedule.load(schedule)
    except (OSError, KeyError, ValueError) as exc:
        raise ConfigError(option, schedule, f"a readable gain schedule ({exc})") from None
    return schedule


@dataclass
class Args:
    """Command-line arguments (``lvgym design charts --help``)."""

    vehicle: str = arg("smile", check=vehicle_option, metavar="NAME|PATH")
    """the vehicle linearised: a shipped vehicle (smile, stratos3, slender) or the path of a vehicle YAML
    file, flown in SMILE's env of the protocol (docs/vehicles.md)"""
    protocol: str = arg("v1", choices=_protocols)
    """the protocol whose env is linearised"""
    schedule: str = arg("smile", check=_readable)
    """a schedule name in baselines/schedules or a YAML path"""
    out: str = "results/charts"
    """folder of the figures and margins.json (a subfolder per vehicle, protocol and schedule)"""
    fly: str = arg("auto", check=_fly, metavar="MODE|SCHEDULE")
    """how the rows' operating points are reached: centred (gimbal at zero), schedule (the charted schedule
    flies the vehicle), another schedule file, or auto (centred for a shipped vehicle, schedule for a file)"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design charts`` (``python -m lvgym.baselines.design.charts``): write the charts."""
    from lvgym.commandline import parse

    a = parse(Args, argv, "python -m lvgym.baselines.design.charts", __doc__)
    from .target import stem

    out = Path(a.out) / f"{stem(a.vehicle)}_{a.protocol}_{Path(a.schedule).stem}"
    charts(a.vehicle, a.protocol, a.schedule, out, fly=a.fly)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
