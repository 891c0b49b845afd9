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
from lvgym.simulator.servo import Servo
from lvgym.simulator.core import dcm_batch
from lvgym.vehicle import MassModel, Vehicle, load_vehicle
from lvgym.vehicle.slender import slender_vehicle

from .spec import TaskSpec, wind_spec

G0 = 9.80665
#: observation entries (same for ``state`` and ``sensors``; see the env docstrings)
OBS_NAMES = ("roll_rate", "pitch_rate_error", "yaw_rate_error", "pitch_attitude_error", "yaw_attitude_error",
             "alpha_or_accel_z", "beta_or_accel_y", "mach_over_10", "qbar_over_1e5", "gimbal_pitch", "gimbal_yaw",
             "time_fraction", "controller_on", "pitch_rate_reference")
#: stations along the vehicle where the timeline also tabulates the mode shapes, for the rendered view
RENDER_STATIONS = 21
REWARD_TERMS = ("rate_roll", "rate_pitch", "rate_yaw", "effort", "effort_rate", "failure")


@functools.lru_cache(maxsize=32)
def cached_vehicle(key: Any) -> Vehicle:
    """A shipped vehicle by name or path, or ``("slender", length, diameter)`` for the parametric one."""
    if isinstance(key, tuple) and len(key) == 3 and key[0] == "slender":
        return slender_vehicle(length=float(key[1]), diameter=float(key[2]))
    if isinstance(key, str):
        return load_vehicle(key)
    raise ValueError(f"vehicle = {key!r}: a shipped name, a YAML path or ('slender', length, diameter)")


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
        self.steps = np.zeros(self.B, dtype=int)
        self.last_cmd = np.zeros((self.B, 2))
        lay = self.sim.layout
        self._i_mb, self._i_J = lay.params["m_b"], lay.params["J_b"]
        self._i_cg, self._i_om = lay.params["r_cg"], lay.params["omega_modes"]
        self._i_zeta = [lay.slosh_param(j, "zeta") for j in range(self.sim.dynamics.n_slosh)]
        self.n_steps = int(round(s.mission_time_s / s.control_dt_s))

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

    def reset_rows(self, rows: np.ndarray, rngs: list[np.random.Generator]) -> None:
        """New episodes for ``rows``, drawing from ``rngs`` (one generator per row, kept for the episode)."""
        rows = np.atleast_1d(rows)
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
        self.sim.reset_rows(rows, [w[1] for w in winds], [w[0] for w in winds], np.array(mis), np.array(scales),
                            np.array(offsets))
        self.axis_ref_i[rows] = self._C_ib(rows)[:, :, 0]          # the launch axis
        self.cum_error[rows] = 0.0
        self.steps[rows] = 0
        self.last_cmd[rows] = 0.0

    def _C_ib(self, rows: Any = slice(None)) -> np.ndarray:
        return dcm_batch(self.sim.state("q_bi")[rows])

    # ------------------------------------------------------------------------------ task signals
    def controller_on(self) -> np.ndarray:
        """Whether the controller acts: after ``controller_on_after_s`` and while an engine burns."""
        burning = self.timeline.left("burning", self.sim.t).astype(bool)
        return (self.sim.t >= self.spec.controller_on_after_s - 1e-9) & burning

    def reference_rates(self) -> np.ndarray:
        """Reference body rates (B, 3) [rad/s]: zero, or the gravity-turn pitch program (a kick of
        ``kick_angle_deg`` between ``kick_start_s`` and ``kick_end_s`` towards downrange, then the rate at
        which gravity turns the velocity, ``-g sin(theta) / V`` with theta the velocity's angle from the
        vertical; negative pitch rate turns the nose downrange)."""
        ref = np.zeros((self.B, 3))
        s = self.spec
        if s.reference == "gravity_turn":
            t = self.sim.t
            kick = (t >= s.kick_start_s) & (t < s.kick_end_s)
            ref[kick, 1] = -math.radians(s.kick_angle_deg) / (s.kick_end_s - s.kick_start_s)
            after = t >= s.kick_end_s
            if after.any():
                v = self.sim.state("v_zw_i")
                g = self.sim.conditions("g_i")
                gn = np.linalg.norm(g, axis=1)
                up = -g / gn[:, None]
                speed = np.maximum(np.linalg.norm(v, axis=1), 1.0)
                cos_th = np.clip(np.einsum("bi,bi->b", v, up) / speed, -1.0, 1.0)
                ref[after, 1] = -(gn * np.sqrt(1.0 - cos_th**2) / speed)[after]
        return ref

    def attitude_error(self) -> np.ndarray:
        """Pitch and yaw attitude error (B, 2) [rad]: the body axis against the reference axis (the
        launch axis, fixed in inertial space; turned by the pitch program when there is one), body y, z."""
        C_ib = self._C_ib()
        x_b_i = C_ib[:, :, 0]
        e_i = np.cross(x_b_i, self.axis_ref_i)
        e_b = np.einsum("bji,bj->bi", C_ib, e_i)
        return -e_b[:, 1:]

    def observe(self, on: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """Observation (B, 14) float32, entries ``OBS_NAMES``."""
        s, sim = self.spec, self.sim
        if s.observation == "state":
            w = sim.state("omega_bi_b").copy()
            att = self.attitude_error()
            flow = np.stack([sim.conditions("alpha"), sim.conditions("beta")], axis=1)
        else:
            w = sim.gyro_rates()[:, 0, :] + self.gyro_bias
            att = self.attitude_error()
            if "sensor_noise" in s.randomize:
                w += np.stack([g.normal(0.0, s.gyro_noise_radps, 3) for g in self.rngs])
                att = att + np.stack([g.normal(0.0, s.attitude_noise_rad, 2) for g in self.rngs])
            f = sim.conditions("f_aero_b") + sim.conditions("thrust_e")
            m = self.timeline.interp("mass", sim.t)
            acc = f[:, [2, 1]] / m[:, None]
            if "sensor_noise" in s.randomize:
                acc = acc + np.stack([g.normal(0.0, s.accel_noise_mps2, 2) for g in self.rngs])
            flow = acc / G0
        obs = np.empty((self.B, len(OBS_NAMES)), dtype=np.float32)
        obs[:, 0] = w[:, 0]
        obs[:, 1] = w[:, 1] - ref[:, 1]
        obs[:, 2] = w[:, 2] - ref[:, 2]
        obs[:, 3:5] = att
        obs[:, 5:7] = flow
        obs[:, 7] = sim.conditions("mach") / 10.0
        obs[:, 8] = sim.conditions("qbar") / 1e5
        obs[:, 9:11] = self.sim.gimbal / self.gimbal_limit
        obs[:, 11] = sim.t / s.mission_time_s
        obs[:, 12] = on
        obs[:, 13] = ref[:, 1]
        return obs

    # ------------------------------------------------------------------------------ step
    def step(self, action: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Advance every row by one control period with ``action`` (B, 2) in [-1, 1] (``tvc``) or (B, 1)
        in {0, 1, 2} (``rcs``: negative, no, positive roll pulse). Returns observation, reward,
        terminated, truncated and a dict of per-row arrays (``info``)."""
        s, sim = self.spec, self.sim
        on = self.controller_on()
        moment = np.zeros((self.B, 3))
        if s.control == "tvc":
            a = np.clip(np.asarray(action, dtype=float).reshape(self.B, 2), -1.0, 1.0)
            cmd = np.where(on[:, None], a * self.gimbal_limit, 0.0)
        else:
            a = np.asarray(action).reshape(self.B, -1)[:, 0]
            cmd = np.zeros((self.B, 2))
            moment[:, 0] = np.where(on, (a.astype(float) - 1.0) * s.rcs_torque_nm, 0.0)
        events = sim.step(cmd, s.control_dt_s, moment)
        effort, effort_rate = sim.effort[:, 0], sim.effort[:, 1]
        self.steps += 1
        ref = self.reference_rates()
        if s.reference == "gravity_turn":
            C_ib = self._C_ib()
            turn = C_ib @ np.array([0.0, 1.0, 0.0])           # pitch axis in inertial
            ang = ref[:, 1] * s.control_dt_s
            k = turn
            v = self.axis_ref_i
            self.axis_ref_i = (v * np.cos(ang)[:, None] + np.cross(k, v) * np.sin(ang)[:, None]
                               + k * np.einsum("bi,bi->b", k, v)[:, None] * (1 - np.cos(ang))[:, None])
        w = sim.state("omega_bi_b")
        failed = sim.failed.copy()
        err = np.abs(np.where(failed[:, None], 0.0, w - ref))
        self.cum_error += err * s.control_dt_s
        terms = {
            "rate_roll": -s.rate_weights[0] * err[:, 0] * s.control_dt_s,
            "rate_pitch": -s.rate_weights[1] * err[:, 1] * s.control_dt_s,
            "rate_yaw": -s.rate_weights[2] * err[:, 2] * s.control_dt_s,
            "effort": -s.effort_weight * effort,
            "effort_rate": -s.effort_rate_weight * effort_rate,
        }
        qa = sim.conditions("qbar") * np.degrees(sim.conditions("alpha_total"))
        att = self.attitude_error()
        att_deg = np.degrees(np.linalg.norm(att, axis=1))
        reason = np.full(self.B, "", dtype=object)
        reason[att_deg > s.attitude_limit_deg] = "attitude error beyond the limit"
        reason[qa > s.qalpha_limit_pa_deg] = "q-alpha beyond the structural limit"
        reason[failed] = "non-finite state"
        terminated = reason != ""
        truncated = ~terminated & (self.steps >= self.n_steps)
        remaining = np.maximum(s.mission_time_s - sim.t, 0.0)
        terms["failure"] = np.where(terminated, -s.failure_penalty_rad_per_s * remaining, 0.0)
        reward = sum(terms.values())
        obs = self.observe(self.controller_on(), ref)
        if failed.any():
            obs[failed] = 0.0
        info = {"reward_terms": terms, "cumulative_rate_error": self.cum_error.copy(),
                "qbar": sim.conditions("qbar"), "mach": sim.conditions("mach"),
                "alpha_total": sim.conditions("alpha_total"), "qalpha_pa_deg": qa, "time": sim.t.copy(),
                "stage": self.timeline.left("stage", sim.t), "controller_on": on,
                "slosh_angles": sim.slosh_angles(), "eta": sim.state("eta").copy(), "gimbal": self.sim.gimbal.copy(),
                "attitude_error": att, "termination": reason, "events": events}
        return obs, reward, terminated, truncated, info
