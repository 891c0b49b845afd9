"""The ascent task over a batch: one code path for the single env, the VectorEnv and the SB3 VecEnv.

:class:`AscentBatch` owns a :class:`~lvgym.simulator.Simulator` of B rows and adds what makes it a
task: the gimbal servo settings, the sensors, the reference, the dispersions drawn at reset, the observation,
the reward terms and the termination. Every random draw of row ``b`` comes from that row's generator
(the env's ``np_random``), so a VectorEnv of N rows and N single envs seeded alike are identical.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lvgym.simulator import Simulator, Timeline, build_timeline
from lvgym.simulator.core import Kernel
from lvgym.simulator.servo import Servo
from lvgym.vehicle import MassModel, Vehicle, load_vehicle
from lvgym.vehicle.slender import slender_vehicle

from .signals import (G0, N_TASK, REASONS, T_ATT, T_DT, T_EFFORT, T_EFFORT_RATE, T_GIMBAL, T_GTURN, T_KICK0, T_KICK1,
                      T_KICK_ANGLE, T_MISSION, T_N_STEPS, T_ON_AFTER, T_PENALTY, T_QALPHA, T_SENSORS, T_W_ROLL, T_W_YAW,
                      reset_signals, step_signals_range)
from .spec import TaskSpec, wind_spec

#: observation entries (same for ``state`` and ``sensors``; see the env docstrings)
OBS_NAMES = ("roll_rate", "pitch_rate_error", "yaw_rate_error", "pitch_attitude_error", "yaw_attitude_error",
             "alpha_or_accel_z", "beta_or_accel_y", "mach_over_10", "qbar_over_1e5", "gimbal_pitch", "gimbal_yaw",
             "time_fraction", "controller_on", "pitch_rate_reference")
#: stations along the vehicle where the timeline also tabulates the mode shapes, for the rendered view
RENDER_STATIONS = 21
REWARD_TERMS = ("rate_roll", "rate_pitch", "rate_yaw", "effort", "effort_rate", "failure")
_REASONS = np.array(REASONS, dtype=object)
_SIGNALS = Kernel(step_signals_range)      # row ranges on the simulator's threads


@functools.lru_cache(maxsize=32)
def cached_vehicle(key: Any) -> Vehicle:
    """A shipped vehicle by name or path, or ``("slender", length, diameter[, aero_mach])`` for the
    parametric one (``aero_mach``: Mach number its aerodynamic tables are frozen at, None: full tables)."""
    if isinstance(key, tuple) and len(key) in (3, 4) and key[0] == "slender":
        return slender_vehicle(length=float(key[1]), diameter=float(key[2]), aero_mach=key[3] if len(key) == 4 else None)
    if isinstance(key, str):
        return load_vehicle(key)
    raise ValueError(f"vehicle = {key!r}: a shipped name, a YAML path or ('slender', length, diameter[, aero_mach])")


@functools.lru_cache(maxsize=32)
def cached_timeline(key: Any, model: str, t_end: float, physics_dt: float, n_modes: int | None,
                    imu: float) -> Timeline:
    """Timelines are shared between the envs of a process (they are read-only)."""
    vehicle = cached_vehicle(key)
    stations = [imu, *np.linspace(0.0, -vehicle.length, RENDER_STATIONS).tolist()]
    return build_timeline(MassModel(vehicle), model, t_end, 0.05, n_modes, stations, 0.5 / physics_dt)


class AscentBatch:
    """B rows of one ascent task (see :class:`~.spec.TaskSpec`)."""

    def __init__(self, spec: TaskSpec, batch: int = 1) -> None:
        self.spec = s = spec
        key = tuple(s.vehicle) if isinstance(s.vehicle, (list, tuple)) else str(s.vehicle)
        vehicle = cached_vehicle(key)
        self.imu = s.imu_station_m if s.imu_station_m is not None else -0.25 * vehicle.length
        tl = cached_timeline(key, s.model, s.mission_time_s + 1.0, s.physics_dt_s, s.n_modes, self.imu)
        limits = [math.degrees(e.gimbal_limit) for e in vehicle.stages[0].engines if e.gimbal_limit is not None]
        self.gimbal_limit = math.radians(s.gimbal_limit_deg if s.gimbal_limit_deg is not None
                                         else (min(limits) if limits else 5.0))
        servo = Servo(s.actuator_frequency, s.actuator_damping, self.gimbal_limit, math.radians(s.gimbal_rate_limit_degps))
        self.sim = Simulator(vehicle, s.model, site=s.site, elevation_deg=s.elevation_deg,
                             rail_length=s.rail_length_m, physics_dt=s.physics_dt_s, timeline=tl, servo=servo)
        self.vehicle, self.timeline = vehicle, tl
        self.B = int(batch)
        self.sim.reset(self.B)
        self.rngs: list[np.random.Generator] = [np.random.default_rng(0) for _ in range(self.B)]
        self.gyro_bias = np.zeros((self.B, 3))
        self.axis_ref_i = np.zeros((self.B, 3))
        self.cum_error = np.zeros((self.B, 3))
        self.steps = np.zeros(self.B, dtype=np.int64)
        self.on = np.zeros(self.B, dtype=bool)
        self.obs = np.zeros((self.B, len(OBS_NAMES)), dtype=np.float32)
        self.att = np.zeros((self.B, 2))
        lay = self.sim.layout
        self._i_mb, self._i_J = lay.params["m_b"], lay.params["J_b"]
        self._i_cg, self._i_om = lay.params["r_cg"], lay.params["omega_modes"]
        self._i_zeta = [lay.slosh_param(j, "zeta") for j in range(self.sim.dynamics.n_slosh)]
        self.n_steps = int(round(s.mission_time_s / s.control_dt_s))
        self._tp = self._task_vector()
        self._burning = tl.burning.astype(float)
        self._noisy = s.observation == "sensors" and "sensor_noise" in s.randomize

    # ------------------------------------------------------------------------------ reset
    def _dispersions(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Parameter scale and offset and thrust misalignment of one row, drawn from ``rng``.

        mass: body mass x N(1, 1 %), CG station + N(0, 2 cm), inertia x N(1, 3 %); slosh_damping:
        ratios x log-uniform [0.5, 2]; bending_frequency: x N(1, 5 %); thrust_misalignment: N(0, 0.05 deg)
        per axis (clipped at 3 sigma)."""
        n_p = self.sim.layout.n_p
        scale, offset, mis = np.ones(n_p), np.zeros(n_p), np.zeros(2)
        r = self.spec.randomize
        if "mass" in r:
            scale[self._i_mb] = 1.0 + np.clip(rng.normal(0.0, 0.01), -0.03, 0.03)
            offset[self._i_cg.start] = np.clip(rng.normal(0.0, 0.02), -0.06, 0.06)
            scale[self._i_J] = 1.0 + np.clip(rng.normal(0.0, 0.03), -0.09, 0.09)
        if "slosh_damping" in r:
            f = math.exp(rng.uniform(math.log(0.5), math.log(2.0)))
            for sl in self._i_zeta:
                scale[sl] = f
        if "bending_frequency" in r:
            scale[self._i_om] = 1.0 + np.clip(rng.normal(0.0, 0.05), -0.15, 0.15)
        if "thrust_misalignment" in r:
            mis = np.radians(np.clip(rng.normal(0.0, 0.05, 2), -0.15, 0.15))
        return scale, offset, mis

    def reset_rows(self, rows: np.ndarray, rngs: list[np.random.Generator]) -> np.ndarray:
        """New episodes for ``rows``, drawing from ``rngs`` (one generator per row, kept for the episode);
        returns their first observations."""
        rows = np.atleast_1d(np.asarray(rows, dtype=np.int64))
        s = self.spec
        winds, scales, offsets, mis = [], [], [], []
        for b, g in zip(rows, rngs):
            self.rngs[b] = g
            wind_rng = g if "wind" in s.randomize else np.random.default_rng(12345)
            winds.append((wind_spec(s.wind, s.mission_time_s), wind_rng))
            sc, of, m = self._dispersions(g)
            scales.append(sc)
            offsets.append(of)
            mis.append(m)
            bias = g.normal(0.0, s.gyro_bias_radps, 3) if "sensor_noise" in s.randomize else np.zeros(3)
            self.gyro_bias[b] = bias
        sim = self.sim
        sim.reset_rows(rows, [w[1] for w in winds], [w[0] for w in winds], np.array(mis), np.array(scales),
                       np.array(offsets))
        self.cum_error[rows] = 0.0
        self.steps[rows] = 0
        tl = self.timeline
        reset_signals(rows, self._tp, sim.t, sim.x, sim.diag, sim.gimbal, self.axis_ref_i, self.gyro_bias, tl.t,
                      self._burning, tl.mass, tl.dphi_sensor, sim.dynamics.n_modes, self.on, self.obs, self.att)
        self._add_noise(rows)
        return self.obs[rows].copy()

    def _task_vector(self) -> np.ndarray:
        s = self.spec
        tp = np.zeros(N_TASK)
        tp[T_ON_AFTER], tp[T_DT], tp[T_MISSION] = s.controller_on_after_s, s.control_dt_s, s.mission_time_s
        tp[T_W_ROLL:T_W_YAW + 1] = s.rate_weights
        tp[T_EFFORT], tp[T_EFFORT_RATE] = s.effort_weight, s.effort_rate_weight
        tp[T_PENALTY], tp[T_QALPHA], tp[T_ATT] = s.failure_penalty_rad_per_s, s.qalpha_limit_pa_deg, s.attitude_limit_deg
        tp[T_GIMBAL] = self.gimbal_limit
        tp[T_GTURN] = 1.0 if s.reference == "gravity_turn" else 0.0
        tp[T_KICK0], tp[T_KICK1], tp[T_KICK_ANGLE] = s.kick_start_s, s.kick_end_s, math.radians(s.kick_angle_deg)
        tp[T_SENSORS] = 1.0 if s.observation == "sensors" else 0.0
        tp[T_N_STEPS] = self.n_steps
        return tp

    def _add_noise(self, rows: np.ndarray) -> None:
        """Sensor noise on the observation of ``rows`` (gyro, attitude, accelerometers), each row from its
        own generator, when ``sensor_noise`` is randomised with the ``sensors`` observation."""
        if not self._noisy:
            return
        s = self.spec
        for b in rows:
            if self.sim.failed[b]:
                continue
            g = self.rngs[b]
            self.obs[b, 0:3] += g.normal(0.0, s.gyro_noise_radps, 3)
            self.obs[b, 3:5] += g.normal(0.0, s.attitude_noise_rad, 2)
            self.obs[b, 5:7] += g.normal(0.0, s.accel_noise_mps2, 2) / G0

    # ------------------------------------------------------------------------------ task signals
    def controller_on(self) -> np.ndarray:
        """Whether the controller acts now: after ``controller_on_after_s`` and while an engine burns."""
        return self.on.copy()

    def attitude_error(self) -> np.ndarray:
        """Pitch and yaw attitude error (B, 2) [rad]: the body axis against the reference axis (the
        launch axis, fixed in inertial space; turned by the pitch program when there is one), body y, z."""
        return self.att.copy()

    # ------------------------------------------------------------------------------ step
    def step(self, action: np.ndarray, skip: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Advance every row by one control period with ``action`` (B, 2) in [-1, 1] (``tvc``) or (B, 1)
        in {0, 1, 2} (``rcs``: negative, no, positive roll pulse). Returns observation, reward,
        terminated, truncated and a dict of per-row arrays (``info``). Rows ``skip`` (about to be reset by
        the caller) draw no sensor noise, so their generators stay as a single env's would.

        The signals (:mod:`.signals`): reference pitch rate ``r`` (zero, or the gravity-turn programme);
        rate error ``e = |omega - (0, r, 0)|`` (zero once the state is non-finite), integrated into
        ``info["cumulative_rate_error"]``; reward terms ``-w_axis e_axis dt``, ``-effort_weight int
        |gimbal| dt``, ``-effort_rate_weight int |gimbal rate| dt`` and, on termination,
        ``-failure_penalty_rad_per_s * remaining time``; termination on a non-finite state, q-alpha above
        the limit or attitude error above the limit."""
        s, sim, B = self.spec, self.sim, self.B
        on = self.on.copy()
        moment = None
        if s.control == "tvc":
            a = np.asarray(action, dtype=float).reshape(B, 2)
            cmd = np.where(on[:, None], np.clip(a, -1.0, 1.0) * self.gimbal_limit, 0.0)
        else:
            a = np.asarray(action).reshape(B, -1)[:, 0].astype(float)
            cmd = np.zeros((B, 2))
            moment = np.zeros((B, 3))
            moment[:, 0] = np.where(on, (a - 1.0) * s.rcs_torque_nm, 0.0)
        events = sim.step(cmd, s.control_dt_s, moment)
        self.steps += 1
        tl = self.timeline
        terms, reward = np.empty((B, len(REWARD_TERMS))), np.empty(B)
        reason, truncated, qalpha = np.empty(B, dtype=np.int64), np.empty(B, dtype=bool), np.empty(B)
        sim.run_rows(_SIGNALS, self._tp, sim.t, sim.x, sim.diag, sim.failed, sim.effort, sim.gimbal, self.steps,
                     self.axis_ref_i, self.cum_error, self.gyro_bias, tl.t, self._burning, tl.mass, tl.dphi_sensor,
                     sim.dynamics.n_modes, self.on, self.obs, self.att, terms, reward, reason, truncated, qalpha)
        if self._noisy:
            self._add_noise(np.arange(B) if skip is None else np.setdiff1d(np.arange(B), skip))
        terminated = reason != 0
        i_stage = self._stage_index(sim.t)
        info = {"reward_terms": dict(zip(REWARD_TERMS, terms.T)), "cumulative_rate_error": self.cum_error.copy(),
                "qbar": sim.conditions("qbar").copy(), "mach": sim.conditions("mach").copy(),
                "alpha_total": sim.conditions("alpha_total").copy(), "qalpha_pa_deg": qalpha, "time": sim.t.copy(),
                "stage": tl.stage[i_stage], "controller_on": on, "slosh_angles": sim.slosh_angles(),
                "eta": sim.state("eta").copy(), "gimbal": sim.gimbal.copy(), "attitude_error": self.att.copy(),
                "termination": _REASONS[reason], "events": events}
        return self.obs.copy(), reward, terminated, truncated, info

    def _stage_index(self, t: np.ndarray) -> np.ndarray:
        i, w = self.timeline.locate(t)
        return np.where(w >= 1.0, i + 1, i)
