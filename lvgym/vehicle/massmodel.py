"""Mass model of a multi-stage vehicle at any time: depletion, staging, whole-stack mass properties.

:class:`MassModel` turns a :class:`~lvgym.vehicle.config.Vehicle` into

- a :class:`MassState` (time, propellant left in every tank and grain, the phase of every stage), advanced
  exactly over time by :meth:`MassModel.advance`, which processes every event on the way (tank or grain
  empty, burn time over, separation after its delay, the next stage's ignition, fairing jettison) and
  predicts the next one (:meth:`MassModel.next_event`) so the simulator can land its steps on it;
- :class:`MassProperties` of the current stack (:meth:`MassModel.properties`): the rigid body B (structure,
  engines, payload, fairing, fixed propellant, grains) about its CG, one pendulum per slosh tank of the
  whole vehicle (a tank that is empty or no longer attached has slosh mass 0: inactive), and the
  rigid-equivalent stack (slosh masses frozen at rest into B) with exactly the same mass, CG and inertia,
  for the rigid model. Inertias are combined with the parallel-axis theorem (thesis eq. 4.10).

The flow of an engine stops when any tank (or grain) feeding it is empty; the throttle scales it. A stage
separates ``separation_delay`` after its burnout; the next stage ignites ``ignition_delay`` after that.
The first stage ignites at lift-off, t = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .config import Vehicle
from .propulsion import EngineModel
from .tanks import CG_CONVENTIONS, TankProperties, grain_properties, tank_properties

WAITING, BURNING, COAST, SEPARATED = "waiting", "burning", "coast", "separated"


@dataclass(frozen=True)
class MassState:
    """Time-varying part of the mass model. ``tank_mass`` [kg] per tank (``Vehicle.tanks`` order),
    ``grain_mass`` [kg] per stage (0 without a grain), ``phase`` per stage, ``ignition`` and
    ``burnout`` times per stage [s] (nan until they happen), ``engine_on`` per engine of the vehicle,
    ``fairing`` attached or not."""

    t: float
    tank_mass: np.ndarray
    grain_mass: np.ndarray
    phase: tuple[str, ...]
    ignition: np.ndarray
    burnout: np.ndarray
    engine_on: tuple[bool, ...]
    fairing: bool


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of the stack at one instant; stations in metres from the nose tip.

    Rigid body B (everything but the slosh masses): ``m_b`` [kg], ``r_cg_b`` station of its CG (3,),
    ``J_b`` inertia about that CG, body axes [kg m^2] (3, 3). Slosh pendulums, one per slosh tank of
    the whole vehicle (``slosh_names``): ``slosh_mass`` [kg] (0 inactive), ``pendulum_length`` [m],
    ``hinge`` stations (N, 3), ``slosh_rest`` stations of the masses at rest (N, 3),
    ``slosh_damping`` ratios. Rigid-equivalent stack: ``mass`` [kg], ``cg`` (3,), ``inertia`` (3, 3)
    about ``cg``. ``gimbal``: thrust-weighted gimbal station of the burning engines (the lowest attached
    engine's when none burns); ``mass_flow`` [kg/s]; ``tanks`` per tank (None once separated)."""

    t: float
    m_b: float
    r_cg_b: np.ndarray
    J_b: np.ndarray
    slosh_names: tuple[str, ...]
    slosh_mass: np.ndarray
    pendulum_length: np.ndarray
    hinge: np.ndarray
    slosh_rest: np.ndarray
    slosh_damping: np.ndarray
    mass: float
    cg: np.ndarray
    inertia: np.ndarray
    gimbal: np.ndarray
    mass_flow: float
    stages: tuple[str, ...]
    tanks: tuple[TankProperties | None, ...]


def combine(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass [kg], CG (3,) and inertia about the CG (3, 3) of parts ``(m, cg, J_about_own_cg)``
    (parallel-axis theorem, thesis eq. 4.10: ``J + m (|r|^2 I - r r^T)``)."""
    m = sum(p[0] for p in parts)
    if m <= 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    cg = sum(p[0] * p[1] for p in parts) / m
    J = np.zeros((3, 3))
    for mi, ci, Ji in parts:
        r = ci - cg
        J += Ji + mi * (r @ r * np.eye(3) - np.outer(r, r))
    return m, cg, J


class MassModel:
    """Mass properties and propellant depletion of ``vehicle``.

    ``cg_convention``: ``"static"`` (default; the fixed liquid mass keeps the liquid's static CG,
    DESIGN.md note 2) or ``"thesis"`` (fixed mass at the liquid centroid, as the thesis's tables)."""

    def __init__(self, vehicle: Vehicle, cg_convention: str = "static"):
        if cg_convention not in CG_CONVENTIONS:
            raise ValueError(f"cg_convention = {cg_convention!r}: one of {CG_CONVENTIONS}")
        self.vehicle = vehicle
        self.cg_convention = cg_convention
        self.tanks = vehicle.tanks
        self.tank_stage = np.array([i for i, s in enumerate(vehicle.stages) for _ in s.tanks])
        self.engines = [(i, EngineModel(e)) for i, s in enumerate(vehicle.stages) for e in s.engines]
        self.slosh_tanks = [k for k, t in enumerate(self.tanks) if t.slosh]
        self.slosh_names = tuple(self.tanks[k].name for k in self.slosh_tanks)
        # flow share of each tank / grain in its engine's total flow
        self._feeds: list[list[tuple[str, int, float]]] = []
        for si, em in self.engines:
            e, stage = em.engine, vehicle.stages[si]
            of = e.mixture_ratio
            frac = {"propellant": 1.0} if of is None else {"oxidiser": of / (1 + of), "fuel": 1 / (1 + of)}
            feeds = [("tank", k, frac[t.role] * t.share) for k, t in enumerate(self.tanks)
                     if self.tank_stage[k] == si and t.engine == e.name]
            if stage.grain is not None and stage.grain.engine == e.name:
                fuel_tanks = sum(t.share for t in stage.tanks if t.engine == e.name and t.role == "fuel")
                feeds.append(("grain", si, frac["fuel"] * (1.0 - fuel_tanks)))
            self._feeds.append(feeds)

    @property
    def n_slosh(self) -> int:
        """Number of slosh pendulums over the vehicle's whole flight."""
        return len(self.slosh_tanks)

    # -- state ----------------------------------------------------------------------------------
    def initial_state(self) -> MassState:
        """Lift-off: tanks filled to their fill ratios, the first stage ignited at t = 0."""
        v = self.vehicle
        n = len(v.stages)
        phase = [WAITING] * n
        phase[0] = BURNING
        ignition = np.full(n, np.nan)
        ignition[0] = 0.0
        return MassState(t=0.0, tank_mass=np.array([t.capacity * t.fill_ratio for t in self.tanks]),
                         grain_mass=np.array([s.grain.capacity if s.grain else 0.0 for s in v.stages]),
                         phase=tuple(phase), ignition=ignition, burnout=np.full(n, np.nan),
                         engine_on=tuple(si == 0 for si, _ in self.engines), fairing=v.fairing is not None)

    def _left(self, state: MassState, kind: str, index: int) -> float:
        return state.tank_mass[index] if kind == "tank" else state.grain_mass[index]

    def _engine_stop(self, state: MassState, j: int, throttle: float) -> float:
        """Time [s] from ``state.t`` until engine ``j`` stops (a feed empty, burn time or table over)."""
        si, em = self.engines[j]
        tau0 = state.t - state.ignition[si]
        step = self.vehicle.staging[si]
        limit = min(em.burn_end, step.burn_time if step.burn_time is not None else np.inf) - tau0
        for kind, index, frac in self._feeds[j]:
            if frac > 0.0:
                limit = min(limit, em.time_to_consume(tau0, self._left(state, kind, index) / frac, throttle))
        return max(limit, 0.0)

    def next_event(self, state: MassState, throttle: float = 1.0) -> float:
        """Time of the next event after ``state.t`` [s] at constant ``throttle`` (inf if none)."""
        v, t_next = self.vehicle, np.inf
        for j, on in enumerate(state.engine_on):
            if on:
                t_next = min(t_next, state.t + self._engine_stop(state, j, throttle))
        for si, phase in enumerate(state.phase):
            step = v.staging[si]
            if phase == COAST and step.separation_delay is not None:
                t_next = min(t_next, state.burnout[si] + step.separation_delay)
            if phase == WAITING and si > 0 and state.phase[si - 1] == SEPARATED:
                t_sep = state.burnout[si - 1] + v.staging[si - 1].separation_delay
                t_next = min(t_next, t_sep + step.ignition_delay)
        if state.fairing and v.fairing_jettison is not None:
            t_next = min(t_next, v.fairing_jettison)
        return max(t_next, state.t)

    def advance(self, state: MassState, t1: float, throttle: float = 1.0) -> tuple[MassState, list[tuple[float, str]]]:
        """Advance to time ``t1`` [s] at constant ``throttle``; returns the new state and the events
        ``(time, description)`` that happened in ``(state.t, t1]``, in order."""
        events: list[tuple[float, str]] = []
        while True:
            t_event = self.next_event(state, throttle)
            t_to = min(t_event, t1)
            state = self._consume(state, t_to, throttle)
            if t_event > t1:
                return state, events
            state, happened = self._apply_events(state, throttle)
            if not happened:  # next_event promised an event that _apply_events does not see: a bug
                raise RuntimeError(f"mass model stalled at t = {state.t!r} s (no event at the predicted time)")
            events += [(state.t, e) for e in happened]

    def _consume(self, state: MassState, t_to: float, throttle: float) -> MassState:
        if t_to <= state.t:
            return state
        tanks, grains = state.tank_mass.copy(), state.grain_mass.copy()
        for j, on in enumerate(state.engine_on):
            if not on:
                continue
            si, em = self.engines[j]
            used = em.consumed(state.t - state.ignition[si], t_to - state.ignition[si], throttle)
            for kind, index, frac in self._feeds[j]:
                store = tanks if kind == "tank" else grains
                left = store[index] - frac * used
                # rounding residue of an emptied store (1e-15 kg after split steps) is no propellant
                store[index] = left if left > 1e-9 * max(store[index], 1.0) else 0.0
        return replace(state, t=t_to, tank_mass=tanks, grain_mass=grains)

    def _apply_events(self, state: MassState, throttle: float) -> tuple[MassState, list[str]]:
        v, t, tol = self.vehicle, state.t, 1e-9 * max(1.0, state.t)
        happened: list[str] = []
        engine_on = list(state.engine_on)
        for j, on in enumerate(engine_on):
            if on and self._engine_stop(state, j, throttle) <= tol:
                engine_on[j] = False
                happened.append(f"engine {self.engines[j][1].engine.name!r} stopped")
        phase, burnout, ignition = list(state.phase), state.burnout.copy(), state.ignition.copy()
        for si, stage in enumerate(v.stages):
            step = v.staging[si]
            if phase[si] == BURNING and not any(engine_on[j] for j, (s, _) in enumerate(self.engines) if s == si):
                phase[si], burnout[si] = COAST, t
                happened.append(f"stage {stage.name!r} burnout")
            if phase[si] == COAST and step.separation_delay is not None and t >= burnout[si] + step.separation_delay - tol:
                phase[si] = SEPARATED
                happened.append(f"stage {stage.name!r} separation")
            if phase[si] == WAITING and si > 0 and phase[si - 1] == SEPARATED:
                t_ign = burnout[si - 1] + v.staging[si - 1].separation_delay + step.ignition_delay
                if t >= t_ign - tol:
                    phase[si], ignition[si] = BURNING, t
                    for j, (s, _) in enumerate(self.engines):
                        engine_on[j] = engine_on[j] or s == si
                    happened.append(f"stage {stage.name!r} ignition")
        fairing = state.fairing
        if fairing and v.fairing_jettison is not None and t >= v.fairing_jettison - tol:
            fairing = False
            happened.append("fairing jettison")
        return replace(state, phase=tuple(phase), burnout=burnout, ignition=ignition,
                       engine_on=tuple(engine_on), fairing=fairing), happened

    # -- properties -----------------------------------------------------------------------------
    def mass_flow(self, state: MassState, throttle: float = 1.0) -> float:
        """Total propellant flow of the burning engines [kg/s]."""
        return sum(em.mass_flow(state.t - state.ignition[si], throttle)
                   for (si, em), on in zip(self.engines, state.engine_on) if on)

    def thrust(self, state: MassState, throttle: float = 1.0, p_ambient: float = 0.0) -> float:
        """Total thrust magnitude of the burning engines [N] at ambient pressure ``p_ambient`` [Pa]."""
        return sum(em.thrust(state.t - state.ignition[si], throttle, p_ambient)
                   for (si, em), on in zip(self.engines, state.engine_on) if on)

    def properties(self, state: MassState, throttle: float = 1.0) -> MassProperties:
        """Mass properties of the stack in ``state`` (see :class:`MassProperties`)."""
        v = self.vehicle
        attached = [si for si, ph in enumerate(state.phase) if ph != SEPARATED]
        parts: list[tuple[float, np.ndarray, np.ndarray]] = []
        tank_props: list[TankProperties | None] = []
        for si in attached:
            stage = v.stages[si]
            s = stage.structure
            parts.append((s.mass, s.cg, s.inertia))
            parts += [(e.part.mass, e.part.cg, e.part.inertia) for e in stage.engines]
            if stage.grain is not None:
                m, x, J = grain_properties(stage.grain, state.grain_mass[si])
                parts.append((m, np.array([x, 0.0, 0.0]), J))
        for k, tank in enumerate(self.tanks):
            if state.phase[self.tank_stage[k]] == SEPARATED:
                tank_props.append(None)
                continue
            tp = tank_properties(tank, state.tank_mass[k], self.cg_convention)
            tank_props.append(tp)
            parts.append((tp.fixed_mass, np.array([tp.fixed_cg, 0.0, 0.0]), tp.fixed_inertia))
        for part, on in ((v.payload, True), (v.fairing, state.fairing)):
            if part is not None and on:
                parts.append((part.mass, part.cg, part.inertia))
        m_b, r_cg_b, J_b = combine(parts)
        n = self.n_slosh
        m_s, L, zeta = np.zeros(n), np.zeros(n), np.zeros(n)
        hinge, rest = np.zeros((n, 3)), np.zeros((n, 3))
        for j, k in enumerate(self.slosh_tanks):
            tp = tank_props[k]
            zeta[j] = self.tanks[k].slosh_damping
            if tp is None:
                hinge[j, 0] = rest[j, 0] = r_cg_b[0]
                continue
            m_s[j], L[j] = tp.slosh_mass, tp.pendulum_length
            hinge[j, 0], rest[j, 0] = tp.hinge_station, tp.slosh_station
        mass, cg, inertia = combine(parts + [(m_s[j], rest[j], np.zeros((3, 3))) for j in range(n)])
        return MassProperties(t=state.t, m_b=m_b, r_cg_b=r_cg_b, J_b=J_b, slosh_names=self.slosh_names,
                              slosh_mass=m_s, pendulum_length=L, hinge=hinge, slosh_rest=rest, slosh_damping=zeta,
                              mass=mass, cg=cg, inertia=inertia, gimbal=self._gimbal(state, attached, throttle),
                              mass_flow=self.mass_flow(state, throttle),
                              stages=tuple(v.stages[si].name for si in attached), tanks=tuple(tank_props))

    def _gimbal(self, state: MassState, attached: list[int], throttle: float) -> np.ndarray:
        weights, points = [], []
        for (si, em), on in zip(self.engines, state.engine_on):
            if on:
                weights.append(max(em.thrust(state.t - state.ignition[si], throttle), 1e-12))
                points.append(em.engine.gimbal)
        if weights:
            return np.average(points, axis=0, weights=weights)
        candidates = [em.engine.gimbal for si, em in self.engines if si in attached]
        return min(candidates, key=lambda g: g[0]) if candidates else np.zeros(3)
