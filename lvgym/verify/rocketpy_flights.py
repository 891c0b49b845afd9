"""The two flights of the RocketPy validation (:mod:`.rocketpy_case`): the shipped ``stratos3`` flown by lvgym's
rigid :class:`~lvgym.simulator.Simulator` (flat non-rotating site, constant gravity, US76, zero gimbal, no
wind) and by RocketPy 1.13 (a dev dependency, imported only inside the functions of this module), each as a
:class:`Trajectory` with its wall times.

What RocketPy is given, all taken from lvgym's own vehicle and models so that both fly the same vehicle:

* mass: the rocket without motor is the structure (94 kg, CG and inertia of the vehicle file); the motor's
  dry part is the rest of the stack at burnout (engine and unburnt grain sliver); the propellant's mass
  follows the thrust (RocketPy's ``GenericMotor``: flow = thrust / constant exhaust velocity, which is
  lvgym's table-engine law ``mass_flow * T / T_mean``) with the burnt total of lvgym's timeline; its CG and
  inertia are lvgym's timeline (stack minus dry part, parallel-axis theorem) through a ``GenericMotor``
  subclass. ``motor="generic"`` uses RocketPy's own single-cylinder estimate instead (a sensitivity).
* thrust: the vehicle's thrust table up to lvgym's burnout (the N2O tank empties 0.088 s before the table
  ends, at 44 N). ``stratos3`` gives no nozzle exit area, so neither code corrects the table for ambient
  pressure (RocketPy: no ``reference_pressure``).
* aerodynamics: the same nose, body and fins (RocketPy's Barrowman surfaces); drag is lvgym's zero-angle
  axial-force coefficient ``CA(M, 0)`` on lvgym's Mach grid, linear in between, as the power-off and the
  power-on curve.
* environment: constant gravity 9.80665 m/s^2; lvgym's US76 every 100 m up to 160 km as RocketPy's custom
  atmosphere (RocketPy's built-in ISA ends at 80 km and its spline extrapolation turns pressure and
  density negative above about 81 km: ``atmosphere="isa"`` shows the effect); RocketPy's Earth rotation
  (its ``Flight`` adds the Coriolis acceleration of the launch latitude) switched off, because lvgym's
  ``flat`` site does not rotate (``earth_rotation=True`` keeps it).
* launch: the same rail elevation and length (RocketPy: ``inclination``, ``rail_length``).

Altitude datum: lvgym's altitude is that of the CG, with the vehicle standing on its base at altitude 0;
RocketPy's is that of the centre of dry mass (CDM), which starts at 0. RocketPy's altitudes are shifted up
by the CDM's height above the base on the pad, ``(L + x_cdm) sin(E)`` (3.64 m at 85 deg), so that after
burnout (CG = CDM) both give the height of the same point above the same ground.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.environment import make
from lvgym.errors import require
from lvgym.simulator import EnvironmentSpec, LaunchSpec, Simulator, TimelineSpec

G0 = 9.80665                          #: standard gravity, both simulators [m/s^2]
VEHICLE = "stratos3"
ELEVATION_DEG = 85.0                  #: rail elevation of the main case [deg]
RAIL_LENGTH = 10.0                    #: rail length [m] (RocketPy needs a rail > 0, also when vertical)
T_END = 240.0                         #: timeline length [s], past the apogee (about 166 s)
STEP = 0.05                           #: lvgym step per call [s] (RK4 steps of physics_dt inside)
RP_MAX_STEP = 0.1                     #: largest RocketPy (LSODA) step [s], for dense histories
NOZZLE_RADIUS = 0.1                   #: [m] not in the vehicle file; RocketPy uses it only for jet damping
ATMOSPHERE_TOP = 160e3                #: top of the US76 table handed to RocketPy [m]
ATMOSPHERE_DZ = 100.0                 #: its spacing [m]
R_AIR_ROCKETPY = 287.05287            #: RocketPy's Environment.air_gas_constant [J/(kg K)]


@dataclass(frozen=True)
class Trajectory:
    """One simulator's flight: ``apogee`` [m] above the pad, ``max_mach`` [-], ``t_apogee``, ``t_max_mach``
    and ``t_burnout`` [s]; histories ``t`` [s], ``altitude`` [m], ``mach`` [-]; ``wall_time`` [s] in all, of
    which ``setup_time`` [s] before the flight (lvgym: the simulator with its timeline and the reset; RocketPy:
    the environment, motor and rocket, before ``Flight`` integrates)."""

    name: str
    apogee: float
    max_mach: float
    t_apogee: float
    t_max_mach: float
    t_burnout: float
    t: np.ndarray
    altitude: np.ndarray
    mach: np.ndarray
    wall_time: float
    setup_time: float = float("nan")

    @property
    def flight_time(self) -> float:
        """Wall time of the flight alone [s]."""
        return self.wall_time - self.setup_time



def _peak(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """``(time, value)`` of the largest sample of ``y(t)``, refined by a parabola through three samples."""
    k = int(np.argmax(y))
    if 0 < k < len(y) - 1:
        a, b, c = np.polyfit(t[k - 1:k + 2] - t[k], y[k - 1:k + 2], 2)
        if a < 0.0:
            dt = float(np.clip(-b / (2 * a), t[k - 1] - t[k], t[k + 1] - t[k]))
            return float(t[k] + dt), float(c + b * dt + a * dt * dt)
    return float(t[k]), float(y[k])



# ------------------------------------------------------------------------------------------ lvgym
def lvgym_simulator(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH,
                    t_end: float = T_END) -> Simulator:
    """The rigid ``stratos3`` on the flat non-rotating site, constant gravity, US76, no wind."""
    return Simulator(VEHICLE, "rigid", launch=LaunchSpec("flat", elevation_deg, rail_length),
                     environment=EnvironmentSpec(gravity="constant", atmosphere="us76", wind="none"),
                     timeline=TimelineSpec(t_end=t_end))


def fly_lvgym(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH,
              t_end: float = T_END) -> Trajectory:
    """Fly lvgym's rigid simulator with the gimbal at zero until just past apogee."""
    start = time.perf_counter()
    sim = lvgym_simulator(elevation_deg, rail_length, t_end)
    data = sim.reset()
    setup = time.perf_counter() - start
    v = sim.view(data)
    up = np.array([1.0, 0.0, 0.0])                       # flat site: the launch frame's +x is up
    t, alt, mach = [0.0], [float(v.conditions("altitude")[0])], [float(v.conditions("mach")[0])]
    while True:
        sim.step(data, [[0.0, 0.0]], STEP)
        if v.failed[0]:
            raise RuntimeError(f"lvgym's flight failed (non-finite state) at t = {v.t[0]:.2f} s")
        t.append(float(v.t[0]))
        alt.append(float(v.conditions("altitude")[0]))
        mach.append(float(v.conditions("mach")[0]))
        if t[-1] > 1.0 and float(v.state("v_zw_i")[0] @ up) < 0.0:
            break
        if t[-1] >= t_end - STEP:
            raise RuntimeError(f"no apogee before t_end = {t_end} s: raise t_end")
    ta, apogee = _peak(np.array(t), np.array(alt))
    tm, max_mach = _peak(np.array(t), np.array(mach))
    burnout = next(tt for tt, e in sim.timeline.events if e.endswith("burnout"))
    return Trajectory("lvgym", apogee, max_mach, ta, tm, float(burnout), np.array(t), np.array(alt),
                      np.array(mach), time.perf_counter() - start, setup)


# ------------------------------------------------------------------------------------------ mass split
def _shift(m: float, cg: float, J: np.ndarray, ref: float) -> np.ndarray:
    """Parallel-axis term: inertia about the station ``ref`` [m] of a part of mass ``m`` [kg] with CG
    station ``cg`` [m] and inertia ``J`` (3, 3) about its CG [kg m^2]."""
    r = np.array([cg - ref, 0.0, 0.0])
    return J + m * (r @ r * np.eye(3) - np.outer(r, r))


@dataclass(frozen=True)
class MassSplit:
    """lvgym's rigid stack split the way RocketPy builds a rocket; stations [m] from the nose tip, negative
    aft; inertias ``(axial, transverse)`` [kg m^2] about each part's own CG.

    ``rocket_*``: the structure (RocketPy's rocket without motor); ``dry_*``: the rest of the stack at
    burnout (engine, unburnt grain); ``t`` (n,) [s] with ``prop_mass`` [kg], ``prop_cg`` [m],
    ``prop_axial``, ``prop_transverse`` (n,): the propellant (stack minus both); ``burnt`` [kg];
    ``t_burnout`` [s]; ``cdm``: CG station of the whole dry stack (RocketPy's centre of dry mass) [m];
    ``length`` of the vehicle [m]."""

    rocket_mass: float
    rocket_cg: float
    rocket_inertia: tuple[float, float]
    dry_mass: float
    dry_cg: float
    dry_inertia: tuple[float, float]
    t: np.ndarray
    prop_mass: np.ndarray
    prop_cg: np.ndarray
    prop_axial: np.ndarray
    prop_transverse: np.ndarray
    burnt: float
    t_burnout: float
    cdm: float
    length: float


def mass_split(sim: Simulator) -> MassSplit:
    """Split the timeline of ``sim`` (a single-stage vehicle) into structure, motor dry part and propellant."""
    tl, vehicle = sim.timeline, sim.vehicle
    if len(vehicle.stages) != 1 or len(vehicle.stages[0].engines) != 1:
        raise ValueError(f"{vehicle.name}: the RocketPy case handles one stage with one engine")
    s = vehicle.stages[0].structure
    burnout = next(t for t, e in tl.events if e.endswith("burnout"))
    if tl.t[-1] <= burnout:
        raise ValueError("the timeline ends before burnout: raise t_end")
    t, keep = np.unique(tl.t, return_index=True)            # event rows are stored twice: keep the first
    m, cg, J = tl.mass[keep], tl.cg[keep, 0], tl.inertia[keep]
    m_f, cg_f, J_f = m[-1], cg[-1], J[-1]
    m_d = m_f - s.mass                                      # motor dry part = final stack - structure
    cg_d = (m_f * cg_f - s.mass * s.cg[0]) / m_d
    # _shift with a negative mass moves an inertia about a station to the part's own CG
    J_d = _shift(-m_d, cg_d, J_f - _shift(s.mass, s.cg[0], s.inertia, cg_f), cg_f)
    m_p = m - m_f                                           # propellant = stack - final stack
    live = m_p > 1e-9 * m[0]
    cg_p = np.where(live, (m * cg - m_f * cg_f) / np.where(live, m_p, 1.0), np.nan)
    J_p = np.full((len(t), 3, 3), np.nan)
    for k in np.flatnonzero(live):
        J_p[k] = _shift(-m_p[k], cg_p[k], J[k] - _shift(m_f, cg_f, J_f, cg[k]), cg[k])
    last = np.flatnonzero(live)[-1]
    cg_p[~live], J_p[~live] = cg_p[last], J_p[last]           # no propellant left: hold (times zero mass)
    return MassSplit(rocket_mass=float(s.mass), rocket_cg=float(s.cg[0]),
                     rocket_inertia=(float(s.inertia[0, 0]), float(s.inertia[1, 1])),
                     dry_mass=float(m_d), dry_cg=float(cg_d), dry_inertia=(float(J_d[0, 0]), float(J_d[1, 1])),
                     t=t, prop_mass=m_p, prop_cg=cg_p, prop_axial=J_p[:, 0, 0], prop_transverse=J_p[:, 1, 1],
                     burnt=float(m[0] - m_f), t_burnout=float(burnout), cdm=float(cg_f),
                     length=float(vehicle.length))


# ------------------------------------------------------------------------------------------ RocketPy
def _us76_table(top: float = ATMOSPHERE_TOP, dz: float = ATMOSPHERE_DZ) -> tuple[np.ndarray, np.ndarray]:
    """``(pressure, temperature)`` tables ``[[z, value], ...]`` of lvgym's US76 for RocketPy, z [m] geometric.
    The temperature is ``p / (R rho)`` with RocketPy's gas constant, so that RocketPy's ``rho = p / (R T)``
    and ``a = sqrt(1.4 R T)`` are US76's density and speed of sound, above 86 km too."""
    z = np.arange(0.0, top + dz / 2, dz)
    s = make("atmosphere", "us76")(z)
    return np.column_stack([z, s.pressure]), np.column_stack([z, s.pressure / (R_AIR_ROCKETPY * s.density)])


def _tabulated_motor_class() -> type:
    """A RocketPy ``GenericMotor`` whose propellant CG and inertia are tables of time (defined on first use,
    so that RocketPy stays a dev dependency)."""
    from rocketpy import GenericMotor
    from rocketpy.mathutils.function import funcify_method

    class TabulatedMotor(GenericMotor):
        """``GenericMotor`` with ``prop = (t, cg, axial, transverse)``: the propellant's CG [m] in the
        motor's coordinates and its inertia about that CG [kg m^2], linear in time."""

        def __init__(self, prop: tuple[np.ndarray, ...], **kwargs: Any) -> None:
            self._prop = prop
            super().__init__(**kwargs)

        @funcify_method("Time (s)", "center of mass (m)", "linear", "constant")
        def center_of_propellant_mass(self):
            return np.column_stack([self._prop[0], self._prop[1]])

        @funcify_method("Time (s)", "Inertia I_11 (kg m²)", "linear", "constant")
        def propellant_I_11(self):
            return np.column_stack([self._prop[0], self._prop[3]])

        @funcify_method("Time (s)", "Inertia I_22 (kg m²)", "linear", "constant")
        def propellant_I_22(self):
            return np.column_stack([self._prop[0], self._prop[3]])

        @funcify_method("Time (s)", "Inertia I_33 (kg m²)", "linear", "constant")
        def propellant_I_33(self):
            return np.column_stack([self._prop[0], self._prop[2]])

    return TabulatedMotor


def rocketpy_flight(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH, *,
                    motor: str = "tabulated", earth_rotation: bool = False, atmosphere: str = "us76",
                    patch_issue_1186: bool = False, jet_damping: bool = True,
                    timings: dict[str, float] | None = None, sim: Simulator | None = None) -> tuple[Any, MassSplit]:
    """RocketPy's ``Flight`` of ``stratos3`` (see the module docstring) and the :class:`MassSplit` it used.

    ``motor``: ``"tabulated"`` (propellant CG and inertia from lvgym's timeline) or ``"generic"``
    (RocketPy's cylinder over tank and grain, CG fixed at its middle); ``earth_rotation``: keep RocketPy's
    Coriolis term (latitude 0); ``atmosphere``: ``"us76"`` (lvgym's table) or ``"isa"`` (RocketPy's
    built-in standard atmosphere); ``patch_issue_1186``: a diagnostic, reverse the sign of
    ``Rocket.com_to_cdm_function`` and ``Rocket.nozzle_to_cdm``, which RocketPy 1.13's
    ``Flight.u_dot_generalized`` reads as vectors from the CDM although they run towards it (RocketPy
    issue #1186, fix proposed in PR #1196); ``jet_damping=False``: a diagnostic, put the nozzle at the CDM
    and zero its gyration tensor, which removes RocketPy's jet-damping terms (lvgym has none). ``sim``: the
    lvgym simulator of the same launch whose vehicle and tables RocketPy is given (default: built here)."""
    require("rocketpy", "dev", "the RocketPy comparison")
    from rocketpy import Environment, Flight, Function, GenericMotor, Rocket

    if motor not in ("tabulated", "generic"):
        raise ValueError(f"motor = {motor!r}: 'tabulated' or 'generic'")
    if atmosphere not in ("us76", "isa"):
        raise ValueError(f"atmosphere = {atmosphere!r}: 'us76' or 'isa'")
    sim = lvgym_simulator(elevation_deg, rail_length) if sim is None else sim
    vehicle, split, aero = sim.vehicle, mass_split(sim), sim.aerodynamics
    if aero is None or not hasattr(aero, "nose_shape"):
        raise ValueError(f"{vehicle.name}: needs a barrowman 'aerodynamics' section")

    env = Environment(gravity=G0, latitude=0.0, longitude=0.0, elevation=0.0)
    if atmosphere == "us76":
        pressure, temperature = _us76_table()
        env.set_atmospheric_model(type="custom_atmosphere", pressure=pressure, temperature=temperature,
                                  wind_u=0.0, wind_v=0.0)
    else:
        env.set_atmospheric_model(type="standard_atmosphere")
    if not earth_rotation:
        env.earth_rotation_vector = [0.0, 0.0, 0.0]

    mach = aero.axes[0]
    cd = np.array([aero.coefficients(float(m), 0.0)["CA"] for m in mach])
    drag = Function(np.column_stack([mach, cd]), "Mach", "Cd", "linear", "constant")
    # RocketPy "nose_to_tail": positions are distances from the nose tip, aft positive (= -station)
    rocket = Rocket(radius=aero.radius, mass=split.rocket_mass,
                    inertia=(split.rocket_inertia[1], split.rocket_inertia[1], split.rocket_inertia[0]),
                    power_off_drag=drag, power_on_drag=drag, center_of_mass_without_motor=-split.rocket_cg,
                    coordinate_system_orientation="nose_to_tail")
    kinds = {"ogive": "ogive", "cone": "conical", "von_karman": "von karman"}
    rocket.add_nose(length=aero.nose_length, kind=kinds[aero.nose_shape], position=0.0)
    for f in aero.fins:
        rocket.add_trapezoidal_fins(n=f.count, root_chord=f.root_chord, tip_chord=f.tip_chord, span=f.span,
                                    position=-f.station, sweep_length=f.sweep)
    if aero.tail_length > 0.0:
        rocket.add_tail(top_radius=aero.radius, bottom_radius=0.5 * aero.aft_diameter, length=aero.tail_length,
                        position=aero.nose_length + aero.body_length)

    stage = vehicle.stages[0]
    table, t_b = stage.engines[0].thrust_table, split.t_burnout
    thrust = np.vstack([table[table[:, 0] < t_b], [[t_b, float(np.interp(t_b, table[:, 0], table[:, 1]))]]])
    stores = [(tk.top, tk.bottom, tk.inner_radius) for tk in stage.tanks]
    if stage.grain is not None:
        stores.append((stage.grain.top, stage.grain.top - stage.grain.length, stage.grain.outer_radius))
    top, bottom = max(a for a, _, _ in stores), min(b for _, b, _ in stores)
    # motor coordinates "combustion_chamber_to_nozzle" with the origin at the nose tip: = rocket coordinates
    common = dict(thrust_source=thrust, burn_time=(0.0, t_b), chamber_radius=max(r for _, _, r in stores),
                  chamber_height=top - bottom, chamber_position=-0.5 * (top + bottom),
                  propellant_initial_mass=split.burnt, nozzle_radius=NOZZLE_RADIUS, dry_mass=split.dry_mass,
                  center_of_dry_mass_position=-split.dry_cg,
                  dry_inertia=(split.dry_inertia[1], split.dry_inertia[1], split.dry_inertia[0]),
                  nozzle_position=vehicle.length, coordinate_system_orientation="combustion_chamber_to_nozzle")
    if motor == "tabulated":
        prop = (split.t, -split.prop_cg, split.prop_axial, split.prop_transverse)
        rp_motor = _tabulated_motor_class()(prop=prop, **common)
    else:
        rp_motor = GenericMotor(**common)
    rocket.add_motor(rp_motor, position=0.0)
    if patch_issue_1186:
        rocket.com_to_cdm_function = -1 * rocket.com_to_cdm_function
        rocket.nozzle_to_cdm = -rocket.nozzle_to_cdm
    if not jet_damping:
        from rocketpy.mathutils.vector_matrix import Matrix

        rocket.nozzle_to_cdm = 0.0
        rocket.nozzle_gyration_tensor = Matrix([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    if timings is not None:
        timings["setup_done"] = time.perf_counter()
    flight = Flight(rocket=rocket, environment=env, rail_length=rail_length, inclination=elevation_deg,
                    heading=90.0, terminate_on_apogee=True, max_time=600.0, max_time_step=RP_MAX_STEP)
    return flight, split


def fly_rocketpy(elevation_deg: float = ELEVATION_DEG, rail_length: float = RAIL_LENGTH,
                 **options: Any) -> Trajectory:
    """Fly RocketPy (``options`` of :func:`rocketpy_flight`); altitudes shifted to lvgym's datum. Its set-up
    time includes building lvgym's simulator for the mass split unless ``options`` pass one as ``sim``."""
    start = time.perf_counter()
    timings: dict[str, float] = {}
    flight, split = rocketpy_flight(elevation_deg, rail_length, timings=timings, **options)
    sol = np.asarray(flight.solution)
    t = sol[:, 0]
    datum = (split.length + split.cdm) * math.sin(math.radians(elevation_deg))     # CDM above the base
    alt = sol[:, 3] - flight.env.elevation + datum
    mach = np.array([flight.mach_number.get_value_opt(tt) for tt in t])
    tm, max_mach = _peak(t, mach)
    return Trajectory("RocketPy", float(flight.apogee - flight.env.elevation + datum), max_mach,
                      float(flight.apogee_time), tm, float(flight.rocket.motor.burn_out_time), t, alt, mach,
                      time.perf_counter() - start, timings["setup_done"] - start)
