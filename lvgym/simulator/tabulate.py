"""Building a :class:`~.timeline.Timeline`: the mass model and the bending modes of one vehicle evaluated on
the timeline's grid (every ``dt`` seconds, every breakpoint of a thrust table and both sides of every event),
one batch of rows per stretch between events, the vehicle file's ``tables`` applied (:mod:`.tabled`), the
modes above a cut-off decoupled; looked up first in the on-disk cache (:mod:`.cache`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lvgym.dynamics import NonRigidModel
from lvgym.environment.aeroelastic import resample_modes
from lvgym.errors import check_choice, check_number
from lvgym.vehicle import MassModel
from lvgym.vehicle.beam import one_blas_thread
from lvgym.vehicle.massmodel import BURNING, SEPARATED, MassState
from lvgym.vehicle.structure import ModeSchedule, mode_transfer

from .cache import cached
from .tabled import apply_mass, apply_modes
from .timeline import MODE_BASES, MODELS, Timeline

__all__ = ["build_timeline"]

_TINY = 1e-9          # the row before an event is taken this fraction of the time before it


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
