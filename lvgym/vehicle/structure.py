"""Bending modes of the current stack: the mass model's parts on the free-free beam of :mod:`.beam`.

The beam of the attached stages carries

- stiffness from each stage's ``sections`` (``EI`` given, or a tube of ``material`` and ``wall_thickness``;
  the sections of the attached stages must tile the stack);
- the mass of the rigid body B, the same mass the dynamics core flies: each stage's structure mass spread
  uniformly over the stage with a point mass at the stage end that puts its CG where the vehicle file says;
  engines, payload and fairing as point masses with their pitch inertia; fixed liquid as a column over the
  liquid height (with a point mass at its end that puts its CG at the fixed mass's station); a hybrid
  grain over its length. Slosh masses are not on the beam: they are the pendulums,
  coupled to the modes through the mode shape at their hinges.

:class:`ModeSchedule` decides when the modes are recomputed: by default they are frozen at lift-off (the
thesis's assumption) and recomputed only when a stage separates; with ``recompute_interval`` [s] (vehicle
file, ``structure.recompute_interval``) also as propellant burns. :func:`mode_transfer` carries the modal
coordinates across such a change of basis. ``structure.first_mode_hz`` calibrates
the stiffness to a known first frequency at lift-off (one factor on every section's EI).
"""

from __future__ import annotations

import pickle
from dataclasses import dataclass

import numpy as np

from lvgym.errors import ConfigError

from .beam import BeamModes, stack_modes, transfer
from .definition import Vehicle
from .massmodel import SEPARATED, MassModel, MassProperties, MassState
from .sections import MATERIALS, DistributedMass, PointMass, Section, tube


@dataclass(frozen=True)
class VehicleModes:
    """Mode data the dynamics core takes, for K modes per plane (y and z share shapes).

    ``omega`` [rad/s] (K,), ``zeta`` [-] (K,), ``phi_gimbal`` [1/sqrt(kg)] and ``dphi_gimbal``
    [1/(m sqrt(kg))] (K,), ``phi_hinge`` (N, K) at each slosh hinge, ``sensor_stations`` [m] (S,) with
    ``phi_sensor`` and ``dphi_sensor`` (S, K); ``beam`` the full result (shapes at every node), ``t`` the
    time [s] of the mass state they were computed for."""

    t: float
    omega: np.ndarray
    zeta: np.ndarray
    phi_gimbal: np.ndarray
    dphi_gimbal: np.ndarray
    phi_hinge: np.ndarray
    sensor_stations: np.ndarray
    phi_sensor: np.ndarray
    dphi_sensor: np.ndarray
    beam: BeamModes | None


def _split(mass: float, top: float, bottom: float, x_cg: float) -> tuple[float, float, float]:
    """``mass`` [kg] between stations ``top`` and ``bottom`` [m] as a uniform part [kg] plus a point mass
    [kg] at the end station [m] on the CG's side, so that together they have their CG at ``x_cg`` (all of
    it a point mass at ``x_cg`` when that lies outside the span)."""
    if not bottom <= x_cg <= top or top - bottom < 1e-6:  # a shallow layer's fixed mass above its surface,
        # or a film too thin for an element: all of it at x_cg
        return 0.0, mass, x_cg
    mid = 0.5 * (top + bottom)
    end = top if x_cg > mid else bottom
    m_end = 0.0 if end == mid else min(max(mass * (x_cg - mid) / (end - mid), 0.0), mass)
    return mass - m_end, m_end, end


def _structure_split(stage) -> tuple[float, float, float]:
    return _split(stage.structure.mass, stage.top, stage.bottom, float(stage.structure.cg[0]))


def _stiffness(vehicle: Vehicle, attached: list[int]) -> list[Section]:
    """Beam sections of the attached stages: EI from the vehicle file, the stage's uniform structure
    mass per length."""
    out = []
    for si in attached:
        stage = vehicle.stages[si]
        uniform = max(_structure_split(stage)[0] / stage.length, 1e-9)
        if not stage.sections:
            raise ConfigError(f"{stage.key}.sections", [], "bending modes need the stage's stiffness sections",
                              vehicle.source)
        for sec in stage.sections:
            EI = sec.EI
            if EI is None:
                if sec.material not in MATERIALS:
                    raise ConfigError(f"{sec.key}.material", sec.material, f"one of {sorted(MATERIALS)}",
                                      vehicle.source)
                EI = tube(MATERIALS[sec.material], sec.outer_diameter, sec.wall_thickness)[0]
            out.append(Section(sec.top, sec.bottom, EI, uniform))
    return out


def stack_masses(vehicle: Vehicle, state: MassState, props: MassProperties
                 ) -> tuple[list[PointMass], list[DistributedMass]]:
    """Point and distributed masses of the rigid body B on the beam other than the uniform structure
    mass, which the sections carry (see the module docstring)."""
    points: list[PointMass] = []
    spread: list[DistributedMass] = []
    for si, stage in enumerate(vehicle.stages):
        if state.phase[si] == SEPARATED:
            continue
        _, m_end, end = _structure_split(stage)
        if m_end > 0.0:
            points.append(PointMass(end, m_end))
        points += [PointMass(float(e.part.cg[0]), e.part.mass, float(e.part.inertia[1, 1])) for e in stage.engines]
        if stage.grain is not None and state.grain_mass[si] > 0.0:
            g = stage.grain
            spread.append(DistributedMass(g.top, g.bottom, float(state.grain_mass[si])))
    for tank, tp in zip(vehicle.tanks, props.tanks):
        if tp is not None and tp.fixed_mass > 0.0 and tp.height > 0.0:
            top = tank.bottom + tp.height
            m_col, m_end, end = _split(tp.fixed_mass, top, tank.bottom, tp.fixed_cg)
            if m_col > 0.0:
                spread.append(DistributedMass(top, tank.bottom, m_col))
            if m_end > 0.0:
                points.append(PointMass(end, m_end))
    for part, on in ((vehicle.payload, True), (vehicle.fairing, state.fairing)):
        if part is not None and on:
            points.append(PointMass(float(part.cg[0]), part.mass, float(part.inertia[1, 1])))
    return points, spread


def stiffness_factor(vehicle: Vehicle, cg_convention: str = "static") -> float:
    """Factor on every section's EI that gives the lift-off stack the vehicle file's ``first_mode_hz``
    (1 without it). The mass-normalised shapes do not change with a common factor on EI; every
    frequency scales with its square root."""
    target = vehicle.structure.first_mode_hz
    if target is None:
        return 1.0
    mm = MassModel(vehicle, cg_convention)
    state = mm.initial_state()
    props = mm.properties(state)
    attached = [si for si, ph in enumerate(state.phase) if ph != SEPARATED]
    points, spread = stack_masses(vehicle, state, props)
    beam = stack_modes(_stiffness(vehicle, attached), points, spread, n_modes=1)
    return float((2.0 * np.pi * target / beam.omega[0]) ** 2)


def _stack_modes(sections: list[Section], points: list[PointMass], spread: list[DistributedMass], n_modes: int,
                 query: np.ndarray, solved: dict[bytes, BeamModes] | None) -> BeamModes:
    """:func:`.beam.stack_modes`, looked up first in ``solved`` (the caller's beams so far, by the exact
    bits of their inputs, so the result is the same arrays a new solve gives), and stored there."""
    if solved is None:
        return stack_modes(sections, points, spread, n_modes=n_modes, query_stations=query)
    query = np.ascontiguousarray(query, dtype=float)
    key = pickle.dumps((sections, points, spread, n_modes, query.shape, query.tobytes()), protocol=4)
    if key not in solved:
        solved[key] = stack_modes(sections, points, spread, n_modes=n_modes, query_stations=query)
    return solved[key]


def vehicle_modes(vehicle: Vehicle, state: MassState, props: MassProperties, n_modes: int | None = None,
                  sensor_stations=None, ei_factor: float | None = None,
                  solved: dict[bytes, BeamModes] | None = None, probe_stations=()) -> VehicleModes:
    """First ``n_modes`` (default: the vehicle file's) bending modes of the stack in ``state``;
    ``ei_factor`` multiplies every EI (default :func:`stiffness_factor`). ``solved``: the beams solved so
    far by the caller (a dict it keeps), so that a stack whose masses have not changed (a coast between
    burnout and separation while the modes are recomputed every few seconds) is not solved again.
    ``probe_stations`` [m]: further stations appended to the sensor stations whose shapes and slopes are
    read off the solved beam with its element shape functions (:meth:`~.beam.BeamModes.shape_at`) and
    are not nodes of its mesh, so the modes, and the shapes at every other station, are those without
    them (a dispersed IMU station interpolates between such probes)."""
    opts = vehicle.structure
    K = opts.n_modes if n_modes is None else int(n_modes)
    sensors = np.asarray(opts.sensor_stations if sensor_stations is None else sensor_stations, float).reshape(-1)
    probes = np.asarray(probe_stations, float).reshape(-1)
    N = props.slosh_mass.size
    if K == 0:
        z = np.zeros(0)
        S = sensors.size + probes.size
        return VehicleModes(props.t, z, z, z, z, np.zeros((N, 0)), np.concatenate([sensors, probes]), np.zeros((S, 0)),
                            np.zeros((S, 0)), None)
    attached = [si for si, ph in enumerate(state.phase) if ph != SEPARATED]
    sections = _stiffness(vehicle, attached)
    top, bottom = max(s.top for s in sections), min(s.bottom for s in sections)
    hinges = np.clip(props.hinge[:, 0], bottom, top)  # inactive pendulums may sit off the stack
    # sensors on a stage that has separated read the shape at the end of the remaining stack
    query = np.concatenate([[props.gimbal[0]], hinges, np.clip(sensors, bottom, top)])
    points, spread = stack_masses(vehicle, state, props)
    factor = stiffness_factor(vehicle) if ei_factor is None else ei_factor
    if factor != 1.0:
        sections = [Section(sec.top, sec.bottom, sec.EI * factor, sec.mass_per_length) for sec in sections]
    beam = _stack_modes(sections, points, spread, K, query, solved)
    phi_s, dphi_s = beam.phi[1 + N:].copy(), beam.dphi[1 + N:].copy()
    if probes.size:
        phi_p, dphi_p = beam.shape_at(np.clip(probes, bottom, top))
        phi_s, dphi_s = np.vstack([phi_s, phi_p]), np.vstack([dphi_s, dphi_p])
    return VehicleModes(t=props.t, omega=beam.omega.copy(), zeta=np.full(K, opts.damping),
                        phi_gimbal=beam.phi[0].copy(), dphi_gimbal=beam.dphi[0].copy(),
                        phi_hinge=beam.phi[1:1 + N].copy(), sensor_stations=np.concatenate([sensors, probes]),
                        phi_sensor=phi_s, dphi_sensor=dphi_s, beam=beam)


def mode_transfer(old: VehicleModes, new: VehicleModes) -> np.ndarray:
    """Matrix ``T`` (K_new, K_old) with ``eta_new = T eta_old`` (and the same for ``eta_dot``) when the
    modes change from ``old`` to ``new``: the deflection field of the attached stack kept, projected
    onto the new mass-normalised shapes (:func:`.beam.transfer`). The same matrix serves both planes
    (y and z share shapes); without modes it is empty."""
    if old.beam is None or new.beam is None:
        return np.zeros((new.omega.size, old.omega.size))
    return transfer(old.beam, new.beam)


class ModeSchedule:
    """When to recompute the modes: frozen at lift-off and recomputed at every separation (default), or
    also every ``recompute_interval`` seconds of flight (``None``: the vehicle file's setting)."""

    def __init__(self, mass_model: MassModel, n_modes: int | None = None, recompute_interval: float | None = None,
                 sensor_stations=None, probe_stations=()):
        self.mass_model = mass_model
        self.n_modes = n_modes
        self.interval = mass_model.vehicle.structure.recompute_interval if recompute_interval is None \
            else recompute_interval
        self.sensor_stations = sensor_stations
        self.probe_stations = probe_stations          # read off the beam, not meshed (:func:`vehicle_modes`)
        self.ei_factor = stiffness_factor(mass_model.vehicle, mass_model.cg_convention)
        self._solved: dict[bytes, BeamModes] = {}                # the beams of this schedule, by their inputs
        self._key: tuple | None = None
        self._modes: VehicleModes | None = None

    def _due(self, t: float, attached: tuple[bool, ...]) -> bool:
        """Whether the modes are to be recomputed at time ``t`` [s] with the stages ``attached``."""
        last = self._modes
        if last is None or attached != self._key or t < last.t:                 # a new stack or a new flight
            return True
        return self.interval is not None and t - last.t >= self.interval - 1e-12

    def modes(self, state: MassState, props: MassProperties | None = None) -> VehicleModes:
        """The modes in force at ``state`` (computed when the schedule says so, cached otherwise)."""
        attached = tuple(ph != SEPARATED for ph in state.phase)
        if self._due(state.t, attached):
            props = props if props is not None else self.mass_model.properties(state)
            self._modes = vehicle_modes(self.mass_model.vehicle, state, props, self.n_modes, self.sensor_stations,
                                        self.ei_factor, self._solved, self.probe_stations)
            self._key = attached
        return self._modes

    def modes_rows(self, state: MassState, props: MassProperties) -> list[VehicleModes]:
        """The modes in force at each state of the batch ``state`` (with its batched ``props``), in order,
        as :meth:`modes` one state after the other: a list of B, the same object while unchanged."""
        attached = tuple(ph != SEPARATED for ph in state.phase)
        out = []
        for i, t in enumerate(state.t.tolist()):
            if self._due(t, attached):
                self._modes = vehicle_modes(self.mass_model.vehicle, state.row(i), props.row(i), self.n_modes,
                                            self.sensor_stations, self.ei_factor, self._solved, self.probe_stations)
                self._key = attached
            out.append(self._modes)
        return out
