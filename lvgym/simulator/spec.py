"""What a :class:`~.core.Simulator` flies, besides its vehicle and model: four frozen, validated specs.

=====================  ===========================================================================================
spec                   what it says
=====================  ===========================================================================================
:class:`LaunchSpec`    where the vehicle starts: the launch site and the rail (elevation, length)
:class:`EnvironmentSpec`  what it flies through: gravity, atmosphere, wind and aerodynamic models; the aeroelastic
                       strip loads
:class:`TimelineSpec`  what the timeline tabulates: mission time, table step, bending modes, sensor stations, the
                       CG convention, when the modes are recomputed and how the state crosses a change
:class:`PhysicsSpec`   how a step is flown: the largest RK4 step, the slosh dampers' frequency, the threads
=====================  ===========================================================================================

>>> from lvgym.simulator import Simulator, TimelineSpec
>>> sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=5.0))

Each spec checks its values when it is made: a bad one raises a :class:`~lvgym.errors.ConfigError`
naming the key, the value and what is allowed. The models (gravity, atmosphere, wind, aerodynamics) are
given as :func:`lvgym.environment.make` names or mappings, or as model objects; the simulator makes them.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any

from lvgym.environment import LaunchSite
from lvgym.errors import ConfigError, check_choice, check_number

from .piece import SLOSH_FREQUENCIES
from .timeline import MODE_BASES

__all__ = ["EnvironmentSpec", "LaunchSpec", "PhysicsSpec", "SITES", "TimelineSpec"]

#: launch sites of the shipped vehicles (the ranges' published coordinates); azimuth clockwise from north
SITES = {
    "andoya": LaunchSite(latitude_deg=69.2943, longitude_deg=16.0205, altitude_m=10.0, azimuth_deg=0.0),
    "el_arenosillo": LaunchSite(latitude_deg=37.0970, longitude_deg=-6.7350, altitude_m=20.0, azimuth_deg=225.0),
    "flat": LaunchSite(latitude_deg=0.0, longitude_deg=0.0, altitude_m=0.0, azimuth_deg=90.0, flat_earth=True),
}


def _whole(key: str, value: Any, lo: int) -> int:
    """``value`` as an int when it is a whole number (not a bool) >= ``lo``; else a :class:`ConfigError`."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < lo:
        raise ConfigError(key, value, f"an integer >= {lo}")
    return int(value)


@dataclass(frozen=True)
class LaunchSpec:
    """Where the vehicle starts. ``site``: a :class:`LaunchSite` or a key of :data:`SITES`;
    ``elevation_deg``: the rail's elevation above the horizon [deg] (90: vertical) towards
    ``site.azimuth_deg``; ``rail_length`` [m] (0: lift-off straight from the pad)."""

    site: Any = "andoya"
    elevation_deg: float = 90.0
    rail_length: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.site, LaunchSite) and (not isinstance(self.site, str) or self.site not in SITES):
            raise ConfigError("site", self.site, f"one of {sorted(SITES)} or a LaunchSite")
        object.__setattr__(self, "elevation_deg", check_number("elevation_deg", self.elevation_deg, 0.0, 90.0,
                                                               lo_open=True))
        object.__setattr__(self, "rail_length", check_number("rail_length", self.rail_length, 0.0, math.inf))

    def launch_site(self) -> LaunchSite:
        """The :class:`LaunchSite` (``site`` looked up in :data:`SITES` when it is a key)."""
        return SITES[self.site] if isinstance(self.site, str) else self.site


@dataclass(frozen=True)
class EnvironmentSpec:
    """What the vehicle flies through. ``gravity``, ``atmosphere``, ``wind``: names or mappings for
    :func:`lvgym.environment.make`, or models (the wind may also be given per row at
    :meth:`~.core.Simulator.reset`); ``aerodynamics``: ``"vehicle"`` (the vehicle file's ``aerodynamics``
    section), a name, mapping or model, or None (no aerodynamic loads); ``aeroelastic``: the strip-theory
    aeroelastic loads (:mod:`.strips`): True, False or None (the vehicle file's ``structure.aeroelastic``).
    They act only on a model with bending modes and aerodynamics; the v0 envs pass False."""

    gravity: Any = "egm2008"
    atmosphere: Any = "us76"
    wind: Any = "none"
    aerodynamics: Any = "vehicle"
    aeroelastic: bool | None = None

    def __post_init__(self) -> None:
        if self.aeroelastic not in (None, True, False):
            raise ConfigError("aeroelastic", self.aeroelastic, "True, False or None (the vehicle file's)")


@dataclass(frozen=True)
class TimelineSpec:
    """What the timeline (:func:`.tabulate.build_timeline`) tabulates. ``t_end``: mission time [s];
    ``timeline_dt``: the table step [s]; ``n_modes``: bending modes per plane (None: the vehicle file's;
    modes above the Nyquist frequency of the RK4 step are decoupled); ``sensor_stations`` [m]: where the mode
    slopes are tabulated (an IMU); ``cg_convention``: ``static`` or ``thesis``; ``mode_interval`` [s]:
    recompute the modes also every so many seconds (None: the vehicle file's setting); ``mode_basis``:
    ``held`` (v0: the modal coordinates kept as numbers across a change of the modes) or ``projected`` (the
    deflection field kept, see :mod:`.timeline`)."""

    t_end: float = 60.0
    timeline_dt: float = 0.05
    n_modes: int | None = None
    sensor_stations: tuple[float, ...] = ()
    cg_convention: str = "static"
    mode_interval: float | None = None
    mode_basis: str = "held"

    def __post_init__(self) -> None:
        object.__setattr__(self, "t_end", check_number("t_end", self.t_end, 0.0, math.inf, lo_open=True))
        object.__setattr__(self, "timeline_dt", check_number("timeline_dt", self.timeline_dt, 0.0, math.inf,
                                                             lo_open=True))
        if self.n_modes is not None:
            object.__setattr__(self, "n_modes", _whole("n_modes", self.n_modes, 0))
        try:
            stations = tuple(float(s) for s in self.sensor_stations)
        except (TypeError, ValueError):
            raise ConfigError("sensor_stations", self.sensor_stations, "a sequence of stations [m]") from None
        if not all(math.isfinite(s) for s in stations):
            raise ConfigError("sensor_stations", self.sensor_stations, "finite stations [m]")
        object.__setattr__(self, "sensor_stations", stations)
        check_choice("cg_convention", self.cg_convention, ("static", "thesis"))
        if self.mode_interval is not None:
            object.__setattr__(self, "mode_interval", check_number("mode_interval", self.mode_interval, 0.0, 1e5,
                                                                   lo_open=True))
        check_choice("mode_basis", self.mode_basis, MODE_BASES)


@dataclass(frozen=True)
class PhysicsSpec:
    """How a step is flown. ``physics_dt``: the largest RK4 step [s]; ``slosh_frequency``: the pendulums'
    damper frequency, ``vacuum_thrust`` (v0: ``sqrt(T_0 / m / L)`` from the timeline's vacuum thrust) or
    ``specific_force`` (``sqrt(|a_x| / L)`` from the axial specific force of the row's latest flight
    conditions; see :mod:`.piece`); ``threads``: the threads a large batch is split over (None: the
    default, :func:`.threads.default_threads`)."""

    physics_dt: float = 0.01
    slosh_frequency: str = "vacuum_thrust"
    threads: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "physics_dt", check_number("physics_dt", self.physics_dt, 0.0, 0.1, lo_open=True))
        check_choice("slosh_frequency", self.slosh_frequency, SLOSH_FREQUENCIES)
        if self.threads is not None:
            object.__setattr__(self, "threads", _whole("threads", self.threads, 1))
