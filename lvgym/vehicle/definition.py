"""A vehicle definition as frozen dataclasses: the stages in firing order with their structure, engines,
tanks, hybrid grain and stiffness sections, the payload and fairing, the staging sequence and the options
of the structural model, each read from its mapping of the vehicle file by a :class:`~.reader.Reader` that
checks every single value against the physical ranges below. How the parts fit together is checked in
:mod:`.checks`; :mod:`.config` finds, reads and checks a whole file (``docs/vehicles.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .limits import QAlphaLimit
from .reader import Reader
from .timetables import VehicleTables

__all__ = ["G0", "TANK_ROLES", "Engine", "Grain", "RigidPart", "Section", "Stage", "StagingStep", "StructureOptions",
           "Tank", "Vehicle"]

#: standard gravity used by the thrust equation [m/s^2]
G0 = 9.80665
TANK_ROLES = ("oxidiser", "fuel", "propellant")
# Physical ranges of single values (docs/vehicles.md); how parts fit together is checked in checks.py.
MAX_LENGTH = 1000.0        # [m] stations, lengths and heights
MAX_DIAMETER = 50.0        # [m] stage and section diameters (tank and grain radii: half of it)
MAX_MASS = 1e7             # [kg] one rigid part
MAX_DENSITY = 25_000.0     # [kg/m^3] liquids and grains (osmium is 22,590)
MAX_MASS_FLOW = 1e5        # [kg/s] one engine (an F-1 burnt 2,600)
MAX_ISP = 10_000.0         # [s]
MAX_THRUST = 1e9           # [N] one engine (an F-1 gave 7.8e6)
MAX_TIME = 1e5             # [s] burn times, delays, jettison


@dataclass(frozen=True)
class RigidPart:
    """A body of constant mass: structure, engine, payload, fairing.

    ``mass`` [kg]; ``cg`` station of its CG [m] (3,); ``inertia`` about its own CG, body axes
    [kg m^2] (3, 3)."""

    name: str
    mass: float
    cg: np.ndarray
    inertia: np.ndarray

    @staticmethod
    def read(r: Reader, name: str) -> RigidPart:
        return RigidPart(name=name, mass=r.number("mass", lo=0.0, hi=MAX_MASS), cg=r.station("cg"),
                         inertia=r.inertia("inertia", [0.0, 0.0, 0.0]))


@dataclass(frozen=True)
class Section:
    """Bending stiffness of the structure between two stations: either ``EI`` [N m^2] or a hollow
    circular wall of ``material`` with ``wall_thickness`` [m] and ``outer_diameter`` [m]."""

    top: float
    bottom: float
    EI: float | None
    material: str | None
    wall_thickness: float | None
    outer_diameter: float
    key: str

    @staticmethod
    def read(r: Reader, stage_diameter: float) -> Section:
        top = r.number("top", lo=-MAX_LENGTH, hi=0.0)
        bottom = r.number("bottom", lo=-MAX_LENGTH, hi=top, hi_open=True)
        EI = r.number("EI", None, lo=0.0, hi=1e15, lo_open=True)
        material = r.text("material", None)
        thickness = r.number("wall_thickness", None, lo=0.0, lo_open=True, hi=0.5 * MAX_DIAMETER)
        diameter = r.number("outer_diameter", stage_diameter, lo=0.0, lo_open=True, hi=MAX_DIAMETER)
        if (EI is None) == (material is None):
            raise r.error("EI", EI, "give either EI or material with wall_thickness, not both or neither")
        if material is not None and thickness is None:
            raise r.error("wall_thickness", None, "required with material")
        if thickness is not None and 2 * thickness > diameter:
            raise r.error("wall_thickness", thickness, f"must be at most half the outer diameter {diameter}")
        return Section(top, bottom, EI, material, thickness, diameter, r.path)


@dataclass(frozen=True)
class Engine:
    """An engine of a stage.

    ``gimbal``: station of the gimbal (thrust application node) [m]; ``mass_flow``: nominal total mass
    flow [kg/s] at throttle 1; ``isp``: specific impulse [s] (the thrust equation, thesis eq. 4.1,
    ``T = mdot Isp g0 + A_e (p_e - p_0)``); or ``thrust_table``: rows ``[t since ignition (s),
    thrust (N)]`` and then ``mass_flow`` is the flow at the table's mean thrust, scaled with thrust;
    ``mixture_ratio``: O/F of the oxidiser and fuel flows (None: one propellant); ``throttle``:
    [min, max] of the flow scale; ``gimbal_limit``: maximum deflection [rad]; ``vectored_share``: the share
    of this engine's thrust that the gimbal turns (1: all of it; 0: a fixed engine; between: e.g. a cluster
    whose outer nozzles are fixed), the rest acting along the body axis."""

    name: str
    part: RigidPart
    gimbal: np.ndarray
    mass_flow: float
    isp: float | None
    thrust_table: np.ndarray | None
    mixture_ratio: float | None
    nozzle_exit_area: float
    nozzle_exit_pressure: float
    throttle: tuple[float, float]
    gimbal_limit: float
    key: str
    vectored_share: float = 1.0

    @staticmethod
    def read(r: Reader) -> Engine:
        name = r.text("name")
        part = RigidPart.read(r, name)
        isp = r.number("isp", None, lo=0.0, lo_open=True, hi=MAX_ISP)
        table = r.table("thrust_table", None)
        if (isp is None) == (table is None):
            raise r.error("isp", isp, "give either isp (thrust equation) or thrust_table, not both or neither")
        if table is not None and (table[0, 0] < 0.0 or np.any(table[:, 1] < 0.0)):
            raise r.error("thrust_table", table.tolist(), "times and thrusts must be >= 0")
        if table is not None and np.any(table[:, 1] > MAX_THRUST):
            raise r.error("thrust_table", table.tolist(), f"thrusts must be <= {MAX_THRUST:g} N")
        if table is not None and not np.any(table[:, 1] > 0.0):
            raise r.error("thrust_table", table.tolist(), "needs a thrust > 0 somewhere (it has no impulse)")
        engine = Engine(
            name=name, part=part, gimbal=r.station("gimbal"),
            mass_flow=r.number("mass_flow", lo=0.0, lo_open=True, hi=MAX_MASS_FLOW), isp=isp, thrust_table=table,
            mixture_ratio=r.number("mixture_ratio", None, lo=0.0, lo_open=True, hi=100.0),
            nozzle_exit_area=r.number("nozzle_exit_area", 0.0, lo=0.0, hi=np.pi * MAX_DIAMETER**2 / 4),
            nozzle_exit_pressure=r.number("nozzle_exit_pressure", 0.0, lo=0.0, hi=1e8),
            throttle=r.pair("throttle", [1.0, 1.0], lo=0.0, hi=2.0),
            gimbal_limit=np.radians(r.number("gimbal_limit_deg", 5.0, lo=0.0, hi=45.0)), key=r.path,
            vectored_share=r.number("vectored_share", 1.0, lo=0.0, hi=1.0))
        if table is not None and engine.throttle != (1.0, 1.0):
            raise r.error("throttle", list(engine.throttle), "a thrust-table engine cannot be throttled: [1, 1]")
        r.done()
        return engine


@dataclass(frozen=True)
class Tank:
    """A cylindrical liquid tank (thesis 4.1.1) with one slosh pendulum (first lateral mode).

    ``inner_radius``, ``height`` [m]; ``top`` station of the tank top [m]; ``density`` [kg/m^3];
    ``fill_ratio`` of the height at lift-off [-]; ``engine`` it feeds and its ``role`` in that engine's
    mixture; ``share`` of that role's flow [-]; ``slip_factor`` (thesis eq. 4.3: the fraction of the
    liquid's roll inertia that does not follow the body); ``slosh_damping`` ratio [-]; ``slosh``: whether
    the tank gets a pendulum."""

    name: str
    inner_radius: float
    height: float
    top: float
    density: float
    fill_ratio: float
    engine: str
    role: str
    share: float
    slip_factor: float
    slosh_damping: float
    slosh: bool
    key: str

    @property
    def bottom(self) -> float:
        """Station of the tank bottom [m]."""
        return self.top - self.height

    @property
    def capacity(self) -> float:
        """Liquid mass of the full tank [kg]."""
        return float(np.pi * self.inner_radius**2 * self.height * self.density)

    @staticmethod
    def read(r: Reader) -> Tank:
        tank = Tank(
            name=r.text("name"), inner_radius=r.number("inner_radius", lo=0.0, lo_open=True, hi=0.5 * MAX_DIAMETER),
            height=r.number("height", lo=0.0, lo_open=True, hi=MAX_LENGTH),
            top=r.number("top", lo=-MAX_LENGTH, hi=0.0),
            density=r.number("density", lo=0.0, lo_open=True, hi=MAX_DENSITY),
            fill_ratio=r.number("fill_ratio", lo=0.0, hi=1.0),
            engine=r.text("engine"), role=r.text("role", choices=TANK_ROLES),
            share=r.number("share", 1.0, lo=0.0, hi=1.0, lo_open=True),
            slip_factor=r.number("slip_factor", 0.95, lo=0.0, hi=1.0),
            slosh_damping=r.number("slosh_damping", 0.01, lo=0.0, hi=10.0), slosh=r.flag("slosh", True), key=r.path)
        r.done()
        return tank


@dataclass(frozen=True)
class Grain:
    """The solid fuel grain of a hybrid stage: a hollow cylinder of ``length`` [m] from station ``top``
    [m], outer radius [m], initial port radius [m] and ``density`` [kg/m^3], burnt from the port
    outwards (uniform regression) at the fuel flow of ``engine``'s mixture ratio. Its mass and inertia
    are its own model (a thick-walled cylinder); it does not slosh."""

    name: str
    top: float
    length: float
    outer_radius: float
    port_radius: float
    density: float
    engine: str
    key: str

    @property
    def bottom(self) -> float:
        return self.top - self.length

    @property
    def capacity(self) -> float:
        """Mass of the unburnt grain [kg]."""
        return float(np.pi * (self.outer_radius**2 - self.port_radius**2) * self.length * self.density)

    @staticmethod
    def read(r: Reader) -> Grain:
        outer = r.number("outer_radius", lo=0.0, lo_open=True, hi=0.5 * MAX_DIAMETER)
        grain = Grain(name=r.text("name"), top=r.number("top", lo=-MAX_LENGTH, hi=0.0),
                      length=r.number("length", lo=0.0, lo_open=True, hi=MAX_LENGTH), outer_radius=outer,
                      port_radius=r.number("port_radius", lo=0.0, hi=outer, hi_open=True),
                      density=r.number("density", lo=0.0, lo_open=True, hi=MAX_DENSITY), engine=r.text("engine"),
                      key=r.path)
        r.done()
        return grain


@dataclass(frozen=True)
class Stage:
    """One stage: its structure, engines, tanks, optional hybrid grain and stiffness sections.

    ``top`` station of the stage's top [m]; ``length`` [m]; ``outer_diameter`` [m]; ``aerodynamics``: the
    raw mapping of the stack's aerodynamics once this stage is the lowest attached one (empty: the
    stack's before it; the first stage's is the vehicle's top-level ``aerodynamics``)."""

    name: str
    top: float
    length: float
    outer_diameter: float
    structure: RigidPart
    engines: tuple[Engine, ...]
    tanks: tuple[Tank, ...]
    grain: Grain | None
    sections: tuple[Section, ...]
    key: str
    aerodynamics: dict[str, Any] = field(default_factory=dict)

    @property
    def bottom(self) -> float:
        return self.top - self.length

    @staticmethod
    def read(r: Reader) -> Stage:
        name = r.text("name")
        diameter = r.number("outer_diameter", lo=0.0, lo_open=True, hi=MAX_DIAMETER)
        s = r.child("structure")
        structure = RigidPart.read(s, f"{name} structure")
        s.done()
        grain_r = r.child("grain", None)
        sections = []
        for sr in r.children("sections", []):
            sections.append(Section.read(sr, diameter))
            sr.done()
        aero = r.raw("aerodynamics", {})
        if not isinstance(aero, dict):
            raise r.error("aerodynamics", aero, "must be a mapping (the stack's aerodynamics once this stage is "
                          "the lowest attached one)")
        stage = Stage(name=name, top=r.number("top", lo=-MAX_LENGTH, hi=0.0),
                      length=r.number("length", lo=0.0, lo_open=True, hi=MAX_LENGTH),
                      outer_diameter=diameter, structure=structure,
                      engines=tuple(Engine.read(e) for e in r.children("engines", [])),
                      tanks=tuple(Tank.read(t) for t in r.children("tanks", [])),
                      grain=Grain.read(grain_r) if grain_r else None, sections=tuple(sections), key=r.path,
                      aerodynamics=aero)
        r.done()
        return stage


@dataclass(frozen=True)
class StagingStep:
    """When a stage fires and leaves: ``ignition_delay`` [s] after the previous stage separated (the
    first stage ignites at lift-off, t = 0), ``burn_time`` [s] (None: until a tank or the grain is
    empty), ``separation_delay`` [s] after burnout (None: never separates)."""

    stage: str
    ignition_delay: float
    burn_time: float | None
    separation_delay: float | None

    @staticmethod
    def read(r: Reader) -> StagingStep:
        step = StagingStep(stage=r.text("stage"), ignition_delay=r.number("ignition_delay", 0.0, lo=0.0, hi=MAX_TIME),
                           burn_time=r.number("burn_time", None, lo=0.0, lo_open=True, hi=MAX_TIME),
                           separation_delay=r.number("separation_delay", None, lo=0.0, hi=MAX_TIME))
        r.done()
        return step


@dataclass(frozen=True)
class StructureOptions:
    """Bending model options: ``n_modes`` per plane, modal damping ratio, and when the modes are
    recomputed: ``recompute_interval`` [s] (None: frozen at lift-off, the thesis's assumption and the
    default); ``sensor_stations`` where gyro mode slopes are wanted [m]; ``first_mode_hz``: calibrate
    the beam's stiffness (all sections by one factor) so that the first mode at lift-off has this
    frequency [Hz] (a measured or finite-element value; None: the sections as given); ``aeroelastic``:
    whether the simulator applies the strip-theory aeroelastic loads (thesis eq. 2.14-2.19)."""

    n_modes: int = 2
    damping: float = 0.01
    recompute_interval: float | None = None
    sensor_stations: tuple[float, ...] = ()
    first_mode_hz: float | None = None
    aeroelastic: bool = False

    @staticmethod
    def read(r: Reader | None) -> StructureOptions:
        if r is None:
            return StructureOptions()
        sensors = r.raw("sensor_stations", [])
        if not isinstance(sensors, list) or not all(
                isinstance(s, (int, float)) and not isinstance(s, bool) and -MAX_LENGTH <= s <= 0 for s in sensors):
            raise r.error("sensor_stations", sensors, f"must be a list of finite stations in [{-MAX_LENGTH:g}, 0]")
        opts = StructureOptions(n_modes=r.integer("n_modes", 2, lo=0, hi=20),
                                damping=r.number("damping", 0.01, lo=0.0, hi=1.0),
                                recompute_interval=r.number("recompute_interval", None, lo=0.0, lo_open=True,
                                                            hi=MAX_TIME),
                                sensor_stations=tuple(float(s) for s in sensors),
                                first_mode_hz=r.number("first_mode_hz", None, lo=0.0, lo_open=True, hi=1000.0),
                                aeroelastic=r.flag("aeroelastic", False))
        r.done()
        return opts


@dataclass(frozen=True)
class Vehicle:
    """A whole vehicle definition. ``stages`` in firing order; ``aerodynamics`` is kept as the raw
    mapping for the environment layer's generator (checked there)."""

    name: str
    description: str
    stages: tuple[Stage, ...]
    payload: RigidPart | None
    fairing: RigidPart | None
    fairing_jettison: float | None
    staging: tuple[StagingStep, ...]
    structure: StructureOptions
    aerodynamics: dict[str, Any] = field(default_factory=dict)
    source: str | None = None
    #: the structural q-alpha limit the file gives (constant or over the flight), or None: the env's
    qalpha_limit: QAlphaLimit | None = None
    #: tables over flight time that replace the mass properties and modes the parts give (:mod:`.timetables`)
    tables: VehicleTables | None = None

    @property
    def length(self) -> float:
        """Overall length [m]: from the nose tip to the bottom of the first stage."""
        return -min(s.bottom for s in self.stages)

    @property
    def tanks(self) -> tuple[Tank, ...]:
        """All tanks, in stage firing order."""
        return tuple(t for s in self.stages for t in s.tanks)
