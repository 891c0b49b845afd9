"""The mission timeline: the mass model and the bending modes tabulated over the flight, once per vehicle.

Propellant depletion and staging do not depend on the vehicle's motion (the engines run at full
throttle), so the dynamics parameters, the thrust and the mass properties are functions of time
alone. :func:`build_timeline` evaluates :class:`~lvgym.vehicle.MassModel` and
:class:`~lvgym.vehicle.structure.ModeSchedule` on a grid (every ``dt`` seconds, every breakpoint of a
thrust table and both sides of every event) and :class:`Timeline` interpolates it linearly, so a step
costs a table look-up instead of a mass-model evaluation and a batch of vehicles at different times
looks up its rows in one call. Event times are stored twice (the row before and the row after), and the
simulator lands its steps on them, so nothing is interpolated across a separation.

Mode data are held piecewise constant between the times the modes are recomputed (separations, and every
``mode_interval`` seconds when set). ``mode_basis`` says what becomes of the modal state at such a change:
``held`` (v0) keeps the numbers ``eta``, ``eta_dot`` as they are in the new basis; ``projected`` keeps the
deflection field: the timeline stores one transfer matrix per change (:func:`lvgym.vehicle.structure.mode_transfer`,
rows of modes above the cut-off zeroed, several changes at one time multiplied into one), the simulator
cuts its steps at the change times and applies the matrix there (:mod:`.piece`).

``model`` picks which parameters the dynamics core flies (thesis section 4.4):

=============  ===============================================================================
``rigid``      the rigid-equivalent stack (slosh masses frozen at rest): same mass, CG and inertia
``slosh``      the rigid body B and one pendulum per slosh tank
``flex``       the rigid-equivalent stack on its bending modes (slosh masses on the beam as rigid)
``nonrigid``   B, the pendulums and the modes, coupled (the thesis's full model)
=============  ===============================================================================
"""

from __future__ import annotations

import functools
from collections import namedtuple
from dataclasses import dataclass, replace

import numba as nb
import numpy as np

from lvgym.dynamics import NonRigidModel
from lvgym.environment.aeroelastic import resample_modes
from lvgym.errors import check_choice, check_number
from lvgym.vehicle import MassModel
from lvgym.vehicle.massmodel import BURNING, SEPARATED
from lvgym.vehicle.structure import ModeSchedule, mode_transfer

MODELS = ("rigid", "slosh", "flex", "nonrigid")
MODE_BASES = ("held", "projected")
_TINY = 1e-9          # the row before an event is taken this fraction of the time before it


@dataclass(frozen=True)
class Timeline:
    """Tabulated flight of one vehicle. Rows ``t`` (n,) [s], non-decreasing, event times twice.

    ``params`` (n, n_p): dynamics parameters (:class:`~lvgym.dynamics.NonRigidModel` layout of
    ``model``); ``hold`` (n_p,) columns that are piecewise constant (mode data); ``thrust0`` (n,) [N]
    and ``exit_area`` (n,) [m^2]: thrust ``max(T_0 - A_e p_amb, 0)``; ``mass`` (n,) [kg], ``cg`` (n, 3)
    [m], ``inertia`` (n, 3, 3) [kg m^2] of the whole stack; ``slosh_mass`` (n, N) [kg];
    ``burning`` (n,) any engine burning; ``stage`` (n,) index of the lowest attached stage;
    ``phi_sensor`` (n, S, K) mode shapes and ``dphi_sensor`` (n, S, K) slopes at the sensor stations
    ``sensor_stations`` (S,) [m]; ``strip_stations`` (n_stages, n) [m] the aeroelastic strips of each
    stage (n = 0: none) with ``phi_strip`` (n, K, n_strip) mode shapes and ``dphi_strip`` slopes at the
    strips of the row's lowest attached stage (linear between the beam's nodes);
    ``events`` ((time, description), ...); ``mode_change_t`` (C,) [s] the changes of the mode basis
    (``mode_basis="projected"``; none when ``held``) and ``mode_transfer`` (C, K, K) their matrices
    (``eta_new = T eta_old``); ``mode_interval`` [s] (None: at separations only) and ``mode_basis`` the
    options it was built with."""

    model: str
    dynamics: NonRigidModel
    t: np.ndarray
    params: np.ndarray
    hold: np.ndarray
    thrust0: np.ndarray
    exit_area: np.ndarray
    mass: np.ndarray
    cg: np.ndarray
    inertia: np.ndarray
    slosh_mass: np.ndarray
    burning: np.ndarray
    stage: np.ndarray
    stage_names: tuple[str, ...]
    slosh_names: tuple[str, ...]
    sensor_stations: np.ndarray
    phi_sensor: np.ndarray
    dphi_sensor: np.ndarray
    strip_stations: np.ndarray
    phi_strip: np.ndarray
    dphi_strip: np.ndarray
    events: tuple[tuple[float, str], ...]
    mode_change_t: np.ndarray
    mode_transfer: np.ndarray
    mode_interval: float | None = None
    mode_basis: str = "held"

    @property
    def t_end(self) -> float:
        return float(self.t[-1])

    @property
    def event_times(self) -> np.ndarray:
        return np.array(sorted({t for t, _ in self.events}))

    def locate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Row index ``i`` and weight ``w`` of the times ``t`` (B,): value = (1-w) row i + w row i+1.
        A time equal to an event time takes the row after the event (:func:`locate_k`)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        i, w = np.empty(t.size, dtype=np.int64), np.empty(t.size)
        locate_rows(self.t, t, i, w)
        return i, w

    def interp(self, name: str, t) -> np.ndarray:
        """Linear interpolation of the row quantity ``name`` at the times ``t`` (B,): shape (B, ...)
        (:func:`interp_k`)."""
        a = getattr(self, name)
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((t.size, int(np.prod(a.shape[1:], dtype=int))))
        interp_rows(self.t, np.ascontiguousarray(a, dtype=float).reshape(a.shape[0], -1), t, out)
        return out.reshape((t.size,) + a.shape[1:])

    def left(self, name: str, t) -> np.ndarray:
        """The row quantity ``name`` in force at the times ``t`` (no interpolation; the row after an
        event at an event time, :func:`held_k`)."""
        i, w = self.locate(t)
        return getattr(self, name)[np.where(w >= 1.0, i + 1, i)]

    def params_at(self, t, scale: np.ndarray | None = None, offset: np.ndarray | None = None) -> np.ndarray:
        """Dynamics parameters (B, n_p) at the times ``t`` (B,): interpolated, mode data held, then
        ``* scale + offset`` (B, n_p) when given (:func:`params_k`, as the simulator's step)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        n_p = self.params.shape[1]
        scale = np.ones((t.size, n_p)) if scale is None else np.ascontiguousarray(scale, dtype=float)
        offset = np.zeros((t.size, n_p)) if offset is None else np.ascontiguousarray(offset, dtype=float)
        out = np.empty((t.size, n_p))
        params_rows(self.t, self.params, self.hold, scale, offset, t, out)
        return out

    @functools.cached_property
    def tables(self) -> Tables:
        """The columns the compiled step and the task signals read (:class:`Tables`)."""
        return Tables(t=np.ascontiguousarray(self.t, dtype=float), params=np.ascontiguousarray(self.params),
                      hold=np.ascontiguousarray(self.hold), thrust0=np.ascontiguousarray(self.thrust0, dtype=float),
                      exit_area=np.ascontiguousarray(self.exit_area, dtype=float),
                      stage=np.ascontiguousarray(self.stage, dtype=float),
                      burning=np.ascontiguousarray(self.burning, dtype=float),
                      mass=np.ascontiguousarray(self.mass, dtype=float),
                      phi_sensor=np.ascontiguousarray(self.phi_sensor, dtype=float),
                      dphi_sensor=np.ascontiguousarray(self.dphi_sensor, dtype=float),
                      phi_strip=np.ascontiguousarray(self.phi_strip, dtype=float),
                      dphi_strip=np.ascontiguousarray(self.dphi_strip, dtype=float),
                      event_times=np.ascontiguousarray(self.event_times, dtype=float),
                      mode_change_t=np.ascontiguousarray(self.mode_change_t, dtype=float),
                      mode_transfer=np.ascontiguousarray(self.mode_transfer, dtype=float))


#: the timeline's columns as compiled code reads them: ``t`` (n,) [s] rows; ``params`` (n, n_p);
#: ``hold`` (n_p,) bool; ``thrust0`` (n,) [N]; ``exit_area`` (n,) [m^2]; ``stage`` (n,) lowest attached
#: stage; ``burning`` (n,) 1 while an engine burns; ``mass`` (n,) [kg]; ``phi_sensor`` (n, S, K)
#: [1/sqrt(kg)] and ``dphi_sensor`` (n, S, K) [1/(m sqrt(kg))] mode shapes and slopes at the sensor stations;
#: ``phi_strip``, ``dphi_strip`` (n, K, n_strip) at the aeroelastic strips;
#: ``event_times`` (E,) [s], each once; ``mode_change_t`` (C,) [s] and ``mode_transfer``
#: (C, K, K) the changes of the mode basis the step projects the modal state across (none: held)
Tables = namedtuple("Tables", ["t", "params", "hold", "thrust0", "exit_area", "stage", "burning", "mass",
                               "phi_sensor", "dphi_sensor", "phi_strip", "dphi_strip", "event_times", "mode_change_t",
                               "mode_transfer"])


# ---------------------------------------------------------------------------- compiled look-ups (the only ones)
@nb.njit(cache=True, nogil=True, inline="always")
def locate_k(tl_t, t):
    """Row ``i`` and weight ``w`` of time ``t`` in the timeline rows ``tl_t``: value = (1-w) row i + w
    row i+1; a time equal to an event time (stored twice) takes the row after the event."""
    n = tl_t.size
    i = np.searchsorted(tl_t, t, side="right") - 1
    i = min(max(i, 0), n - 2)
    span = tl_t[i + 1] - tl_t[i]
    w = (t - tl_t[i]) / span if span > 0.0 else 0.0
    return i, min(max(w, 0.0), 1.0)


@nb.njit(cache=True, nogil=True, inline="always")
def params_k(tl_t, tl_p, hold, scale, offset, t, out):
    """Dynamics parameters at time ``t`` into ``out``: interpolated, held columns from the row in
    force, then ``* scale + offset``."""
    i, w = locate_k(tl_t, t)
    j = i + 1 if w >= 1.0 else i
    for k in range(out.size):
        v = tl_p[j, k] if hold[k] else (1.0 - w) * tl_p[i, k] + w * tl_p[i + 1, k]
        out[k] = v * scale[k] + offset[k]


@nb.njit(cache=True, nogil=True, inline="always")
def interp_k(tl_t, values, t):
    """Linear interpolation of a timeline column ``values`` at time ``t``."""
    i, w = locate_k(tl_t, t)
    return (1.0 - w) * values[i] + w * values[i + 1]


@nb.njit(cache=True, nogil=True, inline="always")
def held_k(tl_t, values, t):
    """The value of a piecewise-constant timeline column ``values`` in force at time ``t`` (the row
    after an event at an event time)."""
    i, w = locate_k(tl_t, t)
    return values[i + 1] if w >= 1.0 else values[i]


@nb.njit(cache=True)
def locate_rows(tl_t, t, i_out, w_out):
    """:func:`locate_k` of every time ``t`` (B,)."""
    for b in range(t.size):
        i_out[b], w_out[b] = locate_k(tl_t, t[b])


@nb.njit(cache=True)
def interp_rows(tl_t, values, t, out):
    """:func:`interp_k` of every column of ``values`` (n, m) at every time ``t`` (B,) into ``out`` (B, m)."""
    for b in range(t.size):
        for k in range(values.shape[1]):
            out[b, k] = interp_k(tl_t, values[:, k], t[b])


@nb.njit(cache=True)
def params_rows(tl_t, tl_p, hold, scale, offset, t, out):
    """:func:`params_k` at every time ``t`` (B,) with the rows' ``scale``, ``offset`` (B, n_p)."""
    for b in range(t.size):
        params_k(tl_t, tl_p, hold, scale[b], offset[b], t[b], out[b])


def _kept(modes, cutoff_hz: float) -> np.ndarray:
    """Which modes are at or below ``cutoff_hz`` (the others are decoupled)."""
    return modes.omega <= 2.0 * np.pi * cutoff_hz


def _cut(modes, cutoff_hz: float):
    """The modes with those above ``cutoff_hz`` decoupled."""
    keep = _kept(modes, cutoff_hz)
    if keep.all():
        return modes
    return replace(modes, phi_gimbal=modes.phi_gimbal * keep, dphi_gimbal=modes.dphi_gimbal * keep,
                   phi_hinge=modes.phi_hinge * keep, phi_sensor=modes.phi_sensor * keep,
                   dphi_sensor=modes.dphi_sensor * keep)


def _grid(mm: MassModel, t_end: float, dt: float) -> tuple[list[float], list[tuple[float, str]]]:
    """Grid times and the events of the whole flight."""
    _, events = mm.advance(mm.initial_state(), t_end)
    times = set(np.linspace(0.0, t_end, max(2, int(np.ceil(t_end / dt - 1e-9)) + 1)).tolist())
    for si, em in mm.engines:
        if em.engine.thrust_table is not None:
            ign = 0.0 if si == 0 else None
            if ign is None:
                ign = next((t for t, e in events if e == f"stage {mm.vehicle.stages[si].name!r} ignition"), None)
            if ign is not None:
                times |= {ign + float(tau) for tau in em.engine.thrust_table[:, 0] if 0 <= ign + tau <= t_end}
    times |= {t for t, _ in events}
    return sorted(times), events


def build_timeline(mass_model: MassModel, model: str, t_end: float, dt: float = 0.05,
                   n_modes: int | None = None, sensor_stations=(), mode_cutoff_hz: float = np.inf,
                   cache: bool = True, strip_stations=None, *, mode_interval: float | None = None,
                   mode_basis: str = "held") -> Timeline:
    """Tabulate ``mass_model``'s vehicle from lift-off to ``t_end`` [s] for the dynamics ``model``
    (one of ``MODELS``) every ``dt`` [s] (and at every event and thrust-table breakpoint), with
    ``n_modes`` bending modes per plane (default: the vehicle file's; 0 for rigid and slosh) and
    mode slopes at ``sensor_stations`` [m].

    Modes above ``mode_cutoff_hz`` are decoupled (their shapes and slopes at the gimbal, hinges and
    sensors set to zero): they stay at rest. The simulator cuts at the Nyquist frequency of its RK4
    step, ``1 / (2 physics_dt)``: a stiff upper stage's 200 Hz mode coupled to its slosh masses makes
    a 10 ms RK4 step diverge, and no load sampled at that step could excite it faithfully.

    ``strip_stations`` (n_stages, n) [m]: the aeroelastic strips of each stage (:mod:`.strips`; None:
    none); each row tabulates the mode shapes and slopes at the strips of its lowest attached stage,
    interpolated linearly between the beam's nodes (the strips are not added to the beam's mesh, so the
    modes are those of a timeline without strips), decoupled modes zero.
    ``mode_interval`` [s]: recompute the modes also every so many seconds of flight (None: the vehicle
    file's ``structure.recompute_interval``, else at separations only); ``mode_basis``: ``held`` or
    ``projected``, see the module docstring.

    ``cache``: look the timeline up in the on-disk cache first and store it there (:mod:`.cache`: keyed by
    the vehicle's whole content, these arguments and the source of the code that builds it)."""
    if model not in MODELS:
        raise ValueError(f"model = {model!r}: one of {MODELS}")
    if not t_end > 0.0 or not dt > 0.0:
        raise ValueError(f"t_end = {t_end!r} and dt = {dt!r} must be > 0 s")
    check_choice("mode_basis", mode_basis, MODE_BASES)
    if mode_interval is not None:
        mode_interval = check_number("mode_interval", mode_interval, 0.0, 1e5, lo_open=True)
    if cache:
        from .cache import cached
        strips_key = None if strip_stations is None else np.asarray(strip_stations, float).tolist()
        return cached(mass_model, (model, float(t_end), float(dt), n_modes, tuple(np.ravel(sensor_stations).tolist()),
                                   float(mode_cutoff_hz), strips_key, mode_interval, mode_basis),
                      lambda: build_timeline(mass_model, model, t_end, dt, n_modes, sensor_stations, mode_cutoff_hz,
                                             cache=False, strip_stations=strip_stations, mode_interval=mode_interval,
                                             mode_basis=mode_basis))
    mm = mass_model
    vehicle = mm.vehicle
    sensors = np.asarray(sensor_stations, dtype=float).reshape(-1)
    strips = np.zeros((len(vehicle.stages), 0)) if strip_stations is None else np.asarray(strip_stations, float)
    if strips.ndim != 2 or strips.shape[0] != len(vehicle.stages):
        raise ValueError(f"strip_stations of shape {strips.shape}: expected ({len(vehicle.stages)}, n), one row per stage")
    with_modes = model in ("flex", "nonrigid")
    K = (vehicle.structure.n_modes if n_modes is None else int(n_modes)) if with_modes else 0
    with_slosh = model in ("slosh", "nonrigid")
    N = mm.n_slosh if with_slosh else 0
    dyn = NonRigidModel(N, K)
    schedule = ModeSchedule(mm, n_modes=K, recompute_interval=mode_interval, sensor_stations=sensors) if K > 0 else None
    projected = mode_basis == "projected"
    changes: list[tuple[float, np.ndarray]] = []          # (time, transfer matrix) of each change of basis
    last = None                                           # the modes of the previous row
    times, events = _grid(mm, t_end, dt)
    event_times = {t for t, _ in events}
    lay = dyn.layout
    rows: dict[str, list] = {k: [] for k in ("t", "p", "T0", "Ae", "m", "cg", "J", "ms", "burn", "stage", "phi",
                                                 "dphi", "phi_strip", "dphi_strip")}
    state = mm.initial_state()
    for t in times:
        samples = []
        if t in event_times and t > 0.0:
            pre, _ = mm.advance(state, t - _TINY * max(1.0, t))
            samples.append((t, pre))
        state, _ = mm.advance(state, t)
        samples.append((t, state))
        for tt, s in samples:
            props = mm.properties(s)
            on = [(si, em) for (si, em), o in zip(mm.engines, s.engine_on) if o]
            T0 = mm.thrust(s, 1.0, 0.0)
            Ae = sum(em.engine.nozzle_exit_area for _, em in on)
            if with_slosh:
                m_b, cg, J = props.m_b, props.r_cg_b, props.J_b
            else:
                m_b, cg, J = props.mass, props.cg, props.inertia
            modes = schedule.modes(s, props) if schedule is not None else None
            attached = [si for si, ph in enumerate(s.phase) if ph != SEPARATED]
            lowest = min(attached) if attached else len(s.phase) - 1
            if modes is not None and strips.shape[1]:
                beam, keep = modes.beam, _kept(modes, mode_cutoff_hz)
                on_strips = resample_modes(strips[lowest], beam.node_stations, beam.phi_nodes.T, beam.dphi_nodes.T)
                rows["phi_strip"].append(on_strips[0] * keep[:, None])
                rows["dphi_strip"].append(on_strips[1] * keep[:, None])
            else:
                rows["phi_strip"].append(np.zeros((K, strips.shape[1])))
                rows["dphi_strip"].append(np.zeros((K, strips.shape[1])))
            if projected and modes is not None:
                if last is not None and modes is not last:
                    T = mode_transfer(last, modes) * (modes.omega <= 2.0 * np.pi * mode_cutoff_hz)[:, None]
                    if changes and changes[-1][0] == tt:          # two changes at one time: one matrix
                        T = T @ changes.pop()[1]
                    changes.append((tt, T))
                last = modes
            if modes is not None:
                modes = _cut(modes, mode_cutoff_hz)
            slosh = []
            for j in range(N):
                m_s, L = props.slosh_mass[j], props.pendulum_length[j]
                accel = T0 / props.mass
                slosh.append({"m": m_s, "length": L if m_s > 0 else 0.0, "r_hinge": props.hinge[j],
                              "zeta": props.slosh_damping[j],
                              "omega": np.sqrt(accel / L) if (m_s > 0 and L > 0) else 0.0,
                              "phi": modes.phi_hinge[j] if modes is not None else np.zeros(0)})
            p = dyn.params(m_b=m_b, J_b=J, r_cg=cg, r_gimbal=props.gimbal,
                           omega_modes=modes.omega if modes is not None else (),
                           zeta_modes=modes.zeta if modes is not None else (),
                           phi_gimbal=modes.phi_gimbal if modes is not None else (),
                           dphi_gimbal=modes.dphi_gimbal if modes is not None else (), slosh=slosh)
            rows["t"].append(tt)
            rows["p"].append(p)
            rows["T0"].append(T0)
            rows["Ae"].append(Ae)
            rows["m"].append(props.mass)
            rows["cg"].append(props.cg)
            rows["J"].append(props.inertia)
            rows["ms"].append(props.slosh_mass)
            rows["burn"].append(any(ph == BURNING for ph in s.phase) and T0 > 0.0)
            rows["stage"].append(lowest)
            for key, name in (("phi", "phi_sensor"), ("dphi", "dphi_sensor")):
                rows[key].append(getattr(modes, name) if modes is not None and sensors.size
                                 else np.zeros((sensors.size, K)))
    hold = np.zeros(lay.n_p, dtype=bool)
    for key in ("omega_modes", "zeta_modes", "phi_gimbal", "dphi_gimbal"):
        hold[lay.params[key]] = True
    for j in range(N):
        hold[lay.slosh_param(j, "phi")] = True
    return Timeline(model=model, dynamics=dyn, t=np.array(rows["t"]), params=np.array(rows["p"]), hold=hold,
                    thrust0=np.array(rows["T0"]), exit_area=np.array(rows["Ae"]), mass=np.array(rows["m"]),
                    cg=np.array(rows["cg"]), inertia=np.array(rows["J"]), slosh_mass=np.array(rows["ms"]),
                    burning=np.array(rows["burn"]), stage=np.array(rows["stage"]),
                    stage_names=tuple(s.name for s in vehicle.stages), slosh_names=mm.slosh_names,
                    sensor_stations=sensors,
                    phi_sensor=np.array(rows["phi"]).reshape(len(rows["t"]), sensors.size, K),
                    dphi_sensor=np.array(rows["dphi"]).reshape(len(rows["t"]), sensors.size, K),
                    strip_stations=strips, phi_strip=np.array(rows["phi_strip"]).reshape(len(rows["t"]), K, strips.shape[1]),
                    dphi_strip=np.array(rows["dphi_strip"]).reshape(len(rows["t"]), K, strips.shape[1]),
                    events=tuple((float(t), e) for t, e in events),
                    mode_change_t=np.array([t for t, _ in changes], dtype=float),
                    mode_transfer=np.array([T for _, T in changes], dtype=float).reshape(len(changes), K, K),
                    mode_interval=mode_interval, mode_basis=mode_basis)
