"""The mission timeline: the mass model and the bending modes tabulated over the flight, once per vehicle.

Propellant depletion and staging do not depend on the vehicle's motion (the engines run at full
throttle), so the dynamics parameters, the thrust and the mass properties are functions of time
alone. :func:`build_timeline` evaluates :class:`~lvgym.vehicle.MassModel` and
:class:`~lvgym.vehicle.structure.ModeSchedule` on a grid (every ``dt`` seconds, every breakpoint of a
thrust table and both sides of every event), array-wise, one batch of rows per stretch between events
(:meth:`~lvgym.vehicle.MassModel.history`; the same numbers, to the last bit, as evaluating the rows one at
a time), and :class:`Timeline` interpolates it linearly, so a step
costs a table look-up instead of a mass-model evaluation and a batch of vehicles at different times
looks up its rows in one call. Event times are stored twice (the row before and the row after), and the
simulator lands its steps on them, so nothing is interpolated across a separation.

Mode data are held piecewise constant between the times the modes are recomputed (separations, and every
``mode_interval`` seconds when set). ``mode_basis`` says what becomes of the modal state at such a change:
``held`` (v0) keeps the numbers ``eta``, ``eta_dot`` as they are in the new basis; ``projected`` keeps the
deflection field: the timeline stores one transfer matrix per change (:func:`lvgym.vehicle.structure.mode_transfer`,
rows of modes above the cut-off zeroed, several changes at one time multiplied into one), the simulator
cuts its steps at the change times and applies the matrix there (:mod:`.piece`).

A vehicle file's ``tables`` (:mod:`lvgym.vehicle.timetables`) replace the stack's mass, CG and inertia and
the tabled modes' frequencies and damping in the rows (:mod:`.tabled`).

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
from lvgym.vehicle.beam import one_blas_thread
from lvgym.vehicle.massmodel import BURNING, SEPARATED, MassState
from lvgym.vehicle.structure import ModeSchedule, mode_transfer

from .tabled import apply_mass, apply_modes

MODELS = ("rigid", "slosh", "flex", "nonrigid")
MODE_BASES = ("held", "projected")
_TINY = 1e-9          # the row before an event is taken this fraction of the time before it


@dataclass(frozen=True)
class Timeline:
    """Tabulated flight of one vehicle. Rows ``t`` (n,) [s], non-decreasing, event times twice.

    ``params`` (n, n_p): dynamics parameters (:class:`~lvgym.dynamics.NonRigidModel` layout of
    ``model``); ``hold`` (n_p,) columns that are piecewise constant (mode data); ``thrust0`` (n,) [N]
    and ``exit_area`` (n,) [m^2]: thrust ``max(T_0 - A_e p_amb, 0)``; ``vectored_share`` (n,) the share of
    it the gimbal turns (:meth:`~lvgym.vehicle.MassModel.vectored_share`); ``mass`` (n,) [kg], ``cg`` (n, 3)
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
    vectored_share: np.ndarray
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
                      vectored_share=np.ascontiguousarray(self.vectored_share, dtype=float),
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
#: ``hold`` (n_p,) bool; ``thrust0`` (n,) [N]; ``exit_area`` (n,) [m^2]; ``vectored_share`` (n,) [-] the
#: share of the thrust the gimbal turns; ``stage`` (n,) lowest attached
#: stage; ``burning`` (n,) 1 while an engine burns; ``mass`` (n,) [kg]; ``phi_sensor`` (n, S, K)
#: [1/sqrt(kg)] and ``dphi_sensor`` (n, S, K) [1/(m sqrt(kg))] mode shapes and slopes at the sensor stations;
#: ``phi_strip``, ``dphi_strip`` (n, K, n_strip) at the aeroelastic strips;
#: ``event_times`` (E,) [s], each once; ``mode_change_t`` (C,) [s] and ``mode_transfer``
#: (C, K, K) the changes of the mode basis the step projects the modal state across (none: held)
Tables = namedtuple("Tables", ["t", "params", "hold", "thrust0", "exit_area", "vectored_share", "stage", "burning", "mass",
                               "phi_sensor", "dphi_sensor", "phi_strip", "dphi_strip", "event_times", "mode_change_t",
                               "mode_transfer"])


# ---------------------------------------------------------------------------- compiled look-ups (the only ones)
_FORWARD = 8              # rows locate_from_k walks forward before it bisects


@nb.njit(cache=True, nogil=True, inline="always")
def locate_k(tl_t, t):
    """Row ``i`` and weight ``w`` of time ``t`` in the timeline rows ``tl_t``: value = (1-w) row i + w
    row i+1; a time equal to an event time (stored twice) takes the row after the event."""
    n = tl_t.size
    i = np.searchsorted(tl_t, t, side="right") - 1
    return _weight_k(tl_t, min(max(i, 0), n - 2), t)


@nb.njit(cache=True, nogil=True, inline="always")
def _weight_k(tl_t, i, t):
    """``(i, w)`` of :func:`locate_k` for its row ``i``."""
    span = tl_t[i + 1] - tl_t[i]
    w = (t - tl_t[i]) / span if span > 0.0 else 0.0
    return i, min(max(w, 0.0), 1.0)


@nb.njit(cache=True, nogil=True, inline="always")
def locate_from_k(tl_t, t, hint):
    """:func:`locate_k` (the same row and weight) searched forward from the row ``hint`` (the row of an
    earlier, not later, time of the same flight: a step's pieces and sensors go forward a row or two at a
    time); a bisection when ``hint`` is not at or before ``t`` (e.g. -1) or ``t`` lies more than a few rows
    ahead."""
    n = tl_t.size
    i = hint
    if i < 0 or i > n - 2 or not tl_t[i] <= t:
        return locate_k(tl_t, t)
    for _ in range(_FORWARD):
        if i >= n - 2 or not tl_t[i + 1] <= t:         # the last row at or before t (at most n - 2)
            return _weight_k(tl_t, i, t)
        i += 1
    return locate_k(tl_t, t)


@nb.njit(cache=True, nogil=True, inline="always")
def params_k(tl_t, tl_p, hold, scale, offset, t, out):
    """Dynamics parameters at time ``t`` into ``out``: interpolated, held columns from the row in
    force, then ``* scale + offset``."""
    i, w = locate_k(tl_t, t)
    params_at_k(tl_p, hold, scale, offset, i, w, out)


@nb.njit(cache=True, nogil=True, inline="always")
def params_at_k(tl_p, hold, scale, offset, i, w, out):
    """:func:`params_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    j = i + 1 if w >= 1.0 else i
    for k in range(out.size):
        v = tl_p[j, k] if hold[k] else (1.0 - w) * tl_p[i, k] + w * tl_p[i + 1, k]
        out[k] = v * scale[k] + offset[k]


@nb.njit(cache=True, nogil=True, inline="always")
def interp_k(tl_t, values, t):
    """Linear interpolation of a timeline column ``values`` at time ``t``."""
    i, w = locate_k(tl_t, t)
    return interp_at_k(values, i, w)


@nb.njit(cache=True, nogil=True, inline="always")
def interp_at_k(values, i, w):
    """:func:`interp_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    return (1.0 - w) * values[i] + w * values[i + 1]


@nb.njit(cache=True, nogil=True, inline="always")
def held_k(tl_t, values, t):
    """The value of a piecewise-constant timeline column ``values`` in force at time ``t`` (the row
    after an event at an event time)."""
    i, w = locate_k(tl_t, t)
    return held_at_k(values, i, w)


@nb.njit(cache=True, nogil=True, inline="always")
def held_at_k(values, i, w):
    """:func:`held_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    return values[i + 1] if w >= 1.0 else values[i]


@nb.njit(cache=True, nogil=True, inline="always")
def row_in_force_k(i, w):
    """The row in force (the row after an event at an event time) at the row ``i`` and weight ``w`` of
    :func:`locate_k`."""
    return i + 1 if w >= 1.0 else i


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
                   mode_basis: str = "held", sensor_probes=()) -> Timeline:
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
    ``projected``, see the module docstring. ``sensor_probes`` [m]: further sensor stations, appended to
    ``sensor_stations`` in the timeline's ``sensor_stations``, ``phi_sensor`` and ``dphi_sensor``, read off
    each solved beam with its element shape functions and not added to its mesh (the meshed stations'
    shapes and the modes are bit for bit those of a timeline without them): the stations a dispersed IMU
    interpolates between.

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
        probes_key = tuple(np.ravel(sensor_probes).tolist())
        return cached(mass_model, (model, float(t_end), float(dt), n_modes, tuple(np.ravel(sensor_stations).tolist()),
                                   float(mode_cutoff_hz), strips_key, mode_interval, mode_basis)
                      + ((probes_key,) if probes_key else ()),
                      lambda: build_timeline(mass_model, model, t_end, dt, n_modes, sensor_stations, mode_cutoff_hz,
                                             cache=False, strip_stations=strip_stations, mode_interval=mode_interval,
                                             mode_basis=mode_basis, sensor_probes=sensor_probes))
    with one_blas_thread():          # once for all the beam solves and mode transfers of the build
        return _tabulate(mass_model, model, t_end, dt, n_modes, sensor_stations, mode_cutoff_hz, strip_stations,
                         mode_interval, mode_basis, sensor_probes)


def _tabulate(mm: MassModel, model: str, t_end: float, dt: float, n_modes: int | None, sensor_stations,
              mode_cutoff_hz: float, strip_stations, mode_interval: float | None, mode_basis: str,
              sensor_probes) -> Timeline:
    """The work of :func:`build_timeline` (arguments checked, no cache)."""
    vehicle = mm.vehicle
    meshed = np.asarray(sensor_stations, dtype=float).reshape(-1)
    probes = np.asarray(sensor_probes, dtype=float).reshape(-1)
    sensors = np.concatenate([meshed, probes])
    strips = np.zeros((len(vehicle.stages), 0)) if strip_stations is None else np.asarray(strip_stations, float)
    if strips.ndim != 2 or strips.shape[0] != len(vehicle.stages):
        raise ValueError(f"strip_stations of shape {strips.shape}: expected ({len(vehicle.stages)}, n), one row per stage")
    with_modes = model in ("flex", "nonrigid")
    K = (vehicle.structure.n_modes if n_modes is None else int(n_modes)) if with_modes else 0
    with_slosh = model in ("slosh", "nonrigid")
    N = mm.n_slosh if with_slosh else 0
    dyn = NonRigidModel(N, K)
    schedule = (ModeSchedule(mm, n_modes=K, recompute_interval=mode_interval, sensor_stations=meshed,
                             probe_stations=probes) if K > 0 else None)
    times, events = _grid(mm, t_end, dt)
    cols: dict[str, list] = {k: [] for k in ("t", "T0", "Ae", "Vs", "burn", "stage", "modes", "m_b", "r_cg", "J_b",
                                             "gimbal", "m", "cg", "J", "ms", "L", "hinge", "rest", "zeta")}
    for row_t, state in _pieces(mm, times, {t for t, _ in events}):
        props = mm.properties(state)
        T0 = mm.thrust(state, 1.0, 0.0)
        attached = [si for si, ph in enumerate(state.phase) if ph != SEPARATED]
        b = row_t.size
        cols["t"].append(row_t)
        cols["T0"].append(T0)
        cols["Ae"].append(np.full(b, float(sum(em.engine.nozzle_exit_area
                                               for (_, em), on in zip(mm.engines, state.engine_on) if on))))
        cols["Vs"].append(np.broadcast_to(mm.vectored_share(state), (b,)))
        cols["burn"].append((BURNING in state.phase) & (T0 > 0.0))
        cols["stage"].append(np.full(b, min(attached) if attached else len(state.phase) - 1))
        cols["modes"] += schedule.modes_rows(state, props) if schedule is not None else [None] * b
        for key, name in (("m_b", "m_b"), ("r_cg", "r_cg_b"), ("J_b", "J_b")) if with_slosh else \
                (("m_b", "mass"), ("r_cg", "cg"), ("J_b", "inertia")):
            cols[key].append(getattr(props, name))
        for key, name in (("gimbal", "gimbal"), ("m", "mass"), ("cg", "cg"), ("J", "inertia"), ("ms", "slosh_mass"),
                          ("L", "pendulum_length"), ("hinge", "hinge"), ("rest", "slosh_rest"),
                          ("zeta", "slosh_damping")):
            cols[key].append(getattr(props, name))
    modes_rows = cols.pop("modes")
    c = {k: np.concatenate(v) for k, v in cols.items()}
    n = c["t"].size
    apply_mass(vehicle.tables, c, events, with_slosh, N, vehicle.source)       # the file's tables (.tabled)
    tabled = vehicle.tables is not None and bool(vehicle.tables.modes) and K > 0
    md = _mode_rows(modes_rows, K, N, sensors.size, strips, c["stage"], np.inf if tabled else mode_cutoff_hz,
                    mode_basis == "projected", c["t"])
    if tabled:
        apply_modes(vehicle.tables, md, c["t"], K, mode_cutoff_hz, events, vehicle.source, modes_rows)
    m_s, L = c["ms"][:, :N], c["L"][:, :N]
    live = (m_s > 0) & (L > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        omega_s = np.where(live, np.sqrt((c["T0"] / c["m"])[:, None] / L), 0.0)
    slosh = [{"m": m_s[:, j], "length": np.where(m_s[:, j] > 0, L[:, j], 0.0), "r_hinge": c["hinge"][:, j],
              "zeta": c["zeta"][:, j], "omega": omega_s[:, j], "phi": md["phi_hinge"][:, j]} for j in range(N)]
    p = dyn.params(m_b=c["m_b"], J_b=c["J_b"], r_cg=c["r_cg"], r_gimbal=c["gimbal"], omega_modes=md["omega"],
                   zeta_modes=md["zeta"], phi_gimbal=md["phi_gimbal"], dphi_gimbal=md["dphi_gimbal"], slosh=slosh)
    lay = dyn.layout
    hold = np.zeros(lay.n_p, dtype=bool)
    for key in ("omega_modes", "zeta_modes", "phi_gimbal", "dphi_gimbal"):
        hold[lay.params[key]] = True
    for j in range(N):
        hold[lay.slosh_param(j, "phi")] = True
    changes = md["changes"]
    return Timeline(model=model, dynamics=dyn, t=c["t"], params=p, hold=hold, thrust0=c["T0"], exit_area=c["Ae"],
                    vectored_share=c["Vs"],
                    mass=c["m"], cg=c["cg"], inertia=c["J"], slosh_mass=c["ms"], burning=c["burn"], stage=c["stage"],
                    stage_names=tuple(s.name for s in vehicle.stages), slosh_names=mm.slosh_names,
                    sensor_stations=sensors, phi_sensor=md["phi_sensor"].reshape(n, sensors.size, K),
                    dphi_sensor=md["dphi_sensor"].reshape(n, sensors.size, K), strip_stations=strips,
                    phi_strip=md["phi_strip"], dphi_strip=md["dphi_strip"],
                    events=tuple((float(t), e) for t, e in events),
                    mode_change_t=np.array([t for t, _ in changes], dtype=float),
                    mode_transfer=np.array([T for _, T in changes], dtype=float).reshape(len(changes), K, K),
                    mode_interval=mode_interval, mode_basis=mode_basis)


def _pieces(mm: MassModel, times: list[float], event_times: set[float]) -> list[tuple[np.ndarray, MassState]]:
    """The rows of the timeline as ``(row times (b,) [s], batched mass state)`` pieces, one per stretch
    between events: every grid time, and before each event time > 0 also the state a moment before it
    (``_TINY`` of the time earlier, advanced from the grid time before; stored at the event's time)."""
    stretches, _ = mm.history(times)
    pieces = []
    for k, s in enumerate(stretches):
        row_t = s.t
        te = float(stretches[k + 1].t[0]) if k + 1 < len(stretches) else None
        if te is not None and te in event_times and te > 0.0:
            pre, _ = mm.advance(s.row(-1), te - _TINY * max(1.0, te))
            row_t = np.append(s.t, te)
            s = replace(s, t=np.append(s.t, pre.t), tank_mass=np.vstack([s.tank_mass, pre.tank_mass]),
                        grain_mass=np.vstack([s.grain_mass, pre.grain_mass]))
        pieces.append((row_t, s))
    return pieces


def _mode_rows(modes_rows: list, K: int, N: int, S: int, strips: np.ndarray, stage: np.ndarray, cutoff_hz: float,
               projected: bool, t: np.ndarray) -> dict[str, np.ndarray]:
    """The mode columns of the rows (each row's :class:`~lvgym.vehicle.structure.VehicleModes` or None):
    frequencies, damping, shapes and slopes at the gimbal, hinges (n, N, K) and sensors (n, S, K) with the
    modes above ``cutoff_hz`` decoupled, at the strips of each row's lowest attached ``stage`` (n, K,
    n_strip), and the changes of basis ``[(time, transfer matrix)]`` (``projected``; several changes at
    one time multiplied into one)."""
    n, n_strip = len(modes_rows), strips.shape[1]
    out = {"omega": np.zeros((n, K)), "zeta": np.zeros((n, K)), "phi_gimbal": np.zeros((n, K)),
           "dphi_gimbal": np.zeros((n, K)), "phi_hinge": np.zeros((n, N, K)), "phi_sensor": np.zeros((n, S, K)),
           "dphi_sensor": np.zeros((n, S, K)), "phi_strip": np.zeros((n, K, n_strip)),
           "dphi_strip": np.zeros((n, K, n_strip)), "changes": []}
    if K == 0:
        return out
    cut: dict[int, tuple] = {}                          # id of the modes: (modes, its decoupled version)
    on_strips: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
    changes: list[tuple[float, np.ndarray]] = []
    stages = stage.tolist()
    # the rows where the modes or the stage change (within a run of rows nothing new happens)
    starts = [0] + [i for i in range(1, n) if modes_rows[i] is not modes_rows[i - 1] or stages[i] != stages[i - 1]]
    last = None
    for i in starts:
        modes = modes_rows[i]
        if id(modes) not in cut:
            cut[id(modes)] = (modes, _cut(modes, cutoff_hz))
        if projected and last is not None and modes is not last:
            T = mode_transfer(last, modes) * _kept(modes, cutoff_hz)[:, None]
            if changes and changes[-1][0] == t[i]:          # two changes at one time: one matrix
                T = T @ changes.pop()[1]
            changes.append((float(t[i]), T))
        last = modes
        if n_strip and (id(modes), int(stages[i])) not in on_strips:
            beam, keep = modes.beam, _kept(modes, cutoff_hz)
            phi, dphi = resample_modes(strips[int(stages[i])], beam.node_stations, beam.phi_nodes.T, beam.dphi_nodes.T)
            on_strips[id(modes), int(stages[i])] = (phi * keep[:, None], dphi * keep[:, None])
    which = {key: u for u, key in enumerate(cut)}
    lengths = np.diff([*starts, n])
    index = np.repeat([which[id(modes_rows[i])] for i in starts], lengths)
    unique = [c for _, c in cut.values()]
    for key in ("omega", "zeta", "phi_gimbal", "dphi_gimbal", "phi_sensor", "dphi_sensor"):
        out[key] = np.array([getattr(m, key) for m in unique]).reshape((len(unique),) + out[key].shape[1:])[index]
    out["phi_hinge"] = np.array([m.phi_hinge[:N] for m in unique]).reshape(len(unique), N, K)[index]
    if n_strip:
        keys = list(on_strips)
        pair = {k: u for u, k in enumerate(keys)}
        at = np.repeat([pair[id(modes_rows[i]), int(stages[i])] for i in starts], lengths)
        out["phi_strip"] = np.array([on_strips[k][0] for k in keys])[at]
        out["dphi_strip"] = np.array([on_strips[k][1] for k in keys])[at]
    out["changes"] = changes
    return out
