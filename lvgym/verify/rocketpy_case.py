"""Validation of the rigid simulator against RocketPy: the shipped ``stratos3`` flown by both, no wind.

``lvgym verify rocketpy`` (``python -m lvgym.verify.rocketpy_case``) flies the vehicle with lvgym's
:class:`~lvgym.simulator.Simulator` (``model="rigid"``, flat non-rotating site, constant gravity, US76, zero
gimbal) and with RocketPy 1.13 (a dev dependency; both flights, and what RocketPy is given:
:mod:`.rocketpy_flights`), prints Markdown tables of apogee,
maximum Mach number, their times and the burnout time of both with the relative differences, and writes
``docs/figures/rocketpy_stratos3.png`` (altitude and Mach against time), and ends with both codes' wall
times for the same flight, with and without set-up, lvgym cold and warm (:mod:`.rocketpy_timing`).
docs/rocketpy-validation.md discusses the numbers.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.commandline import arg, parse
from lvgym.errors import require

from .rocketpy_flights import ELEVATION_DEG, RAIL_LENGTH, VEHICLE, Trajectory, fly_lvgym, fly_rocketpy
from .rocketpy_timing import timing_table

CASES = ((85.0, 10.0), (90.0, 10.0))  #: (elevation [deg], rail [m]) of the report: main and vertical
FIGURE = Path(__file__).resolve().parents[2] / "docs" / "figures" / "rocketpy_stratos3.png"
#: RocketPy variants of the sensitivity table: label -> options of :func:`~.rocketpy_flights.rocketpy_flight`
SENSITIVITIES: dict[str, dict[str, Any]] = {
    "GenericMotor cylinder (propellant CG fixed)": {"motor": "generic"},
    "Earth rotation on (Coriolis, latitude 0, heading east)": {"earth_rotation": True},
    "RocketPy's built-in ISA (negative above 81 km)": {"atmosphere": "isa"},
    "r_CM / r_NOZ sign reversed (RocketPy issue #1186)": {"patch_issue_1186": True},
    "the same and no jet damping (as lvgym)": {"patch_issue_1186": True, "jet_damping": False},
}



@dataclass(frozen=True)
class Comparison:
    """Both flights of one launch (``elevation_deg`` [deg], ``rail_length`` [m])."""

    elevation_deg: float
    rail_length: float
    lvgym: Trajectory
    rocketpy: Trajectory

    def relative(self, name: str) -> float:
        """``(lvgym - RocketPy) / RocketPy`` of the scalar ``name`` (e.g. ``"apogee"``) [-]."""
        ref = getattr(self.rocketpy, name)
        return (getattr(self.lvgym, name) - ref) / ref

    def table(self) -> str:
        """Markdown table of both flights and the relative differences."""
        rows = [("apogee", "apogee [m]", "{:.1f}"), ("max_mach", "maximum Mach [-]", "{:.4f}"),
                ("t_apogee", "time of apogee [s]", "{:.2f}"),
                ("t_max_mach", "time of maximum Mach [s]", "{:.2f}"),
                ("t_burnout", "burnout [s] (RocketPy: given)", "{:.3f}"),
                ("setup_time", "wall time, set-up [s]", "{:.3f}"), ("flight_time", "wall time, flight [s]", "{:.3f}"),
                ("wall_time", "wall time, in all [s]", "{:.3f}")]
        out = ["| quantity | lvgym (rigid) | RocketPy | (lvgym - RocketPy) / RocketPy |", "|---|---:|---:|---:|"]
        for key, label, fmt in rows:
            if key.endswith("_time") and key != "t_burnout":
                ratio = getattr(self.rocketpy, key) / getattr(self.lvgym, key)
                rel = f"lvgym {ratio:.1f} times faster"
            else:
                rel = f"{100 * self.relative(key):+.3f} %"
            out.append(f"| {label} | {fmt.format(getattr(self.lvgym, key))} | "
                       f"{fmt.format(getattr(self.rocketpy, key))} | {rel} |")
        return "\n".join(out)



# ------------------------------------------------------------------------------------------ report
def compare(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH, **options: Any) -> Comparison:
    """Fly both simulators from the same rail (``options`` go to :func:`~.rocketpy_flights.rocketpy_flight`)."""
    return Comparison(elevation_deg, rail_length, fly_lvgym(elevation_deg, rail_length),
                      fly_rocketpy(elevation_deg, rail_length, **options))


def sensitivity_table(base: Comparison) -> str:
    """Markdown table of RocketPy's apogee and maximum Mach for each of :data:`SENSITIVITIES` (same
    launch as ``base``), relative to lvgym's."""
    out = ["| RocketPy variant | apogee [m] | lvgym vs it | maximum Mach | lvgym vs it |", "|---|---:|---:|---:|---:|"]
    runs = [("as in the comparison", base.rocketpy)]
    runs += [(label, fly_rocketpy(base.elevation_deg, base.rail_length, **opts))
             for label, opts in SENSITIVITIES.items()]
    for label, rp in runs:
        d_apo = (base.lvgym.apogee - rp.apogee) / rp.apogee
        d_mach = (base.lvgym.max_mach - rp.max_mach) / rp.max_mach
        out.append(f"| {label} | {rp.apogee:.1f} | {100 * d_apo:+.3f} % | {rp.max_mach:.4f} | {100 * d_mach:+.3f} % |")
    return "\n".join(out)


def plot(comparisons: list[Comparison], path: Path = FIGURE) -> Path:
    """Altitude and Mach against time of both simulators (first comparison), and lvgym minus RocketPy
    (RocketPy interpolated to lvgym's times) for all of them; PNG at ``path`` (Agg canvas)."""
    require("matplotlib", "dev", "the RocketPy comparison's plot")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 7.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots(2, 2, sharex=True)
    main = comparisons[0]
    for traj, style in ((main.rocketpy, dict(color="tab:orange", lw=3.5, alpha=0.6)),
                        (main.lvgym, dict(color="tab:blue", lw=1.2))):
        ax[0, 0].plot(traj.t, traj.altitude / 1e3, label=traj.name, **style)
        ax[0, 1].plot(traj.t, traj.mach, label=traj.name, **style)
    for c in comparisons:
        end = min(c.lvgym.t[-1], c.rocketpy.t[-1])
        k = c.lvgym.t <= end
        lab = f"{c.elevation_deg:g} deg, {c.rail_length:g} m rail"
        ax[1, 0].plot(c.lvgym.t[k], c.lvgym.altitude[k] - np.interp(c.lvgym.t[k], c.rocketpy.t, c.rocketpy.altitude),
                      label=lab)
        ax[1, 1].plot(c.lvgym.t[k], c.lvgym.mach[k] - np.interp(c.lvgym.t[k], c.rocketpy.t, c.rocketpy.mach),
                      label=lab)
    for a in ax[:, :].ravel():
        a.axvline(main.lvgym.t_burnout, color="0.6", lw=0.8, ls=":")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    ax[0, 0].set(ylabel="altitude [km]",
                 title=f"stratos3, {main.elevation_deg:g} deg, {main.rail_length:g} m rail, no wind")
    ax[0, 1].set(ylabel="Mach [-]", title="dotted: burnout")
    ax[1, 0].set(xlabel="time [s]", ylabel="altitude: lvgym - RocketPy [m]")
    ax[1, 1].set(xlabel="time [s]", ylabel="Mach: lvgym - RocketPy [-]")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


@dataclass
class Args:
    """Command-line arguments (``lvgym verify rocketpy --help``)."""

    figure: Path = FIGURE
    """PNG path of the figure"""
    tol: float = arg(0.02, lo=0.0, hi=1.0)
    """relative tolerance on apogee and maximum Mach"""
    sensitivity: bool = True
    """fly the RocketPy variants"""
    timing: bool = True
    """time both codes, cold and warm (rocketpy_timing)"""


def main(argv: list[str] | None = None) -> int:
    """Print the tables, write the figure; exit 1 when a case differs by more than ``--tol``."""
    args = parse(Args, argv, "python -m lvgym.verify.rocketpy_case", __doc__)
    start = time.perf_counter()
    comparisons = [compare(e, r) for e, r in CASES]
    ok = True
    for c in comparisons:
        print(f"\n### {VEHICLE}, elevation {c.elevation_deg:g} deg, rail {c.rail_length:g} m\n")
        print(c.table())
        ok &= all(abs(c.relative(k)) <= args.tol for k in ("apogee", "max_mach"))
    if args.sensitivity:
        print(f"\n### RocketPy variants, elevation {comparisons[0].elevation_deg:g} deg\n")
        print(sensitivity_table(comparisons[0]))
    if args.timing:
        print(f"\n### Wall times, {VEHICLE}, elevation {comparisons[0].elevation_deg:g} deg\n")
        print(timing_table(comparisons[0].elevation_deg, comparisons[0].rail_length))
    print(f"\nfigure: {plot(comparisons, args.figure)}")
    print(f"apogee and maximum Mach within {100 * args.tol:g} %: {'yes' if ok else 'NO'}; "
          f"{time.perf_counter() - start:.1f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
