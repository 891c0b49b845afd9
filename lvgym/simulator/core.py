"""The simulator: a vehicle, its environment and the dynamics core, flown together over time.

:class:`Simulator` composes a vehicle file (mass model, staging, bending modes, through a
:class:`~.timeline.Timeline`), the environment models (launch site, gravity, atmosphere, wind,
aerodynamics, through the compiled :mod:`.flight` loads) and the dynamics core, for one vehicle or a
batch of them that may be at different times. It knows nothing of rewards or observation spaces. Besides
the vehicle and the model it takes four frozen specs (:mod:`.spec`): the launch (site, rail), the
environment's models, what the timeline tabulates (or a prebuilt timeline) and how the physics is stepped.

>>> from lvgym.simulator import Simulator, TimelineSpec
>>> sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=5.0))
>>> data = sim.reset()                          # one vehicle on the pad: its state, a SimData
>>> events = sim.step(data, [[0.0, 0.0]], 1.0)  # gimbal (pitch, yaw) [rad] held for 1 s
>>> bool(sim.conditions(data, "altitude")[0] > 10.0)
True
>>> bool(sim.view(data).t[0] == 1.0)            # the same rows, read by name
True

Stepping. :meth:`Simulator.step` advances every row by ``duration`` seconds in one compiled call
(:mod:`.advance`): physics steps of at most ``physics_dt``, cut at every event time (burnout,
separation, ignition, tank empty) of that row. The mass properties, slosh and mode parameters and the
thrust ``T_0`` are evaluated at the middle of each piece and held over it. When the CG of the rigid
body moves within the structure between pieces, the state is shifted so that the structure stays where
it was (:meth:`NonRigidModel.shift_cg`). An optional gimbal :class:`~.servo.Servo` moves at every
physics step. Large batches are split over threads.

State as a value. Everything that changes during a flight is in a :class:`~.data.SimData` (one row per
vehicle) that :meth:`Simulator.reset` returns; the simulator itself holds only what does not change
during a flight (the vehicle, its timeline, the environment models, the rail, the servo). Every method
that changes or reads rows takes that value explicitly: :meth:`Simulator.step` and
:meth:`Simulator.reset_rows` change it in place, the read-outs (:meth:`Simulator.conditions`,
:meth:`Simulator.state`, :meth:`Simulator.slosh_angles`, ...) read it, and :meth:`Simulator.view` binds
them to one value (:class:`~.view.SimView`). :func:`.data.take` / :func:`.data.put` copy rows out and
back: a restored row flies on bit for bit as the original would have.

Lift-off. The vehicle starts on the pad, axis along the launch rail (``elevation_deg`` above the
horizon towards ``site.azimuth_deg``), and is held there while the thrust cannot lift it. It then slides
along the rail without rotating with respect to the Earth until the structure has travelled
``rail_length`` [m]; events ``lift-off`` and ``rail exit`` mark both moments.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from lvgym.environment import LaunchSite, make
from lvgym.environment.earth import WGS84_OMEGA, dcm_to_quat
from lvgym.errors import ConfigError, check_choice
from lvgym.rotations import quat_to_dcm_batch
from lvgym.vehicle import MassModel, Vehicle, load_vehicle

from . import data as simdata
from .advance import StepSetup, advance_range, conditions_rows, constrain_k, slosh_angles_range
from .data import SimData
from .flight import flight_conditions_batch, flight_loads, pack_context, stack_contexts
from .imu import IMU_OFF, Imu
from .layouts import ACTUATOR, CONDITIONS, CONTEXT, DISPERSION, IMU_STATE, RAIL, RAIL_STATE, RS
from .piece import SLOSH_FREQUENCIES
from .servo import DIRECT, Servo
from .spec import SITES, EnvironmentSpec, LaunchSpec, PhysicsSpec, TimelineSpec
from .strips import StripSetup, strip_stations
from .threads import ROWS_PER_THREAD, Kernel, default_threads, pool
from .view import SimView
from .tabulate import build_timeline
from .timeline import MODELS, Timeline
from .vehicleaero import aeroelastic_strips, stage_aerodynamics, vehicle_strips

_ADVANCE, _SLOSH = Kernel(advance_range), Kernel(slosh_angles_range)


def dcm_batch(q: np.ndarray) -> np.ndarray:
    """``C_ib`` (B, 3, 3) of the quaternions ``q_bi`` (B, 4)."""
    out = np.empty((q.shape[0], 3, 3))
    quat_to_dcm_batch(np.ascontiguousarray(q, dtype=float), out)
    return out


class Simulator:
    """A vehicle flown through its environment, one row per vehicle of a batch.

    Parameters
    ----------
    vehicle: a shipped vehicle name, a YAML path or a :class:`~lvgym.vehicle.Vehicle`.
    model: ``rigid``, ``slosh``, ``flex`` or ``nonrigid`` (see :mod:`.timeline`).
    launch: a :class:`~.spec.LaunchSpec` (site, rail elevation and length; default Andoya, vertical, no rail).
    environment: an :class:`~.spec.EnvironmentSpec` (gravity, atmosphere, wind, aerodynamic models, the
        aeroelastic strip loads).
    timeline: a :class:`~.spec.TimelineSpec` (what to tabulate: mission time, modes, sensor stations, ...),
        or a prebuilt :class:`Timeline` to share between simulators, whose options are then the simulator's
        (with the aeroelastic loads on, built with :func:`aeroelastic_strips`' stations).
    physics: a :class:`~.spec.PhysicsSpec` (largest RK4 step, slosh damper frequency, threads).
    servo: a :class:`~.servo.Servo` moving the gimbal at every physics step (default None: the gimbal takes
        the command at once).
    imu: an :class:`~.imu.Imu` (its ``sensor`` indexes the timeline's sensor stations) whose gyro and
        accelerometer filters are advanced at every physics step into ``data.imu`` (default None: no IMU; a
        step must then last a whole number of ``physics_dt``).
    """

    def __init__(self, vehicle: str | Vehicle = "smile", model: str = "nonrigid", *,
                 launch: LaunchSpec = LaunchSpec(), environment: EnvironmentSpec = EnvironmentSpec(),
                 timeline: TimelineSpec | Timeline = TimelineSpec(), physics: PhysicsSpec = PhysicsSpec(),
                 servo: Servo | None = None, imu: Imu | None = None) -> None:
        check_choice("model", model, MODELS)
        for key, value, kinds in (("launch", launch, (LaunchSpec,)), ("environment", environment, (EnvironmentSpec,)),
                                  ("timeline", timeline, (TimelineSpec, Timeline)),
                                  ("physics", physics, (PhysicsSpec,))):
            if not isinstance(value, kinds):
                raise ConfigError(key, value, "a " + " or a ".join(k.__name__ for k in kinds))
        self.launch, self.environment, self.physics = launch, environment, physics
        self.vehicle = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
        self.model = model
        self.site: LaunchSite = launch.launch_site()
        env = environment
        self.gravity = make("gravity", env.gravity) if isinstance(env.gravity, (str, dict)) else env.gravity
        self.atmosphere = (make("atmosphere", env.atmosphere) if isinstance(env.atmosphere, (str, dict))
                           else env.atmosphere)
        self.wind = env.wind
        self.stage_aerodynamics = stage_aerodynamics(self.vehicle, env.aerodynamics)
        self.aerodynamics = self.stage_aerodynamics[0]
        self.aeroelastic = bool(self.vehicle.structure.aeroelastic if env.aeroelastic is None else env.aeroelastic)
        strips = (vehicle_strips(self.vehicle, self.stage_aerodynamics)
                  if self.aeroelastic and self.aerodynamics is not None else None)
        stations = None if strips is None else strip_stations(strips)
        self.physics_dt = physics.physics_dt
        self.elevation = math.radians(launch.elevation_deg)
        self.rail_length = launch.rail_length
        self.slosh_frequency = physics.slosh_frequency
        if isinstance(timeline, Timeline):
            if timeline.model != model:
                raise ConfigError("timeline", f"a timeline of model {timeline.model!r}", f"one of model {model!r}")
            self.timeline = timeline
        else:
            self.timeline = build_timeline(MassModel(self.vehicle, timeline.cg_convention), model, timeline.t_end,
                                           timeline.timeline_dt, timeline.n_modes, timeline.sensor_stations,
                                           0.5 / self.physics_dt, strip_stations=stations,
                                           mode_interval=timeline.mode_interval, mode_basis=timeline.mode_basis)
        self.dynamics = self.timeline.dynamics
        K = self.dynamics.n_modes
        if stations is not None and K > 0 and not np.array_equal(self.timeline.strip_stations, stations):
            raise ConfigError("timeline", "a timeline without mode shapes at the aeroelastic strips",
                              "one built with strip_stations=aeroelastic_strips(...), or "
                              "EnvironmentSpec(aeroelastic=False)")
        #: the strip models in force (one per stage), or None: no aeroelastic loads
        self.strips = None if strips is None or K == 0 else StripSetup(strips, K, self.dynamics.n_slosh)
        self.layout = self.dynamics.layout
        self._i_cg = self.layout.params["r_cg"].start
        self._i_slosh_m = [self.layout.slosh_param(j, "m").start for j in range(self.dynamics.n_slosh)]
        # launch attitude: the pad frame tilted from the vertical towards downrange (+z_b) about y_b
        tilt = math.pi / 2 - self.elevation
        R = np.array([[math.cos(tilt), 0.0, math.sin(tilt)], [0.0, 1.0, 0.0], [-math.sin(tilt), 0.0, math.cos(tilt)]])
        self.C_ib0 = self.site.C_ib0 @ R
        self.q_bi0 = dcm_to_quat(self.C_ib0)
        self.omega_e = 0.0 if self.site.flat_earth else WGS84_OMEGA
        self.rail = self._rail_vector()
        self.servo = servo
        self.imu = imu
        if imu is not None and not all(0 <= i < self.timeline.sensor_stations.size for i in (imu.sensor, *imu.probes)):
            raise ConfigError("imu", f"sensor {imu.sensor}, probes {imu.probes}",
                              f"sensor stations of the timeline (it has {self.timeline.sensor_stations.size})")
        self.threads = physics.threads if physics.threads is not None else default_threads()
        self.tables = self.timeline.tables
        self.setup = StepSetup(rail=self.rail, servo=DIRECT if servo is None else servo.params(),
                               physics_dt=self.physics_dt, n_slosh=self.dynamics.n_slosh,
                               n_modes=self.dynamics.n_modes, n_u=self.layout.n_u,
                               slosh_frequency=SLOSH_FREQUENCIES.index(self.slosh_frequency),
                               imu=IMU_OFF if imu is None else imu.params(self.physics_dt))
        self._event_times_all = np.array([t for t, _ in self.timeline.events], dtype=float)

    # ------------------------------------------------------------------------------ the rows
    def new_data(self, batch: int) -> SimData:
        """Zeroed rows for ``batch`` vehicles (call :meth:`reset_rows` on them before flying)."""
        return simdata.allocate(batch, self.layout.n_x, self.layout.n_p)

    def view(self, data: SimData) -> SimView:
        """The read-outs of the rows ``data`` by name (:class:`~.view.SimView`: ``.t``, ``.x``,
        ``.conditions("qbar")``, ``.state("omega_bi_b")``, ``.gimbal``, ...; views of ``data``'s arrays)."""
        return SimView(self, data)

    # ------------------------------------------------------------------------------ set-up
    def _wind_params(self, wind: Any, rng: np.random.Generator) -> np.ndarray:
        model = make("wind", wind) if isinstance(wind, (str, dict)) else wind
        model.reset(rng)
        return model.params

    def reset(self, batch: int = 1, rng: np.random.Generator | None = None, winds: Sequence[Any] | None = None,
              misalignment: np.ndarray | None = None, param_scale: np.ndarray | None = None,
              param_offset: np.ndarray | None = None, dispersion: np.ndarray | None = None,
              servo_dispersion: np.ndarray | None = None, imu_station: np.ndarray | None = None) -> SimData:
        """``batch`` new vehicles on the pad at t = 0: a new :class:`~.data.SimData` (see
        :meth:`reset_rows` for the options)."""
        B = int(batch)
        if B < 1:
            raise ValueError(f"batch = {batch!r}: at least one vehicle")
        return self.reset_rows(self.new_data(B), np.arange(B), rng, winds, misalignment, param_scale, param_offset,
                               dispersion=dispersion, servo_dispersion=servo_dispersion, imu_station=imu_station)

    def reset_rows(self, data: SimData, rows: Any,
                   rng: np.random.Generator | Sequence[np.random.Generator] | None = None,
                   winds: Sequence[Any] | None = None, misalignment: np.ndarray | None = None,
                   param_scale: np.ndarray | None = None, param_offset: np.ndarray | None = None,
                   dispersion: np.ndarray | None = None, servo_dispersion: np.ndarray | None = None,
                   imu_station: np.ndarray | None = None) -> SimData:
        """Put the vehicles ``rows`` back on the pad at t = 0; the others are untouched.

        ``rng``: one generator, or one per row, for whatever is random (the wind models' ``reset``);
        ``winds``: one wind model (name, mapping or model) per row (default: the simulator's ``wind``);
        ``misalignment`` (R, 2) [rad] fixed thrust misalignment (pitch, yaw); ``param_scale`` /
        ``param_offset`` (R, n_p): a row flies ``timeline params * scale + offset`` (dispersions of mass,
        CG, inertia, slosh damping, bending frequencies); ``dispersion`` (R, n) the rows' load dispersions
        (layout :data:`.layouts.DISPERSION`; default neutral); ``servo_dispersion`` (R, 2) the rows' servo
        natural-frequency factor [-] and delay [physics steps] (default 1 and 0); ``imu_station`` (R,) [m] the
        rows' IMU station shifts along +x_b (default 0: the nominal station; with an IMU only, within the
        stations its ``probes`` tabulate, :meth:`.imu.Imu.placement`). ``data``: the rows (changed in
        place); returns them (a new value when the context had to widen: use the returned one)."""
        d = data
        rows = np.atleast_1d(np.asarray(rows, dtype=int))
        R = rows.size
        rngs = list(rng) if isinstance(rng, (list, tuple)) else [rng] * R
        rngs = [np.random.default_rng() if g is None else g for g in rngs]
        winds = [self.wind] * R if winds is None else list(winds)
        if len(winds) != R or len(rngs) != R:
            raise ValueError(f"{len(winds)} winds and {len(rngs)} generators for {R} rows")
        if self.aerodynamics is None:
            aero = None
        else:
            args = {id(m): m.kernel_args() for m in self.stage_aerodynamics}
            aero = [args[id(m)] for m in self.stage_aerodynamics]
        ctx = [pack_context(self.site.params, self.gravity.params, self.atmosphere.params,
                            self._wind_params(w, g), aero, self.strips) for w, g in zip(winds, rngs)]
        d = simdata.widen(d, max(r.size for r in ctx))
        d.ctx[rows] = stack_contexts(ctx + [np.zeros(d.ctx.shape[1])])[:R]
        n_p = self.layout.n_p
        d.scale[rows] = 1.0 if param_scale is None else np.broadcast_to(param_scale, (R, n_p))
        d.offset[rows] = 0.0 if param_offset is None else np.broadcast_to(param_offset, (R, n_p))
        if misalignment is not None:
            self.misalignment(d)[rows] = np.broadcast_to(np.asarray(misalignment, float), (R, 2))
        if dispersion is not None:
            CONTEXT.view(d.ctx[:, :CONTEXT.size], "dispersion")[rows] = np.broadcast_to(
                np.asarray(dispersion, float), (R, DISPERSION.size))
        d.t[rows] = 0.0
        d.p[rows] = self.timeline.params_at(d.t[rows], d.scale[rows], d.offset[rows])
        d.x[rows] = self.layout.zeros_state(R)
        d.rail_state[rows] = RAIL_STATE.pack({"on": 1.0, "t_lift": np.nan, "t_exit": np.nan})
        d.failed[rows] = False
        d.actuator[rows] = 0.0
        if servo_dispersion is not None:
            sd = np.broadcast_to(np.asarray(servo_dispersion, float), (R, 2))
            if np.any(sd[:, 0] <= 0.0) or np.any(sd[:, 1] < 0.0) or np.any(sd[:, 1] != np.round(sd[:, 1])):
                raise ValueError(f"servo_dispersion = {sd!r}: frequency factors > 0 and whole delays >= 0 steps")
            ACTUATOR.view(d.actuator, "frequency_shift")[rows] = sd[:, :1] - 1.0
            ACTUATOR.view(d.actuator, "delay")[rows] = sd[:, 1:]
        d.x_cg0[rows] = d.p[rows, self._i_cg]
        self._place_on_pad(rows, d)
        q_si = self.layout.view(d.x, "state", "q_si")
        q_si[rows] = d.x[rows][:, None, self.layout.state["q_bi"]]
        self.update_conditions(d, rows)
        if self.imu is not None:
            d.imu[rows] = self._imu_at_rest(rows, d)
            shift = np.zeros(R) if imu_station is None else np.broadcast_to(np.asarray(imu_station, float), (R,))
            IMU_STATE.view(d.imu, "station")[rows] = self.imu.placement(shift, self.timeline.sensor_stations)
        elif imu_station is not None and np.any(np.asarray(imu_station) != 0.0):
            raise ValueError("imu_station: a shifted IMU station needs a simulator with an IMU (imu=)")
        return d

    def _imu_at_rest(self, rows: np.ndarray, d: SimData) -> np.ndarray:
        """IMU filter states of ``rows`` at rest on the pad: the body rate (the Earth's) and the lateral
        specific force of a body turning with the Earth, ``C_bi (omega_e x (omega_e x r) - g)``."""
        lay = self.layout.state
        r = d.x[rows][:, lay["r_zw_i"]]
        a_i = -self.omega_e ** 2 * np.stack([r[:, 0], r[:, 1], np.zeros(rows.size)], axis=1)
        f_b = np.einsum("bji,bj->bi", dcm_batch(d.x[rows][:, lay["q_bi"]]),
                        a_i - CONDITIONS.view(d.conditions[rows], "g_i"))
        return Imu.rest_state(d.x[rows][:, lay["omega_bi_b"]], f_b[:, 1:])

    def _rail_vector(self) -> np.ndarray:
        return RAIL.pack({"omega_e": self.omega_e, "x_base": -self.vehicle.length, "length": self.rail_length,
                          "r_pad_e": self.site.initial_state(0.0)[0], "axis_e": self.C_ib0[:, 0],
                          "q_bi0": self.q_bi0})

    def _place_on_pad(self, rows: np.ndarray, d: SimData) -> None:
        """Put ``rows`` at the rail's start at t = 0, at rest relative to the Earth."""
        lay = self.layout.state
        rail = RAIL.view
        h0 = d.x_cg0[rows] - rail(self.rail, "x_base")
        r = rail(self.rail, "r_pad_e")[None, :] + h0[:, None] * rail(self.rail, "axis_e")[None, :]
        d.x[rows, lay["r_zw_i"]] = r
        d.x[rows, lay["v_zw_i"]] = np.cross([0.0, 0.0, self.omega_e], r)
        for b in rows:
            constrain_k(d.x[b], 0.0, self.rail, d.x_cg0[b], d.p[b, self._i_cg], d.rail_state[b])

    # ------------------------------------------------------------------------------ stepping
    def _chunks(self, batch: int) -> list[tuple[int, int]]:
        """Row ranges run on separate threads (one range for small batches); kept until the batch
        size or the thread count changes (several compiled kernels run per step)."""
        key = (batch, self.threads)
        if getattr(self, "_chunk_key", None) != key:
            k = max(1, min(self.threads, batch // ROWS_PER_THREAD))
            edges = np.linspace(0, batch, k + 1).astype(int)
            self._chunk_list = [(int(a), int(z)) for a, z in zip(edges[:-1], edges[1:]) if z > a]
            self._chunk_key = key
        return self._chunk_list

    def run_rows(self, fn: Kernel, batch: int, *args: Any) -> None:
        """Call ``fn(lo, hi, *args)`` over the row ranges of a batch of ``batch`` rows, on the
        simulator's threads when it has more than one range; ``fn`` is a :class:`Kernel` of a compiled
        ``nogil`` function that touches only rows ``lo:hi`` of its batch arrays."""
        chunks = self._chunks(batch)
        if len(chunks) == 1:
            fn(0, batch, *args)
            return
        list(pool(self.threads).map(lambda ch: fn(ch[0], ch[1], *args), chunks))

    def step(self, data: SimData, gimbal: Any, duration: float, moment: Any = None, *,
             force: Any = None) -> list[tuple[tuple[float, str], ...]]:
        """Advance every row by ``duration`` [s] with the gimbal command ``gimbal`` (B, 2) [rad]
        (pitch, yaw; see :mod:`.flight` for the signs), a commanded body moment ``moment`` (B, 3)
        [N m] (reaction control; default none) and a body force at the CG ``force`` (B, 3) [N], body
        axes (settling thrust; default none) held; returns each row's events, a tuple of ``(time [s],
        name)`` in time order (the empty tuple for a row without: no object per row and step). ``data``:
        the rows, changed in place.

        Without a servo the gimbal takes the command at once; with one (``servo=``) it moves towards
        it at every physics step. The actuator rows then hold the integrals of |gimbal| [rad s] and
        |gimbal rate| [rad] (both axes summed) over the period (:meth:`effort`)."""
        d = data
        B = int(d.t.size)
        if B == 0:
            raise RuntimeError("call reset() before step()")
        if not duration > 0.0:
            raise ValueError(f"duration = {duration!r}: must be > 0 s")
        if self.imu is not None:
            n = max(1, math.ceil(duration / self.physics_dt - 1e-9))
            if abs(duration / n - self.physics_dt) > 1e-9 * self.physics_dt:
                raise ValueError(f"duration = {duration!r}: with an IMU, a whole number of physics_dt = "
                                 f"{self.physics_dt} (its filters are discretised for that step)")
        ACTUATOR.view(d.actuator, "command")[:] = np.broadcast_to(np.asarray(gimbal, dtype=float), (B, 2))
        CONTEXT.view(d.ctx[:, :CONTEXT.size], "moment_b")[:] = 0.0 if moment is None else np.broadcast_to(moment, (B, 3))
        CONTEXT.view(d.ctx[:, :CONTEXT.size], "force_b")[:] = 0.0 if force is None else np.broadcast_to(force, (B, 3))
        t0 = d.t.copy()
        rs = d.rail_state
        i_on, i_lifted = RS.on, RS.lifted
        lifted0, on0 = rs[:, i_lifted].copy(), rs[:, i_on].copy()
        self.run_rows(_ADVANCE, B, flight_loads, d, self.tables, self.setup, float(duration))
        events: list[tuple[tuple[float, str], ...]] = [()] * B      # a row without events: the empty tuple
        ev_t = self._event_times_all
        hit = (ev_t[None, :] > t0[:, None]) & (ev_t[None, :] <= d.t[:, None] + 1e-12)
        new_lift = rs[:, i_lifted] > lifted0
        new_exit = (rs[:, i_on] < on0) & (self.rail_length > 0.0)
        for b in np.flatnonzero(hit.any(axis=1) | new_lift | new_exit):
            evs = [self.timeline.events[i] for i in np.flatnonzero(hit[b])]
            if new_lift[b]:
                evs.append((float(rs[b, RS.t_lift]), "lift-off"))
            if new_exit[b]:
                evs.append((float(rs[b, RS.t_exit]), "rail exit"))
            events[b] = tuple(sorted(evs, key=lambda e: e[0]))
        return events

    def update_conditions(self, data: SimData, rows: Any = None) -> None:
        """Recompute the flight conditions (and the thrust and aerodynamic block in force) of the rows
        ``rows`` (default all) of ``data`` at their current times, e.g. after their state was written by hand."""
        idx = np.arange(data.t.size) if rows is None else np.atleast_1d(np.asarray(rows, dtype=np.int64))
        conditions_rows(idx.astype(np.int64), data, self.tables)

    def conditions_ahead(self, data: SimData, horizons_s: Sequence[float]) -> np.ndarray:
        """The flight conditions (K, B, N_COND) (layout :data:`.layouts.CONDITIONS`) that the rows of ``data``
        meet ``horizons_s`` (K,) [s] ahead with their attitude, rates, structure and thrust as they are now:
        the CG carried on along its inertial velocity and the clock advanced, so that the wind (the frozen
        turbulence field, the gust) and the air are those the vehicle is about to fly into. A preview, not a
        prediction of the flight: it writes nothing of the rows' state, conditions or parameters; the models'
        scratch in their context (the scratch matrix, the gravity kernel's work block, the thrust angle cache,
        keyed on the angles) is overwritten as at every evaluation of the loads, and the flight stays the same
        to the bit (tests/test_privileged.py)."""
        out = np.empty((len(horizons_s),) + data.conditions.shape)
        v_zw_i = self.state(data, "v_zw_i")
        x = data.x.copy()
        r_zw_i = self.layout.view(x, "state", "r_zw_i")
        r0 = r_zw_i.copy()
        for k, h in enumerate(horizons_s):
            r_zw_i[:] = r0 + float(h) * v_zw_i
            flight_conditions_batch(data.t + float(h), x, data.p, data.ctx, out[k])
        return out

    # ------------------------------------------------------------------------------ read-outs
    # of explicit rows ``data`` (views: writing them writes the rows); SimView holds them by name
    @staticmethod
    def gimbal(data: SimData) -> np.ndarray:
        """Gimbal angles (B, 2) [rad] (a view)."""
        return ACTUATOR.view(data.actuator, "gimbal")

    @staticmethod
    def gimbal_rate(data: SimData) -> np.ndarray:
        """Gimbal rates (B, 2) [rad/s] (a view)."""
        return ACTUATOR.view(data.actuator, "gimbal_rate")

    @staticmethod
    def command(data: SimData) -> np.ndarray:
        """Gimbal command held over the last step (B, 2) [rad] (a view)."""
        return ACTUATOR.view(data.actuator, "command")

    @staticmethod
    def load_dispersion(data: SimData, name: str) -> np.ndarray:
        """The rows' load dispersion ``name`` (B,) (layout :data:`.layouts.DISPERSION`: ``thrust_scale``,
        ``axial_scale``, ``normal_scale``, ``cp_shift``), a view: writing it changes the loads from the next
        step on (a thrust loss in flight)."""
        return data.ctx[:, CONTEXT.slice("dispersion").start + DISPERSION.index(name)]

    @staticmethod
    def misalignment(data: SimData) -> np.ndarray:
        """The rows' fixed thrust misalignment (B, 2) [rad] (pitch, yaw), a view: writing it turns the thrust from
        the next step on (a nozzle damaged in flight)."""
        return CONTEXT.view(data.ctx[:, :CONTEXT.size], "misalignment")

    @staticmethod
    def vectored_share(data: SimData) -> np.ndarray:
        """The share of the thrust the gimbal turns (B,) of the rows' current timeline piece (the vehicle's
        ``vectored_share``, :meth:`~lvgym.vehicle.MassModel.vectored_share`; 0 before the first step)."""
        return data.ctx[:, CONTEXT.index("vectored_share")].copy()

    @staticmethod
    def effort(data: SimData) -> np.ndarray:
        """Integrals of |gimbal| [rad s] and |gimbal rate| [rad] over the last period (B, 2)."""
        a = data.actuator
        return np.stack([a[:, ACTUATOR.index("effort")], a[:, ACTUATOR.index("effort_rate")]], axis=1)

    @staticmethod
    def on_rail(data: SimData) -> np.ndarray:
        """Whether each row is still held on the pad or rail (B,)."""
        return data.rail_state[:, RS.on] != 0.0

    @staticmethod
    def lifted(data: SimData) -> np.ndarray:
        """Whether each row has lifted off (B,)."""
        return data.rail_state[:, RS.lifted] != 0.0

    @staticmethod
    def rail_s(data: SimData) -> np.ndarray:
        """Travel of the structure along the rail [m] (B,) (frozen at rail exit; a view)."""
        return data.rail_state[:, RS.s]

    @staticmethod
    def conditions(data: SimData, name: str) -> np.ndarray:
        """Flight condition ``name`` (an entry of :data:`.layouts.CONDITIONS`) of every row of ``data`` at
        its current time (a view; (B,) for a scalar entry)."""
        if name not in CONDITIONS:
            raise KeyError(f"condition {name!r}: one of {sorted(CONDITIONS.names)}")
        out = CONDITIONS.view(data.conditions, name)
        return out[:, 0] if out.shape[1] == 1 else out

    def state(self, data: SimData, name: str) -> np.ndarray:
        """State entry ``name`` of every row of ``data`` (a view, see :class:`lvgym.dynamics.Layout`)."""
        return self.layout.view(data.x, "state", name)

    def slosh_angles(self, data: SimData) -> np.ndarray:
        """Pendulum deflections from the body axis (B, N, 2) [rad]: the rod's angle in the x-y and x-z
        body planes (0 at rest, hanging aft); NaN for a pendulum without mass (an empty or dropped
        tank, whose frozen state means nothing)."""
        N, B = self.dynamics.n_slosh, int(data.t.size)
        out = np.zeros((B, N, 2))
        if N:
            self.run_rows(_SLOSH, B, data.x, N, self.dynamics.n_modes, out)
            out[data.p[:, self._i_slosh_m] <= 0.0] = np.nan
        return out

    def lateral_cg_offset(self, data: SimData) -> np.ndarray:
        """Lateral offset of the whole vehicle's CG from the body axis (B, 2) [m] (y_b, z_b): the slosh
        masses out of their rest position (free-free modes leave the CG of B on the axis)."""
        x, p = data.x, data.p
        if self.dynamics.n_slosh == 0:
            return np.zeros((x.shape[0], 2))
        r_j, _ = self.dynamics.slosh_kinematics(x, p)
        C_ib = dcm_batch(self.state(data, "q_bi"))
        rho_b = np.einsum("bji,bnj->bni", C_ib, r_j - self.state(data, "r_zw_i")[:, None, :])
        m_j = p[:, [self.layout.slosh_param(j, "m").start for j in range(self.dynamics.n_slosh)]]
        m_total = p[:, self.layout.params["m_b"].start] + m_j.sum(axis=1)
        return np.einsum("bn,bni->bi", m_j, rho_b[..., 1:]) / m_total[:, None]
