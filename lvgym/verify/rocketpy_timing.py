"""Wall times of lvgym and RocketPy flying the same Stratos III flight to apogee, with and without set-up.

``lvgym verify rocketpy`` prints this table after its comparisons (``--no-timing`` skips it);
``lvgym verify rocketpy-timing`` (``python -m lvgym.verify.rocketpy_timing``) prints it alone. Both simulators fly the main case of
:mod:`.rocketpy_case` (85 deg, 10 m rail; the flights of :mod:`.rocketpy_flights`) twice in one process, after the
imports and after Numba has loaded its compiled kernels (a warm-up flight of each, or the comparisons, ran first):

* lvgym **cold**: an empty timeline cache (a fresh ``$LVGYM_CACHE_DIR``) and the process's vehicles
  forgotten (:func:`lvgym.vehicle.clear_vehicle_cache`), so its set-up parses the vehicle file, builds its
  aerodynamic tables and builds the mass and mode tables, as for a new or dispersed vehicle; **warm**: the
  same folder again, the tables read from the cache (:mod:`lvgym.simulator.cache`), and the vehicle file,
  unchanged, not parsed again (:func:`lvgym.vehicle.load_vehicle` keeps the vehicle, and with it its
  aerodynamic tables, by the file's content). Set-up: the :class:`~lvgym.simulator.Simulator` and its reset.
* RocketPy has no such cache: its two runs are its first and second flight of the launch. Set-up: the
  environment (lvgym's US76 as a table), the motor and the rocket, from lvgym's vehicle, mass split and
  aerodynamics (the lvgym simulator it reads them from is built beforehand, outside the timing); flight: its
  ``Flight`` (LSODA to apogee).

lvgym's flight: 3,300 calls of 50 ms from Python, each reading the conditions back (how
:func:`~.rocketpy_flights.fly_lvgym` records the histories it compares), and in a third row the same flight
as one ``Simulator.step`` call from lift-off to the time the recorded flight stopped (RocketPy's numbers
of that row are those of its second flight).
"""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass, replace

from lvgym.commandline import arg, parse
from lvgym.simulator.cache import using
from lvgym.vehicle import clear_vehicle_cache

from .rocketpy_flights import ELEVATION_DEG, RAIL_LENGTH, VEHICLE, Trajectory, fly_lvgym, fly_rocketpy, lvgym_simulator


def timings(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH, warm_up: bool = True
            ) -> list[tuple[str, Trajectory, Trajectory]]:
    """``(run, lvgym, RocketPy)`` of the cold and the warm run (see the module docstring); ``warm_up``: fly
    each simulator once first (imports, Numba's kernels), untimed."""
    with tempfile.TemporaryDirectory(prefix="lvgym-timing-") as root:
        if warm_up:
            with using(os.path.join(root, "warm-up")):
                fly_lvgym(elevation_deg, rail_length)
        with using(os.path.join(root, "timed")):
            clear_vehicle_cache()                                       # cold: the vehicle file read again too
            lv_cold = fly_lvgym(elevation_deg, rail_length)
            lv_warm = fly_lvgym(elevation_deg, rail_length)
            start = time.perf_counter()
            sim = lvgym_simulator(elevation_deg, rail_length)
            data = sim.reset()
            set_up = time.perf_counter()
            sim.step(data, [[0.0, 0.0]], float(lv_warm.t[-1]))          # to where the flight above stopped
            lv_one = replace(lv_warm, setup_time=set_up - start, wall_time=time.perf_counter() - start)
        if warm_up:
            fly_rocketpy(elevation_deg, rail_length, sim=sim)
        rp_first = fly_rocketpy(elevation_deg, rail_length, sim=sim)
        rp_second = fly_rocketpy(elevation_deg, rail_length, sim=sim)
    return [("cold (lvgym builds its tables; RocketPy's first flight)", lv_cold, rp_first),
            ("warm (lvgym's tables from the cache; RocketPy's second flight)", lv_warm, rp_second),
            ("warm, lvgym's flight in one `step` call (no history read back)", lv_one, rp_second)]


def timing_table(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH, warm_up: bool = False) -> str:
    """Markdown table of :func:`timings` [s] with how many times faster lvgym is, in all and flight alone."""
    out = ["| run | lvgym set-up | lvgym flight | lvgym in all | RocketPy set-up | RocketPy flight | RocketPy in all "
           "| lvgym faster, in all | lvgym faster, flight alone |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for run, lv, rp in timings(elevation_deg, rail_length, warm_up):
        out.append(f"| {run} | {lv.setup_time:.3f} | {lv.flight_time:.3f} | {lv.wall_time:.3f} | {rp.setup_time:.3f} | "
                   f"{rp.flight_time:.3f} | {rp.wall_time:.3f} | {rp.wall_time / lv.wall_time:.1f} | "
                   f"{rp.flight_time / lv.flight_time:.1f} |")
    return "\n".join(out)


@dataclass
class Args:
    """Command-line arguments (``lvgym verify rocketpy-timing --help``)."""

    elevation: float = arg(ELEVATION_DEG, lo=0.0, lo_open=True, hi=90.0)
    """rail elevation [deg]"""
    rail: float = arg(RAIL_LENGTH, lo=0.0, lo_open=True, hi=1000.0)
    """rail length [m] (RocketPy needs a rail > 0)"""


def main(argv: list[str] | None = None) -> int:
    """Print the table of wall times."""
    args = parse(Args, argv, "python -m lvgym.verify.rocketpy_timing", __doc__)
    print(f"### Wall times [s], {VEHICLE}, elevation {args.elevation:g} deg, rail {args.rail:g} m\n")
    print(timing_table(args.elevation, args.rail, warm_up=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
