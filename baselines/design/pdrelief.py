"""A soft attitude loop without integral for the max-q gust: the ``gs-pd-relief`` schedule.

``lvgym design pd-relief --vehicle smile`` (``python -m lvgym.baselines.design.pdrelief``) writes
``results/schedules/smile_pd_relief.yaml`` (or ``--out``; the shipped ``baselines/schedules/`` one only with
``--overwrite``), the gain schedule of the PID family (:mod:`..gainschedule`) that ``gs-pd-relief`` flies.

The law is the rigid body's attitude loop placed by hand, per plane: a proportional rate loop with an
attitude channel and no integral,

    delta = -kp (e_rate + k_theta e_att),    kp = 2 zeta w / P(t),    k_theta = w / (2 zeta),

so that on the rigid body with control power ``P = s T l / J`` [1/s^2] (``s T`` the vectored thrust, ``l``
the gimbal-to-CG arm, ``J`` the pitch inertia: :func:`.linearize.rigid_terms` at the operating point) the
closed loop is ``s^2 + 2 zeta w s + w^2`` (the aerodynamic moment left out). The schedule carries ``kp`` per
row over flight time (``interpolation: nearest``, rows every ``--row-step`` seconds of each burning phase).

Why no integral: on protocol v2's max-q gust (a jet stream and a 1-cosine gust through max q) every design that
holds the attitude against the wind (an integral, or a stiff loop) carries the wind's whole angle of attack
at max q and breaks the 250 kPa deg limit on a share of the flights; the soft loop leaves a standing
attitude error in a steady wind, so the statically stable vehicle turns partly into it (load relief by
design, as the slender vehicle's ``gs-pid-flex`` gives up 95 % of its integral). What that costs: a
thrust-direction fault or a misalignment is trimmed only by the standing error, so on the fault suite it is
no design (docs/baselines.md, "gs-pd-relief"). ``w`` and ``zeta`` (2 rad/s and 1) were chosen on validation
seeds 0-99 of ``smile-v2-maxq-gust`` (docs/training-results.md, issue 35's section).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.commandline import arg
from lvgym.errors import ConfigError

from ..pid import SCHEDULES
from .linearize import operating_point, reused_flights, rigid_terms
from .target import burn_phases, describe, fly_option, flyer, is_shipped, stem, vehicle_option

__all__ = ["DEFAULT_BANDWIDTH", "DEFAULT_DAMPING", "pd_rows", "row_times", "schedule"]

#: the attitude loop's natural frequency [rad/s] and damping [-] (module docstring)
DEFAULT_BANDWIDTH = 2.0
DEFAULT_DAMPING = 1.0


def row_times(phases: tuple[tuple[float, float], ...], step: float) -> tuple[float, ...]:
    """The rows' flight times [s]: the centres of ``step``-second parts of each burning phase ``(start, end)``
    (one row for a phase shorter than ``step``), to 0.01 s."""
    if not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0.0):
        raise ConfigError("row_step", step, "a positive number of seconds")
    out: list[float] = []
    for a, b in phases:
        n = max(1, round((b - a) / step))
        out += [round(a + (k + 0.5) * (b - a) / n, 2) for k in range(n)]
    return tuple(out)


def pd_rows(times: tuple[float, ...], control_power: np.ndarray, bandwidth: float = DEFAULT_BANDWIDTH,
            damping: float = DEFAULT_DAMPING) -> list[dict[str, float]]:
    """The schedule's rows at ``times`` [s] from the control power [1/s^2] there (module docstring's law)."""
    for key, value in (("bandwidth", bandwidth), ("damping", damping)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
            raise ConfigError(key, value, "a positive number")
    power = np.asarray(control_power, dtype=float)
    if power.shape != (len(times),) or not np.all(np.isfinite(power) & (power > 0.0)):
        raise ConfigError("control_power", power.tolist(), "one positive number per row time")
    k_theta = bandwidth / (2.0 * damping)
    return [{"time_s": float(t), "kp": round(float(2.0 * damping * bandwidth / p), 6), "ki": 0.0, "kd": 0.0,
             "attitude_gain": round(float(k_theta), 6), "control_power_per_s2": round(float(p), 4)}
            for t, p in zip(times, power)]


def schedule(vehicle: Any = "smile", times: tuple[float, ...] | None = None, bandwidth: float = DEFAULT_BANDWIDTH,
             damping: float = DEFAULT_DAMPING, row_step: float = 1.0, fly: str = "privileged") -> dict[str, Any]:
    """The ``gs-pd-relief`` schedule document of ``vehicle`` (a shipped name or a vehicle file): rows at
    ``times`` (default :func:`row_times` of its burning phases), their operating points flown in its v1 env
    with ``fly`` (``privileged``, the default, needs no design; ``centred``; or a schedule), no wind."""
    times = row_times(burn_phases(vehicle, "v1"), row_step) if times is None else tuple(float(t) for t in times)
    policy = flyer(fly)
    power = []
    with reused_flights():
        for t in times:
            op = operating_point(vehicle, t, "rigid", "v1", policy=policy)
            terms = rigid_terms(op)
            power.append(terms["vectored_thrust"] * terms["arm"] / terms["inertia"])
    return {"variable": "time", "interpolation": "nearest",
            "design": {"law": "delta = -kp (e_rate + attitude_gain e_att), no integral", "bandwidth_radps": bandwidth,
                       "damping": damping, "operating_points": {"protocol": "v1", "flown_with": describe(fly)}},
            "rows": pd_rows(times, np.array(power), bandwidth, damping)}


@dataclass
class Args:
    """Command-line arguments (``lvgym design pd-relief --help``)."""

    vehicle: str = arg("smile", check=vehicle_option, metavar="NAME|PATH")
    """the vehicle: a shipped vehicle (smile, stratos3, slender) or the path of a vehicle YAML file"""
    bandwidth: float = arg(DEFAULT_BANDWIDTH, lo=0.0, lo_open=True, hi=100.0)
    """the attitude loop's natural frequency w [rad/s]"""
    damping: float = arg(DEFAULT_DAMPING, lo=0.0, lo_open=True, hi=10.0)
    """its damping ratio"""
    row_step: float = arg(1.0, lo=0.0, lo_open=True, hi=100.0)
    """seconds of burning flight per row (the rows' times: the centres of such parts of each burning phase)"""
    times: list[float] | None = arg(None, nargs="*", lo=0.0, hi=3600.0)
    """the rows' flight times [s] instead"""
    fly: str = arg("privileged", check=fly_option, metavar="MODE|SCHEDULE")
    """how each row's operating point is reached: privileged (the privileged reference, which needs no
    design), centred, or a schedule file"""
    out: str | None = None
    """YAML file (default results/schedules/<vehicle>_pd_relief.yaml; with --overwrite the shipped
    baselines/schedules/<vehicle>_pd_relief.yaml)"""
    overwrite: bool = False
    """allow replacing a shipped schedule (gs-pd-relief reads it)"""


def main(argv: list[str] | None = None) -> int:
    """``lvgym design pd-relief``: design and write the schedule."""
    from lvgym.commandline import command_name, fail, parse

    from .tune import output_path, write_schedule

    prog = "python -m lvgym.baselines.design.pdrelief"
    a = parse(Args, argv, prog, __doc__)
    name = f"{stem(a.vehicle)}_pd_relief"
    try:
        out = output_path(stem(a.vehicle), a.out, a.overwrite, stem=name)
        if a.fly in ("rows", "pid"):
            raise ConfigError("--fly", a.fly, "privileged, centred or a schedule (the law has no rows to fly first)")
        doc = schedule(a.vehicle, tuple(a.times) if a.times else None, a.bandwidth, a.damping, a.row_step, a.fly)
    except ConfigError as exc:
        fail(command_name(prog), exc)
    again = (f"lvgym design pd-relief --vehicle {a.vehicle} --bandwidth {a.bandwidth:g} --damping {a.damping:g}"
             + ("" if a.times else f" --row-step {a.row_step:g}")
             + ("" if not a.times else " --times " + " ".join(f"{t:g}" for t in a.times))
             + ("" if a.fly == "privileged" else f" --fly {a.fly}"))
    write_schedule(out, f"gs-pd-relief schedule of {a.vehicle}", again,
                   "kp [rad of gimbal per rad/s], attitude_gain [rad/s per rad]; control power [1/s^2]", doc)
    shipped = out.parent.resolve() == SCHEDULES.resolve() or not is_shipped(a.vehicle)
    print(f"wrote {out}" + ("" if shipped else f" (gs-pd-relief reads {SCHEDULES / (name + '.yaml')}; replace it "
                                                "with --overwrite)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
