"""The ascent task as a functional env: pure functions of an explicit state and explicit parameters.

After Gymnasium's ``gymnasium.experimental.functional.FuncEnv`` (and brax, gymnax): :class:`AscentFuncEnv`
holds only constants (the vehicle, its timeline, the simulator's models, the task's options); an
episode's whole state is one :data:`AscentState` value, batched over rows::

    func = AscentFuncEnv(SMILE_V0.with_options(model="rigid"))    # lvgym.envs.presets
    rngs = [np.random.default_rng(s) for s in range(8)]
    state = func.initial(rngs)                               # 8 episodes on the pad
    state = func.transition(state, np.zeros((8, 2)), rngs)   # a new state; the old one is unchanged
    obs, reward, done = func.observation(state), func.reward(None, None, state), func.terminal(state)

``transition(..., inplace=True)`` reuses the input state's arrays for the output (as JAX's buffer
donation); the batch core under the Gymnasium faces (:mod:`.core`) steps that way, so it copies nothing.
A transition records its outputs (reward terms, termination, the observation with its sensor noise, the
events) in the new state, so :meth:`reward`, :meth:`terminal` and :meth:`transition_info` read the new
state only. ``rng``: one ``numpy.random.Generator`` per row (the Gymnasium envs' ``np_random``), or None
for a row that draws nothing; every random draw of a row comes from its generator.

Per row and reset (:meth:`AscentFuncEnv.reset`), in this order: the dispersions of ``randomize``
(:meth:`AscentFuncEnv.dispersions`), the gyro bias (``sensor_noise``), the wind realisation (``wind``; a
fixed generator otherwise), the first observation's noise; per step: the observation's noise
(:data:`.layouts.SENSOR_NOISE`; with ``observation="flight"`` the draws of :data:`.layouts.FLIGHT_DRAWS`,
one call per row after the simulator's step, read by the compiled flight computer). So N rows and N
single envs seeded alike are identical.
"""

from __future__ import annotations

import functools
import math
from collections import namedtuple
from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.experimental.functional import FuncEnv

from lvgym.simulator import (EnvironmentSpec, LaunchSpec, PhysicsSpec, SimData, Simulator, Timeline, aeroelastic_strips,
                             build_timeline)
from lvgym.simulator import data as simdata
from lvgym.simulator.core import Kernel
from lvgym.simulator.imu import Imu
from lvgym.simulator.layouts import ACTUATOR, CONDITIONS
from lvgym.simulator.servo import Servo
from lvgym.vehicle import MassModel, Vehicle, load_vehicle
from lvgym.vehicle.designinfo import design_vector
from lvgym.vehicle.slender import SlenderGeometry

from .coast import coast_moment
from .dispersions import DispersionPlan
from .faults import FAULT, apply_faults, decode, fault_info, fault_names
from .history import HistoryStack, recorded_action
from .layouts import (ACTIONS, FLIGHT_DRAWS, NAV, OBSERVATIONS, REASONS, REWARD, REWARD_TERMS, SENSOR_NOISE, TASK,
                      FAULT_INFO, VEHICLE_INFO, informed_layout)
from .limits import qalpha_task_entries, resolve_qalpha_limit
from .privileged import privileged_info
from .scorereward import ScoreReward
from .signals import TaskData, qalpha_limit_rows, reset_signals, step_signals_range
from .spec import IMU_STATION_INTERVALS, IMU_STATION_SIGMA, TaskSpec, wind_spec

__all__ = ["AscentFuncEnv", "AscentParams", "AscentState", "RENDER_STATIONS", "cached_timeline", "cached_vehicle",
           "imu_probe_offsets"]

#: an episode's (or a batch of episodes') whole state: the simulator's rows (:class:`~lvgym.simulator.SimData`),
#: the task's rows (:data:`~.signals.TaskData`) and the events of the last step (one tuple of ``(time, name)`` per
#: row, as :meth:`~lvgym.simulator.Simulator.step` returns them)
AscentState = namedtuple("AscentState", ["sim", "task", "events"])
#: the explicit parameters: ``task`` (layout :data:`.layouts.TASK`), the timeline's
#: :class:`~lvgym.simulator.Tables` and the simulator's step set-up
AscentParams = namedtuple("AscentParams", ["task", "tables", "setup"])
#: stations along the vehicle where the timeline also tabulates the mode shapes, for the rendered view
RENDER_STATIONS = 21
_REASONS = np.array(REASONS, dtype=object)
_SIGNALS = Kernel(step_signals_range)      # row ranges on the simulator's threads


@functools.lru_cache(maxsize=32)
def cached_vehicle(key: str | SlenderGeometry) -> Vehicle:
    """A shipped vehicle by name or path, or the parametric slender vehicle of a
    :class:`~lvgym.vehicle.slender.SlenderGeometry` (a frozen, hashable value: equal geometries share
    the vehicle)."""
    if isinstance(key, SlenderGeometry):
        return key.vehicle()
    if isinstance(key, str):
        return load_vehicle(key)
    raise ValueError(f"vehicle = {key!r}: a shipped name, a YAML path or a SlenderGeometry")


@functools.lru_cache(maxsize=32)
def cached_timeline(key: Any, model: str, t_end: float, physics_dt: float, n_modes: int | None,
                    imu: float, aeroelastic: bool | None = False, mode_interval: float | None = None,
                    mode_basis: str = "held", imu_probes: tuple[float, ...] = ()) -> Timeline:
    """Timelines are shared between the envs of a process (they are read-only). Sensor stations: the IMU
    (index 0), the ``RENDER_STATIONS`` of the rendered view, then the ``imu_probes`` [m] (stations around
    the IMU a dispersed station interpolates between; read off the beam, not meshed, so the others'
    shapes do not change with them)."""
    vehicle = cached_vehicle(key)
    stations = [imu, *np.linspace(0.0, -vehicle.length, RENDER_STATIONS).tolist()]
    return build_timeline(MassModel(vehicle), model, t_end, 0.05, n_modes, stations, 0.5 / physics_dt,
                          strip_stations=aeroelastic_strips(vehicle, aeroelastic=aeroelastic),
                          mode_interval=mode_interval, mode_basis=mode_basis, sensor_probes=imu_probes)


def imu_probe_offsets(length: float) -> np.ndarray:
    """Offsets [m] from the nominal IMU station of the stations tabulated for the ``imu_station``
    dispersion of a vehicle of ``length`` [m]: ``IMU_STATION_INTERVALS`` + 1 evenly spaced over
    +-3 ``IMU_STATION_SIGMA`` ``length``, the nominal (0) left out (it is the IMU's own station)."""
    n = IMU_STATION_INTERVALS // 2
    step = 3.0 * IMU_STATION_SIGMA * length / n
    return np.array([k * step for k in range(-n, n + 1) if k != 0])


def _shown(action: Any) -> str:
    """A short text of an action for an error message."""
    text = (np.array2string(np.asarray(action), threshold=8, precision=4, separator=", ") if np.ndim(action)
            else repr(action))
    return text if len(text) < 120 else text[:117] + "..."


def _rows(rows: Any) -> np.ndarray:
    return np.atleast_1d(np.asarray(rows, dtype=np.int64))


class AscentFuncEnv(FuncEnv):
    """The ascent task of one :class:`~.spec.TaskSpec` as pure functions of an explicit state (see the
    module docstring). Attributes: ``spec``, ``vehicle``, ``timeline``, ``sim`` (the
    :class:`~lvgym.simulator.Simulator` whose constants it flies; the rows are the state's ``sim``),
    ``gimbal_limit`` [rad], ``imu`` station [m], ``n_steps``, ``sample_layout``
    (:data:`.layouts.OBSERVATIONS` of the observation mode), ``observation_layout`` (the same, or with
    ``history`` the stacked one of :mod:`.history`), ``history`` (its :class:`~.history.HistoryStack` or
    None), ``action_space``, ``observation_space``
    (of one row)."""

    def __init__(self, spec: TaskSpec) -> None:
        self.spec = s = spec
        key = s.vehicle                           # a name, a path or a SlenderGeometry (TaskSpec's vehicle_key)
        self.vehicle = vehicle = cached_vehicle(key)
        self.imu = s.imu_station_m if s.imu_station_m is not None else -0.25 * vehicle.length
        # the imu_station dispersion acts on the flight observation's IMU (the others have no IMU dynamics)
        self._imu_sigma = (IMU_STATION_SIGMA * vehicle.length if "imu_station" in s.randomize and
                           s.observation == "flight" else 0.0)
        probes = tuple((self.imu + imu_probe_offsets(vehicle.length)).tolist()) if self._imu_sigma else ()
        self.timeline = tl = cached_timeline(key, s.model, s.mission_time_s + 1.0, s.physics_dt_s, s.n_modes, self.imu,
                                             s.aeroelastic, s.mode_interval_s, s.mode_basis, probes)
        limits = [math.degrees(e.gimbal_limit) for e in vehicle.stages[0].engines if e.gimbal_limit is not None]
        self.gimbal_limit = math.radians(s.gimbal_limit_deg if s.gimbal_limit_deg is not None
                                         else (min(limits) if limits else 5.0))
        servo = Servo(s.actuator_frequency, s.actuator_damping, self.gimbal_limit, math.radians(s.gimbal_rate_limit_degps))
        # the IMU is the timeline's first sensor station, its probes the last ones (cached_timeline)
        n_s = tl.sensor_stations.size
        imu = (Imu(self.imu, 0, s.gyro_bandwidth_hz, s.gyro_damping, s.antialias_hz,
                   probes=tuple(range(n_s - len(probes), n_s))) if s.observation == "flight" else None)
        self.sim = Simulator(vehicle, s.model, launch=LaunchSpec(s.site, s.elevation_deg, s.rail_length_m),
                             environment=EnvironmentSpec(aeroelastic=s.aeroelastic), timeline=tl,
                             physics=PhysicsSpec(s.physics_dt_s, s.slosh_frequency), servo=servo, imu=imu)
        self.n_steps = int(round(s.mission_time_s / s.control_dt_s))
        #: the layout of one sample of the observation mode (the observation itself without ``history``)
        base = OBSERVATIONS[s.observation]
        self.sample_layout = informed_layout(base, s.vehicle_info, s.fault_info)
        #: the ``vehicle_info`` block (the vehicle's design parameters) and where it starts, or None
        self._info = ((design_vector(vehicle), self.sample_layout.offset(VEHICLE_INFO.names[0])) if s.vehicle_info
                      else None)
        #: where the ``fault_info`` block starts, or None
        self._fault_at = self.sample_layout.offset(FAULT_INFO.names[0]) if s.fault_info else None
        self.history = HistoryStack(self.sample_layout, ACTIONS[s.control], s.history) if s.history else None
        self.observation_layout = self.history.layout if self.history else self.sample_layout
        self.action_space = (spaces.Box(-1.0, 1.0, (2,), np.float32) if s.control == "tvc" else spaces.MultiDiscrete([3]))
        self.observation_space = spaces.Box(-np.inf, np.inf, (self.observation_layout.size,), np.float32)
        self._noisy = s.observation == "sensors" and "sensor_noise" in s.randomize
        self._flight_noisy = s.observation == "flight" and "sensor_noise" in s.randomize
        self._faults = "fault" in s.randomize
        self._privileged = bool(s.privileged_info)
        # the draws' standard deviations, field by field (a row draws them in one call, whatever the layout's padding)
        arw = s.gyro_arw_rad_per_sqrt_s / math.sqrt(s.control_dt_s)
        step = s.gyro_bias_rw_radps_per_sqrt_s * math.sqrt(s.control_dt_s)
        sigmas = {"gyro_noise": arw, "bias_step": step, "accel_noise": s.accel_noise_mps2}
        self._draw_slices = [FLIGHT_DRAWS.slice(f.name) for f in FLIGHT_DRAWS.fields]
        self._draw_sigma = np.concatenate([np.full(FLIGHT_DRAWS.field(f.name).size, sigmas[f.name])
                                           for f in FLIGHT_DRAWS.fields])
        self._draw_sigma_reset = np.concatenate([np.full(FLIGHT_DRAWS.field(f.name).size,
                                                         0.0 if f.name == "bias_step" else sigmas[f.name])
                                                 for f in FLIGHT_DRAWS.fields])      # no bias step at a reset
        self._neutral = 0.0 if s.control == "tvc" else 1.0        # the action that commands nothing
        self._noise = [(getattr(s, key), self.sample_layout.slice(names[0]).start, len(names), per)
                       for key, names, per in SENSOR_NOISE if names[0] in self.sample_layout]
        lay = self.sim.layout
        self._i_J = lay.params["J_b"]
        self.qalpha_limit = resolve_qalpha_limit(s, vehicle)
        super().__init__()
        #: the score reward (``reward_kind="score_v2"``, :mod:`.scorereward`) or None (the weighted terms)
        self.score_reward = (ScoreReward(s, self.gimbal_limit, self.n_steps, self.default_params.task, self.sim.tables)
                             if s.reward_kind == "score_v2" else None)

    # ------------------------------------------------------------------------------ parameters
    def get_default_params(self, **kwargs: Any) -> AscentParams:
        """The parameters of ``spec``: the task vector (layout TASK), the timeline's tables, the step
        set-up of the simulator."""
        s = self.spec
        task = TASK.pack({"on_after": s.controller_on_after_s, "dt": s.control_dt_s, "mission": s.mission_time_s,
                          "rate_weights": s.rate_weights, "effort_weight": s.effort_weight,
                          "effort_rate_weight": s.effort_rate_weight, "failure_penalty": s.failure_penalty_rad_per_s,
                          **qalpha_task_entries(self.qalpha_limit), "attitude_limit": s.attitude_limit_deg,
                          "gimbal_limit": self.gimbal_limit, "gravity_turn": float(s.reference == "gravity_turn"),
                          "earth_velocity": float(s.reference_velocity == "earth"),
                          "kick_start": s.kick_start_s, "kick_end": s.kick_end_s,
                          "kick_angle": math.radians(s.kick_angle_deg), "sensors": float(s.observation == "sensors"),
                          "n_steps": self.n_steps, "flight": float(s.observation == "flight")})
        return AscentParams(task=task, tables=self.sim.tables, setup=self.sim.setup)

    def qalpha_limits(self, state: AscentState, params: AscentParams | None = None) -> np.ndarray:
        """The structural q-alpha limit [Pa deg] of every row at its time and Mach number (B,)."""
        params = self.default_params if params is None else params
        sim = state.sim
        out = np.empty(sim.t.size)
        qalpha_limit_rows(params.task, sim.t, self.sim.conditions(sim, "mach"), out)
        return out

    # ------------------------------------------------------------------------------ state
    def new_state(self, batch: int) -> AscentState:
        """Zeroed rows for ``batch`` episodes (reset them with :meth:`reset` before stepping)."""
        B, n_obs = int(batch), self.sample_layout.size
        task = TaskData(steps=np.zeros(B, dtype=np.int64), on=np.zeros(B, dtype=bool), on_step=np.zeros(B, dtype=bool),
                        axis_ref_i=np.zeros((B, 3)), cum_error=np.zeros((B, 3)), rate_error=np.zeros((B, 3)),
                        gyro_bias=np.zeros((B, 3)), obs=np.zeros((B, n_obs), dtype=np.float32), att=np.zeros((B, 2)),
                        terms=REWARD.zeros(B), reward=np.zeros(B), reason=np.zeros(B, dtype=np.int64),
                        truncated=np.zeros(B, dtype=bool), qalpha=np.zeros(B), mass=np.zeros(B),
                        stage=np.zeros(B, dtype=np.int64),
                        pending=np.full((B, max(self.spec.action_delay_steps, 1), self.action_space.shape[0]),
                                        self._neutral),
                        nav=NAV.zeros(B), draws=FLIGHT_DRAWS.zeros(B),
                        history=self.history.zeros(B) if self.history else np.zeros((B, 0), np.float32),
                        fault=FAULT.zeros(B),
                        score=np.zeros((B, self.score_reward.columns if self.score_reward else 0)))
        return AscentState(sim=self.sim.new_data(B), task=task, events=[()] * B)

    @staticmethod
    def take(state: AscentState, rows: Any = None) -> AscentState:
        """A copy of the rows ``rows`` (default all) of ``state``."""
        idx = np.arange(len(state.task.steps)) if rows is None else _rows(rows)
        return AscentState(sim=simdata.take(state.sim, idx), task=TaskData(*(a[idx].copy() for a in state.task)),
                           events=[tuple(state.events[b]) for b in idx])

    @staticmethod
    def put(state: AscentState, rows: Any, src: AscentState) -> AscentState:
        """Write the rows of ``src`` into the rows ``rows`` of ``state`` (in place; returns the state, a
        new value when the simulator's context had to widen)."""
        idx = _rows(rows)
        sim = simdata.put(state.sim, idx, src.sim)
        for a, b in zip(state.task, src.task):
            if a.shape[1:] != b.shape[1:]:
                raise ValueError(f"task rows of shape {b.shape[1:]} for {a.shape[1:]} (another observation mode?)")
            a[idx] = b
        events = list(state.events)
        for i, b in enumerate(idx):
            events[b] = tuple(src.events[i])
        return AscentState(sim=sim, task=state.task, events=events)

    # ------------------------------------------------------------------------------ FuncEnv
    def initial(self, rng: Any, params: AscentParams | None = None) -> AscentState:
        """A new state of ``len(rng)`` episodes on the pad (``rng``: a generator, or one per row)."""
        rngs = [rng] if isinstance(rng, np.random.Generator) else list(rng)
        state = self.new_state(len(rngs))
        return self.reset(state, np.arange(len(rngs)), rngs, params)

    def reset(self, state: AscentState, rows: Any, rng: Sequence[np.random.Generator],
              params: AscentParams | None = None) -> AscentState:
        """New episodes for the rows ``rows`` of ``state`` (in place), drawing from ``rng`` (one generator
        per row); returns the state (a new value when the simulator's context had to widen)."""
        params = self.default_params if params is None else params
        rows, s = _rows(rows), self.spec
        rngs = list(rng)
        if len(rngs) != rows.size:
            raise ValueError(f"{len(rngs)} generators for {rows.size} rows")
        winds, scales, offsets, mis, loads, servos, stations = [], [], [], [], [], [], []
        ts = state.task
        for b, g in zip(rows, rngs):
            wind_rng = g if "wind" in s.randomize else np.random.default_rng(12345)
            winds.append((wind_spec(s.wind, s.mission_time_s), wind_rng))
            sc, of, m, ld, sv, st, fd = self.dispersions(g)
            if self._faults:
                ts.fault[b] = decode(fd, s.fault_kinds, s.fault_onset_s)
            servos.append(sv)
            stations.append(st)
            scales.append(sc)
            offsets.append(of)
            mis.append(m)
            loads.append(ld)
            ts.gyro_bias[b] = g.normal(0.0, s.gyro_bias_radps, 3) if "sensor_noise" in s.randomize else np.zeros(3)
        sim = self.sim.reset_rows(state.sim, rows, [w[1] for w in winds], [w[0] for w in winds], np.array(mis),
                                  np.array(scales), np.array(offsets), dispersion=np.array(loads),
                                  servo_dispersion=np.array(servos),
                                  imu_station=np.array(stations) if self._imu_sigma else None)
        ts.cum_error[rows] = 0.0
        ts.rate_error[rows] = 0.0
        ts.steps[rows] = 0
        ts.terms[rows] = 0.0
        ts.reward[rows] = 0.0
        ts.reason[rows] = 0
        ts.truncated[rows] = False
        ts.qalpha[rows] = 0.0
        ts.pending[rows] = self._neutral
        if self.score_reward:
            self.score_reward.reset(ts, rows)
        self._draw_flight(sim, ts, rows, rngs, self._draw_sigma_reset)
        reset_signals(rows, params.task, params.setup, sim, ts, params.tables)
        self._add_noise(sim, ts, rows, rngs)
        self._add_info(sim, ts, rows)
        if self.history:
            self.history.reset(ts.history, rows, ts.obs[rows])
        events = list(state.events)
        for b in rows:
            events[b] = ()
        return AscentState(sim=sim, task=ts, events=events)

    def transition(self, state: AscentState, action: Any, rng: Sequence[np.random.Generator | None],
                   params: AscentParams | None = None, *, inplace: bool = False, checked: bool = False) -> AscentState:
        """The state one control period later, with ``action`` (B, 2) in [-1, 1] (``tvc``, clipped:
        Gymnasium's convention for a Box) or (B, 1) in {0, 1, 2} (``rcs``: negative, no, positive roll
        pulse). ``rng`` (B,): each row's generator for its sensor noise (None: the row draws nothing, e.g.
        a row about to be reset). ``inplace``: reuse ``state``'s arrays (see the module docstring);
        ``checked``: the caller has passed ``action`` through :meth:`check_action` already."""
        params = self.default_params if params is None else params
        B = state.task.steps.size
        a = np.asarray(action) if checked else self.check_action(action, B)
        st = state if inplace else self.take(state)
        s, sim, ts = self.spec, st.sim, st.task
        on, sampled = ts.on, a
        if s.action_delay_steps:                      # the oldest sampled action acts; this one waits
            q = ts.pending
            now = q[:, 0].copy()
            q[:, :-1] = q[:, 1:]
            q[:, -1] = a
            a = now
        if self._faults:
            apply_faults(self.sim, sim, ts.fault, ts.gyro_bias)
        moment = force = None
        if s.control == "tvc":
            a = a.astype(float)
            cmd = np.where(on[:, None], np.clip(a, -1.0, 1.0) * self.gimbal_limit, 0.0)
            if s.coast_control or s.settling_thrust_n > 0.0:
                moment, force = self._coast(sim, ts)
        else:
            a = a[:, 0].astype(float)
            cmd = np.zeros((B, 2))
            moment = np.zeros((B, 3))
            moment[:, 0] = np.where(on, (a - 1.0) * s.rcs_torque_nm, 0.0)
        events = self.sim.step(sim, cmd, s.control_dt_s, moment, force=force)
        ts.steps[:] += 1
        self._draw_flight(sim, ts, range(B), rng, self._draw_sigma)
        self.sim.run_rows(_SIGNALS, B, params.task, params.setup, sim, ts, params.tables)
        if self.score_reward:
            self.score_reward.step(ts, sim.t, sampled)
        if self._noisy:
            self._add_noise(sim, ts, range(B), rng)
        self._add_info(sim, ts, slice(None))
        if self.history:
            self.history.push(ts.history, ts.obs, recorded_action(s.control, sampled))
        return AscentState(sim=sim, task=ts, events=events)

    def _coast(self, sim: SimData, ts: TaskData) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Body moments and forces (B, 3) [N m], [N] of the coast (the policy off after
        ``controller_on_after_s``): the attitude hold of :mod:`.coast` (``coast_control``) and the settling
        thrust along +x_b (``settling_thrust_n``); None when no row coasts."""
        spec = self.spec
        rows = np.flatnonzero(~ts.on & ~sim.failed & (sim.t >= spec.controller_on_after_s - 1e-9))
        if rows.size == 0:
            return None, None
        B = ts.on.size
        force = None
        if spec.settling_thrust_n > 0.0:
            force = np.zeros((B, 3))
            force[rows, 0] = spec.settling_thrust_n
        moment = None
        if spec.coast_control:
            omega = sim.x[rows][:, self.sim.layout.state["omega_bi_b"]]
            J = sim.p[rows][:, self._i_J].reshape(-1, 3, 3)
            cond = sim.conditions[rows]
            moment = np.zeros((B, 3))
            moment[rows, 1:] = coast_moment(CONDITIONS.view(cond, "alpha")[:, 0], CONDITIONS.view(cond, "beta")[:, 0],
                                            omega[:, 1:], np.stack([J[:, 1, 1], J[:, 2, 2]], axis=1),
                                            spec.coast_bandwidth_radps, spec.coast_torque_nm)
        return moment, force

    def check_action(self, action: Any, batch: int | None = None) -> np.ndarray:
        """``action`` as an array of ``batch`` rows of the action space (None: one element of it), or a
        ``ValueError`` naming the action and the space: a wrong shape, a non-finite TVC action, an RCS
        action outside {0, 1, 2}. TVC values outside [-1, 1] are clipped by :meth:`transition`
        (Gymnasium's convention for a Box)."""
        a = np.asarray(action)
        space = self.action_space
        want = space.shape if batch is None else (batch, *space.shape)
        if a.shape != want:
            what = "an element" if batch is None else f"{batch} row(s)"
            raise ValueError(f"action {_shown(action)} has shape {a.shape}: expected {want}, {what} of the action "
                             f"space {space}")
        if self.spec.control == "tvc":
            if a.dtype.kind not in "fiu" or not np.isfinite(a).all():
                raise ValueError(f"action {_shown(action)} is not finite: the action space is {space} (values "
                                 "outside [-1, 1] are clipped)")
        elif a.dtype.kind not in "fiu" or not np.all((a == 0) | (a == 1) | (a == 2)):
            raise ValueError(f"action {_shown(action)}: the action space is {space}, whole numbers 0 (negative "
                             "roll pulse), 1 (none) or 2 (positive)")
        return a

    def observation(self, state: AscentState, rng: Any = None, params: AscentParams | None = None) -> np.ndarray:
        """The observation (B, n_obs) float32 of every row: what the flight computer sampled (noise
        included), or with ``history`` the stacked samples and actions (:mod:`.history`)."""
        return (state.task.history if self.history else state.task.obs).copy()

    def reward(self, state: AscentState | None, action: Any, next_state: AscentState, rng: Any = None,
               params: AscentParams | None = None) -> np.ndarray:
        """The reward (B,) of the transition into ``next_state`` (the sum of its ``reward_terms``)."""
        return next_state.task.reward.copy()

    def terminal(self, state: AscentState, rng: Any = None, params: AscentParams | None = None) -> np.ndarray:
        """Whether each row ended (B,): a non-finite state, q-alpha or attitude error beyond the limit (with the
        score reward also a gimbal command that breaks the flyability rule)."""
        return state.task.reason != 0

    def truncation(self, state: AscentState, params: AscentParams | None = None) -> np.ndarray:
        """Whether each row reached the mission time without terminating (B,)."""
        return state.task.truncated.copy()

    def transition_info(self, state: AscentState | None, action: Any, next_state: AscentState,
                        params: AscentParams | None = None) -> dict[str, Any]:
        """The per-row arrays of the Gymnasium ``info`` of the transition into ``next_state`` (it reads
        ``next_state`` only)."""
        sim, ts = next_state.sim, next_state.task
        cond = self.sim.conditions
        return {"reward_terms": dict(zip(REWARD_TERMS, ts.terms.T.copy())),
                "cumulative_rate_error": ts.cum_error.copy(), "rate_error": ts.rate_error.copy(),
                "qbar": cond(sim, "qbar").copy(), "mach": cond(sim, "mach").copy(),
                "alpha_total": cond(sim, "alpha_total").copy(), "qalpha_pa_deg": ts.qalpha.copy(),
                "qalpha_limit_pa_deg": self.qalpha_limits(next_state, params), "time": sim.t.copy(),
                "stage": ts.stage.copy(), "controller_on": ts.on_step.copy(),
                "slosh_angles": self.sim.slosh_angles(sim), "eta": self.sim.state(sim, "eta").copy(),
                "gimbal": self.gimbal(next_state), "gimbal_rate": ACTUATOR.view(sim.actuator, "gimbal_rate").copy(),
                "effort_rad_s": self.effort(next_state),
                "attitude_error": ts.att.copy(), "mass": ts.mass.copy(),
                "termination": _REASONS[ts.reason], "events": next_state.events,
                **({"fault": self.ended_faults(next_state)} if self._faults else {}),
                **(self.privileged_info(next_state) if self._privileged else {})}

    def privileged_info(self, state: AscentState) -> dict[str, np.ndarray]:
        """What no flight sensor gives, per row (the ``privileged_info`` option; :func:`.privileged.privileged_info`)."""
        return privileged_info(self.sim, state.sim, self.spec.control_dt_s)

    def ended_faults(self, state: AscentState) -> np.ndarray:
        """The name of each row's fault (B,) where its episode has just ended (terminated or truncated), ``""``
        elsewhere and for a row without one: a fault is named only after its episode (:mod:`.faults`)."""
        ts = state.task
        return np.where((ts.reason != 0) | ts.truncated, fault_names(ts.fault), "")

    def state_info(self, state: AscentState, params: AscentParams | None = None) -> dict[str, Any]:
        """The per-row arrays of the Gymnasium ``info`` after a reset."""
        ts = state.task
        return {"time": state.sim.t.copy(), "cumulative_rate_error": ts.cum_error.copy(), "mass": ts.mass.copy(),
                "controller_on": ts.on.copy()}

    # ------------------------------------------------------------------------------ read-outs
    def gimbal(self, state: AscentState) -> np.ndarray:
        """Gimbal angles (B, 2) [rad] of every row."""
        return ACTUATOR.view(state.sim.actuator, "gimbal").copy()

    def effort(self, state: AscentState) -> np.ndarray:
        """Integral of |gimbal pitch| + |gimbal yaw| over the last control period (B,) [rad s], at the
        physics steps (the reward's ``effort`` term is minus ``effort_weight`` times it)."""
        return state.sim.actuator[:, ACTUATOR.index("effort")].copy()

    @functools.cached_property
    def dispersion_plan(self) -> DispersionPlan:
        """The rows of :data:`~.dispersions.DISPERSIONS` this task draws, their targets resolved."""
        return DispersionPlan(self.spec, self.sim.layout, self.sim.dynamics.n_slosh, self.vehicle)

    def dispersions(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                             np.ndarray, float, np.ndarray]:
        """Parameter scale and offset, thrust misalignment [rad], load dispersions (layout
        :data:`~lvgym.simulator.layouts.DISPERSION`), servo dispersion (layout
        :data:`~.dispersions.SERVO_DISPERSION`), IMU station shift [m] along +x_b and fault draw (layout
        :data:`~.faults.FAULT_DRAW`) of one row: each row of
        the table :data:`~.dispersions.DISPERSIONS` whose name is in ``randomize``, drawn from ``rng`` in
        the table's order (docs/benchmark.md, "Dispersions", is generated from the table)."""
        return self.dispersion_plan.draw(rng)

    def _draw_flight(self, sim: SimData, ts: TaskData, rows: Any, rngs: Sequence[np.random.Generator | None],
                     sigma: np.ndarray) -> None:
        """The flight sensors' draws of ``rows`` for this sample (layout FLIGHT_DRAWS, standard deviations
        ``sigma``), each row from its own generator, when ``sensor_noise`` is randomised with the
        ``flight`` observation; zero for a row without a generator or whose state failed."""
        if not self._flight_noisy:
            return
        d = ts.draws
        for b, g in zip(rows, rngs):
            d[b] = 0.0
            if g is None or sim.failed[b]:
                continue
            z, o = g.normal(0.0, sigma), 0
            for sl in self._draw_slices:
                d[b, sl] = z[o:o + sl.stop - sl.start]
                o += sl.stop - sl.start

    def _add_info(self, sim: SimData, ts: TaskData, rows: Any) -> None:
        """The ``vehicle_info`` and ``fault_info`` blocks of the observation of ``rows`` (an index array or a
        slice): the vehicle's design parameters and the struck fault, except on a row whose flight failed
        (its observation stays zero)."""
        if self._info is None and self._fault_at is None:
            return
        idx = np.arange(ts.obs.shape[0])[rows]
        idx = idx[~sim.failed[idx]]
        if self._info is not None:
            vector, start = self._info
            ts.obs[idx, start:start + VEHICLE_INFO.size] = vector
        if self._fault_at is not None:
            ts.obs[idx, self._fault_at:] = fault_info(ts.fault[idx])

    def _add_noise(self, sim: SimData, ts: TaskData, rows: Any, rngs: Sequence[np.random.Generator | None]) -> None:
        """Sensor noise on the observation of ``rows`` (layout SENSOR_NOISE), each row from its own
        generator, when ``sensor_noise`` is randomised with the ``sensors`` observation."""
        if not self._noisy:
            return
        obs = ts.obs
        for b, g in zip(rows, rngs):
            if g is None or sim.failed[b]:
                continue
            for sigma, start, n, per in self._noise:
                obs[b, start:start + n] += g.normal(0.0, sigma, n) / per
