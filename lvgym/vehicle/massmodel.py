"""Mass model of a multi-stage vehicle at any time: depletion, staging, whole-stack mass properties.

:class:`MassModel` turns a :class:`~lvgym.vehicle.definition.Vehicle` into

- a :class:`MassState` (time, propellant left in every tank and grain, the phase of every stage), advanced
  exactly over time by :meth:`MassModel.advance`, which processes every event on the way (tank or grain
  empty, burn time over, separation after its delay, the next stage's ignition, fairing jettison) and
  predicts the next one (:meth:`MassModel.next_event`) so the simulator can land its steps on it;
- :class:`MassProperties` of the current stack (:meth:`MassModel.properties`): the rigid body B (structure,
  engines, payload, fairing, fixed propellant, grains) about its CG, one pendulum per slosh tank of the
  whole vehicle (a tank that is empty or no longer attached has slosh mass 0: inactive), and the
  rigid-equivalent stack (slosh masses frozen at rest into B) with exactly the same mass, CG and inertia,
  for the rigid model. Inertias are combined with the parallel-axis theorem (thesis eq. 4.10).

:meth:`MassModel.history` gives the states at many times at once, one batched :class:`MassState` per stretch
between events (a leading axis on its time and propellant), and :meth:`MassModel.properties`,
:meth:`~MassModel.thrust` and :meth:`~MassModel.mass_flow` evaluate such a batch with the same equations
array-wise: that is how the simulator's timeline tabulates a flight in one pass.

The flow of an engine stops when any tank (or grain) feeding it is empty; the throttle scales it. A stage
separates ``separation_delay`` after its burnout; the next stage ignites ``ignition_delay`` after that.
The first stage ignites at lift-off, t = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numba as nb
import numpy as np

from lvgym.errors import ConfigError

from .definition import Vehicle
from .propulsion import EngineModel
from .tanks import CG_CONVENTIONS, TankProperties, grain_properties, tank_properties

WAITING, BURNING, COAST, SEPARATED = "waiting", "burning", "coast", "separated"


@dataclass(frozen=True)
class MassState:
    """Time-varying part of the mass model. ``tank_mass`` [kg] per tank (``Vehicle.tanks`` order),
    ``grain_mass`` [kg] per stage (0 without a grain), ``phase`` per stage, ``ignition`` and
    ``burnout`` times per stage [s] (nan until they happen), ``engine_on`` per engine of the vehicle,
    ``fairing`` attached or not.

    A batch of B states that share their phases, ignitions, burnouts, engines and fairing (a stretch
    between events, :meth:`MassModel.history`) has ``t`` (B,), ``tank_mass`` (B, n_tanks) and
    ``grain_mass`` (B, n_stages)."""

    t: float
    tank_mass: np.ndarray
    grain_mass: np.ndarray
    phase: tuple[str, ...]
    ignition: np.ndarray
    burnout: np.ndarray
    engine_on: tuple[bool, ...]
    fairing: bool

    def row(self, i: int) -> MassState:
        """State ``i`` of a batch."""
        return replace(self, t=float(self.t[i]), tank_mass=self.tank_mass[i].copy(),
                       grain_mass=self.grain_mass[i].copy())

    def batched(self) -> MassState:
        """This state as a batch of one."""
        return replace(self, t=np.array([self.t], dtype=float), tank_mass=self.tank_mass[None],
                       grain_mass=self.grain_mass[None])


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of the stack at one instant; stations in metres from the nose tip.

    Rigid body B (everything but the slosh masses): ``m_b`` [kg], ``r_cg_b`` station of its CG (3,),
    ``J_b`` inertia about that CG, body axes [kg m^2] (3, 3). Slosh pendulums, one per slosh tank of
    the whole vehicle (``slosh_names``): ``slosh_mass`` [kg] (0 inactive), ``pendulum_length`` [m],
    ``hinge`` stations (N, 3), ``slosh_rest`` stations of the masses at rest (N, 3),
    ``slosh_damping`` ratios. Rigid-equivalent stack: ``mass`` [kg], ``cg`` (3,), ``inertia`` (3, 3)
    about ``cg``. ``gimbal``: thrust-weighted gimbal station of the burning engines (the lowest attached
    engine's when none burns); ``mass_flow`` [kg/s]; ``tanks`` per tank (None once separated).
    Those of a batched state carry its leading axis B on every array and have arrays (B,) for floats."""

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

    def row(self, i: int) -> MassProperties:
        """Instant ``i`` of a batch."""
        g = self.__getattribute__
        return MassProperties(**{name: float(g(name)[i]) for name in _PROPS_FLOATS},
                              **{name: g(name)[i].copy() for name in _PROPS_ARRAYS},
                              slosh_names=self.slosh_names, stages=self.stages,
                              tanks=tuple(None if tp is None else tp.row(i) for tp in self.tanks))


#: the fields of :class:`MassProperties` that are floats of one instant, arrays of one instant
_PROPS_FLOATS = ("t", "m_b", "mass", "mass_flow")
_PROPS_ARRAYS = ("r_cg_b", "J_b", "slosh_mass", "pendulum_length", "hinge", "slosh_rest", "slosh_damping", "cg",
                 "inertia", "gimbal")


def combine(parts: list[tuple]) -> tuple:
    """Mass [kg], CG (3,) and inertia about the CG (3, 3) of parts ``(m, cg, J_about_own_cg)``
    (parallel-axis theorem, thesis eq. 4.10: ``J + m (|r|^2 I - r r^T)``). Any part may carry a leading
    batch axis B (``m`` (B,), ``cg`` (B, 3), ``J`` (B, 3, 3)); the result then does too."""
    m = 0.0
    for mi, _, _ in parts:
        m = m + np.asarray(mi, dtype=float)
    m = np.asarray(m)
    some = m > 0.0
    first = 0.0
    for mi, ci, _ in parts:
        first = first + np.asarray(mi, dtype=float)[..., None] * np.asarray(ci, dtype=float)
    cg = first / np.where(some, m, 1.0)[..., None]
    J = 0.0
    eye = np.eye(3)
    for mi, ci, Ji in parts:
        r = ci - cg
        rr = r[..., 0] * r[..., 0] + r[..., 1] * r[..., 1] + r[..., 2] * r[..., 2]
        J = J + (Ji + np.asarray(mi, dtype=float)[..., None, None] * (rr[..., None, None] * eye
                                                                      - r[..., :, None] * r[..., None, :]))
    cg = np.where(some[..., None], cg, 0.0) + np.zeros(m.shape + (3,))
    J = np.where(some[..., None, None], J, 0.0) + np.zeros(m.shape + (3, 3))
    return (float(m) if m.ndim == 0 else m), cg, J


def combine_rows(parts: list[tuple], batch: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`combine` of parts for a batch of ``batch`` instants (each part's ``m``, ``cg``, ``J`` a
    number or a (3,), (3, 3) array, or with the leading axis): the same numbers, term by term in the same
    order, in one compiled loop (:func:`_combine_k`); ``m`` (B,), ``cg`` (B, 3), ``J`` (B, 3, 3)."""
    P = len(parts)
    m, c, J = np.empty((P, batch)), np.empty((P, batch, 3)), np.empty((P, batch, 3, 3))
    for p, (mi, ci, Ji) in enumerate(parts):
        m[p], c[p], J[p] = mi, ci, Ji
    out = np.empty(batch), np.empty((batch, 3)), np.empty((batch, 3, 3))
    _combine_k(m, c, J, *out)
    return out


@nb.njit(cache=True, nogil=True)
def _combine_k(m, c, J, out_m, out_cg, out_J):
    """:func:`combine_rows` of parts ``m`` (P, B) [kg], ``c`` (P, B, 3) [m], ``J`` (P, B, 3, 3) [kg m^2]."""
    P, B = m.shape
    Jacc = np.empty((3, 3))
    r = np.empty(3)
    cg = np.empty(3)
    for b in range(B):
        total = 0.0
        for p in range(P):
            total = total + m[p, b]
        some = total > 0.0
        denom = total if some else 1.0
        for k in range(3):
            first = 0.0
            for p in range(P):
                first = first + m[p, b] * c[p, b, k]
            cg[k] = first / denom
        Jacc[:, :] = 0.0
        for p in range(P):
            for k in range(3):
                r[k] = c[p, b, k] - cg[k]
            rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
            for i in range(3):
                for j in range(3):
                    eye = 1.0 if i == j else 0.0
                    Jacc[i, j] = Jacc[i, j] + (J[p, b, i, j] + m[p, b] * (rr * eye - r[i] * r[j]))
        out_m[b] = total
        for i in range(3):
            out_cg[b, i] = (cg[i] if some else 0.0) + 0.0
            for j in range(3):
                out_J[b, i, j] = (Jacc[i, j] if some else 0.0) + 0.0


def body_minus_pendulums(t: np.ndarray, mass: np.ndarray, cg: np.ndarray, J: np.ndarray, slosh_mass: np.ndarray,
                         rest: np.ndarray, key: str, source: str | None):
    """The rigid body B of a stack (``mass`` (B,) [kg], ``cg`` (B, 3) [m], ``J`` (B, 3, 3) [kg m^2] about it)
    without its slosh pendulums (``slosh_mass`` (B, N) [kg] at rest at ``rest`` (B, N, 3) [m], point masses):
    ``m_b`` (B,), ``r_cg_b`` (B, 3), ``J_b`` (B, 3, 3) about B's CG, so that B and the pendulums together are
    the stack (the parallel-axis sum of :func:`combine_rows` with the pendulums' masses negative); the stack
    of a vehicle file's ``mass_properties`` table (:mod:`.timetables`). A :class:`ConfigError` naming ``key``
    when B would have no mass or an impossible inertia at a time ``t`` (B,) [s]."""
    n = slosh_mass.shape[1]
    parts = [(mass, cg, J)] + [(-slosh_mass[:, j], rest[:, j], np.zeros((3, 3))) for j in range(n)]
    m_b, r_b, J_b = combine_rows(parts, mass.size)
    moments = np.linalg.eigvalsh(J_b) if n else np.ones((mass.size, 3))
    bad = (m_b <= 0.0) | np.any(moments <= 0.0, axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise ConfigError(key, f"t = {t[k]:g} s: {mass[k]:g} kg, slosh masses {slosh_mass[k].sum():g} kg",
                          "a stack that holds its slosh pendulums: the rigid body left without them needs a "
                          "positive mass and inertia", source)
    return m_b, r_b, J_b


class MassModel:
    """Mass properties and propellant depletion of ``vehicle``.

    ``cg_convention``: ``"static"`` (default; the fixed liquid mass keeps the liquid's static CG,
    physics note 2) or ``"thesis"`` (fixed mass at the liquid centroid, as the thesis's tables)."""

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
        stretches, events = self._walk(state, np.array([float(t1)]), throttle)
        end = stretches[-1].row(-1)
        return (end if end.t >= state.t else replace(end, t=state.t)), events

    def history(self, times, throttle: float = 1.0, state: MassState | None = None
                ) -> tuple[list[MassState], list[tuple[float, str]]]:
        """The states at the ascending ``times`` [s] from ``state`` (default: lift-off) at constant
        ``throttle``, exactly as :meth:`advance` through one time after the other would give them: one
        batched :class:`MassState` per stretch between events (a time equal to an event's comes after it),
        and the events ``(time, description)`` on the way, in order."""
        stretches, events = self._walk(self.initial_state() if state is None else state,
                                       np.asarray(times, dtype=float).reshape(-1), throttle)
        return [s for s in stretches if s.t.size], events

    def _walk(self, state: MassState, times: np.ndarray, throttle: float
              ) -> tuple[list[MassState], list[tuple[float, str]]]:
        """The stretches of :meth:`history` (the last one ends at ``times[-1]``) and the events."""
        stretches: list[MassState] = []
        events: list[tuple[float, str]] = []
        i, n = 0, times.size
        while True:
            t_event = self.next_event(state, throttle)
            j = max(int(np.searchsorted(times, t_event, side="left")), i)      # times[i:j] come before it
            last = j >= n
            stops = times[i:j] if last else np.append(times[i:j], t_event)
            tanks, grains = self._consume(state, stops, throttle)
            stretches.append(replace(state, t=times[i:j].copy(), tank_mass=tanks[:j - i], grain_mass=grains[:j - i]))
            if last:
                return stretches, events
            state = replace(state, t=float(t_event), tank_mass=tanks[-1].copy(), grain_mass=grains[-1].copy())
            state, happened = self._apply_events(state, throttle)
            if not happened:  # next_event promised an event that _apply_events does not see: a bug
                raise RuntimeError(f"mass model stalled at t = {state.t!r} s (no event at the predicted time)")
            events += [(state.t, e) for e in happened]
            i = j

    def _consume(self, state: MassState, stops: np.ndarray, throttle: float) -> tuple[np.ndarray, np.ndarray]:
        """Propellant left in the tanks (m, n_tanks) and grains (m, n_stages) [kg] at the ascending times
        ``stops`` (m,) [s] with the engines of ``state``: each stop's from the one before (the first from
        ``state``), every burning engine's use taken from its stores in turn. A stop not after the one
        before changes nothing; the rounding residue of an emptied store (1e-15 kg after split steps) is
        no propellant."""
        prev = np.concatenate([[state.t], stops[:-1]])
        moved = stops > prev
        taken: dict[tuple[str, int], list[np.ndarray]] = {}
        for j, on in enumerate(state.engine_on):
            if on:
                si, em = self.engines[j]
                tau0, tau1 = prev - state.ignition[si], stops - state.ignition[si]
                used = np.where(moved, em.consumed(tau0, tau1, throttle), 0.0)
                for kind, index, frac in self._feeds[j]:
                    taken.setdefault((kind, index), []).append(frac * used)
        out = {"tank": np.repeat(state.tank_mass[None], stops.size, axis=0),
               "grain": np.repeat(state.grain_mass[None], stops.size, axis=0)}
        for (kind, index), parts in taken.items():
            start = (state.tank_mass if kind == "tank" else state.grain_mass)[index]
            steps = np.stack(parts, axis=1).ravel()                   # stop by stop, engine by engine
            live = np.repeat(moved, len(parts))
            left = np.subtract.accumulate(np.concatenate([[start], steps]))
            while True:                             # an emptied store: zero, and the rest from zero
                gone = live & (left[1:] != 0.0) & ~(left[1:] > 1e-9 * np.maximum(left[:-1], 1.0))
                if not gone.any():
                    break
                k = int(np.argmax(gone)) + 1
                left[k:] = np.subtract.accumulate(np.concatenate([[0.0], steps[k:]]))
            out[kind][:, index] = left[len(parts)::len(parts)]
        return out["tank"], out["grain"]

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
    def _sum_engines(self, state: MassState, value) -> np.ndarray | float:
        """Sum over the burning engines of ``value(engine_model, tau)`` (``tau`` the time since the
        engine's stage ignited [s]), a float for a state and (B,) for a batch."""
        total = np.zeros(np.shape(state.t))
        for (si, em), on in zip(self.engines, state.engine_on):
            if on:
                total = total + value(em, state.t - state.ignition[si])
        return total[()]

    def mass_flow(self, state: MassState, throttle: float = 1.0):
        """Total propellant flow of the burning engines [kg/s]."""
        return self._sum_engines(state, lambda em, tau: em.mass_flow(tau, throttle))

    def thrust(self, state: MassState, throttle: float = 1.0, p_ambient: float = 0.0):
        """Total thrust magnitude of the burning engines [N] at ambient pressure ``p_ambient`` [Pa]."""
        return self._sum_engines(state, lambda em, tau: em.thrust(tau, throttle, p_ambient))

    def vectored_share(self, state: MassState, throttle: float = 1.0):
        """The share of the burning engines' vacuum thrust that their gimbals turn (each engine's
        ``vectored_share`` weighted by its vacuum thrust; 1 when nothing burns): the share the flight
        loads vector, exact for one engine or engines of one exit-area-to-thrust ratio."""
        total = self.thrust(state, throttle, 0.0)
        turned = self._sum_engines(state, lambda em, tau: em.engine.vectored_share * em.thrust(tau, throttle, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(np.asarray(total) > 0.0, turned / np.where(np.asarray(total) > 0.0, total, 1.0), 1.0)[()]

    def properties(self, state: MassState, throttle: float = 1.0) -> MassProperties:
        """Mass properties of the stack in ``state`` (see :class:`MassProperties`; a batched state gives
        them with its leading axis)."""
        if np.ndim(state.t) == 0:
            return self.properties(state.batched(), throttle).row(0)
        v, B = self.vehicle, state.t.size
        attached = [si for si, ph in enumerate(state.phase) if ph != SEPARATED]
        parts: list[tuple] = []
        tank_props: list[TankProperties | None] = []
        for si in attached:
            stage = v.stages[si]
            s = stage.structure
            parts.append((s.mass, s.cg, s.inertia))
            parts += [(e.part.mass, e.part.cg, e.part.inertia) for e in stage.engines]
            if stage.grain is not None:
                m, x, J = grain_properties(stage.grain, state.grain_mass[:, si])
                parts.append((m, np.array([x, 0.0, 0.0]), J))
        for k, tank in enumerate(self.tanks):
            if state.phase[self.tank_stage[k]] == SEPARATED:
                tank_props.append(None)
                continue
            tp = tank_properties(tank, state.tank_mass[:, k], self.cg_convention)
            tank_props.append(tp)
            parts.append((tp.fixed_mass, _on_axis(tp.fixed_cg), tp.fixed_inertia))
        for part, on in ((v.payload, True), (v.fairing, state.fairing)):
            if part is not None and on:
                parts.append((part.mass, part.cg, part.inertia))
        m_b, r_cg_b, J_b = combine_rows(parts, B)
        n = self.n_slosh
        m_s, L = np.zeros((B, n)), np.zeros((B, n))
        zeta = np.tile([self.tanks[k].slosh_damping for k in self.slosh_tanks], (B, 1)).reshape(B, n)
        hinge, rest = np.zeros((B, n, 3)), np.zeros((B, n, 3))
        for j, k in enumerate(self.slosh_tanks):
            tp = tank_props[k]
            if tp is None:
                hinge[:, j, 0] = rest[:, j, 0] = r_cg_b[:, 0]
                continue
            m_s[:, j], L[:, j] = tp.slosh_mass, tp.pendulum_length
            hinge[:, j, 0], rest[:, j, 0] = tp.hinge_station, tp.slosh_station
        mass, cg, inertia = combine_rows(parts + [(m_s[:, j], rest[:, j], np.zeros((3, 3))) for j in range(n)], B)
        return MassProperties(t=state.t, m_b=m_b, r_cg_b=r_cg_b, J_b=J_b, slosh_names=self.slosh_names,
                              slosh_mass=m_s, pendulum_length=L, hinge=hinge, slosh_rest=rest, slosh_damping=zeta,
                              mass=np.broadcast_to(mass, (B,)), cg=cg, inertia=inertia,
                              gimbal=self._gimbal(state, attached, throttle),
                              mass_flow=np.broadcast_to(self.mass_flow(state, throttle), (B,)),
                              stages=tuple(v.stages[si].name for si in attached), tanks=tuple(tank_props))

    def _gimbal(self, state: MassState, attached: list[int], throttle: float) -> np.ndarray:
        """Thrust-weighted gimbal station (B, 3) of the burning engines of a batched state, else the lowest
        attached engine's."""
        weights, points = [], []
        for (si, em), on in zip(self.engines, state.engine_on):
            if on:
                weights.append(np.maximum(em.thrust(state.t - state.ignition[si], throttle), 1e-12))
                points.append(em.engine.gimbal)
        if weights:                                      # as np.average: sum(w p) / sum(w)
            total, scale = 0.0, 0.0
            for w, g in zip(weights, points):
                total, scale = total + g * w[:, None], scale + w
            return total / scale[:, None]
        candidates = [em.engine.gimbal for si, em in self.engines if si in attached]
        g = min(candidates, key=lambda g: g[0]) if candidates else np.zeros(3)
        return np.tile(g, (state.t.size, 1))


def _on_axis(x: np.ndarray) -> np.ndarray:
    """Points (B, 3) on the body axis at the stations ``x`` (B,) [m]."""
    out = np.zeros((x.size, 3))
    out[:, 0] = x
    return out
