"""``eso``: active disturbance rejection control of pitch and yaw, one batch law (:class:`ESOLaw`, its compiled inner
loop :func:`.esokernel.eso_act_k`) and its one-row face (:class:`ESOPolicy`).

Per plane an extended-state observer estimates the attitude error, its rate and the total disturbance angular
acceleration (everything the rigid double integrator ``theta_ddot = b0 delta`` leaves out: the aerodynamic moment,
the thrust misalignment, the wind, the slosh and the model's errors) from the observation's attitude error and
the gimbal angle its own commands give through a model of the servo and the computational delay; the law is a PD
on the estimates with the disturbance estimate cancelled (J. Han, "From PID to active disturbance rejection
control", IEEE Trans. Industrial Electronics 56(3), 2009), with one controller and one observer bandwidth per
design row (Z. Gao, "Scaling and bandwidth-parameterization based controller tuning", ACC 2003). The
equations: :mod:`.esokernel`; the design and its margins: :mod:`.design.esodesign`, docs/eso.md.

The law reads only the observation: the attitude and rate errors, the actuator position (at engagement),
``time_fraction`` (times the env's mission time: the flight time that selects the row and the control power)
and ``controller_on``. The control power ``b0(t)`` [1/s^2] is the vehicle's design table (vectored thrust times
the gimbal-to-CG arm over the pitch inertia, :func:`.design.linearize.rigid_terms` over the flight), written into
the schedule file with the rows' bandwidths.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import scipy.linalg as sla
import yaml

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError

from .esokernel import ESOCols, ESOTables, eso_act_k, new_state
from .filecache import read_once

SCHEDULES = Path(__file__).resolve().parent / "schedules"
__all__ = ["ESOLaw", "ESOPolicy", "observer_gain", "servo_model", "smile_eso"]


def observer_gain(wo: float, dt: float) -> np.ndarray:
    """The observer's gain (3,) of bandwidth ``wo`` [rad/s] at ``dt`` [s]: the three eigenvalues of the error's
    map ``(I - L C) Phi`` at ``exp(-wo dt)`` (:func:`.design.esodesign.observer_gain`, Ackermann's formula)."""
    if not (math.isfinite(wo) and wo > 0.0 and math.isfinite(dt) and dt > 0.0):
        raise ConfigError("observer_bandwidth_radps", wo, "a finite bandwidth > 0 rad/s at a period > 0")
    phi = np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    beta = math.exp(-wo * dt)
    o = np.vstack([phi[0], phi[0] @ phi, phi[0] @ phi @ phi])            # (Phi, C Phi) with C = [1, 0, 0]
    a = np.poly([beta, beta, beta])
    p = np.linalg.matrix_power(phi, 3) + a[1] * phi @ phi + a[2] * phi + a[3] * np.eye(3)
    return p @ np.linalg.solve(o, np.array([0.0, 0.0, 1.0]))


def servo_model(frequency: float, damping: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``As`` (2, 2), ``Bs`` (2,): the servo ``w^2 / (s^2 + 2 z w s + w^2)`` (states position, rate) with its
    command held over ``dt`` [s] (the exact zero-order hold)."""
    w, z = float(frequency), float(damping)
    a = np.array([[0.0, 1.0], [-w * w, -2.0 * z * w]])
    m = sla.expm(np.block([[a, np.array([[0.0], [w * w]])], [np.zeros((1, 3))]]) * dt)
    return m[:2, :2].copy(), m[:2, 2].copy()


def load_schedule(name: str | Path = "smile_eso") -> dict[str, Any]:
    """The schedule document (a path, or a name in ``baselines/schedules``), read once per process."""
    p = Path(name)
    if not p.exists():
        p = SCHEDULES / f"{name}.yaml"
    if not p.exists():
        raise FileNotFoundError(f"eso schedule {str(name)!r}: no such file (nor {p})")
    return read_once(p, lambda q: yaml.safe_load(q.read_text()), "ESOSchedule")


class ESOLaw(BatchLaw):
    """Pitch and yaw ADRC (module docstring) for ``n`` rows of the TVC envs with the flight observation. ``env``:
    the env (gimbal limit, servo, control period, delay, mission time and observation layout come from it);
    ``schedule``: a schedule document or its name. :attr:`gimbal` (n, 2) [rad]: each row's last command."""

    def __init__(self, *, env: Any, schedule: str | Path | Mapping = "smile_eso", name: str = "eso",
                 n: int = 1) -> None:
        task = env.unwrapped
        spec = task.task
        self.name = name
        doc = schedule if isinstance(schedule, Mapping) else load_schedule(schedule)
        self.dt = float(spec.control_dt_s)
        delay = int(getattr(spec, "action_delay_steps", 0))
        if delay != 1:
            raise ConfigError("env action_delay_steps", delay, "1 (the observer's input model holds one period)")
        self.limit = float(task.gimbal_limit)
        servo = task.sim.servo
        rows = doc["rows"]
        if not rows:
            raise ConfigError("schedule rows", rows, "at least one row")
        t = np.array([float(r["time_s"]) for r in rows])
        wc = np.array([float(r["controller_bandwidth_radps"]) for r in rows])
        wo = np.array([float(r["observer_bandwidth_radps"]) for r in rows])
        if np.any(wc <= 0.0) or np.any(wo <= 0.0):
            raise ConfigError("schedule bandwidths", (wc.tolist(), wo.tolist()), "positive numbers [rad/s]")
        power = doc["control_power"]
        tb, b0 = np.array(power["time_s"], float), np.array(power["per_s2"], float)
        if tb.size < 1 or tb.shape != b0.shape or np.any(np.diff(tb) <= 0.0) or np.any(b0 <= 0.0):
            raise ConfigError("control_power", power, "increasing times [s] and positive powers [1/s^2], as many")
        As, Bs = servo_model(servo.frequency, servo.damping, self.dt)
        self.tables = ESOTables(t, wc * wc, 2.0 * wc, np.array([observer_gain(w, self.dt) for w in wo]), tb, b0,
                                As, Bs, self.dt, float(spec.mission_time_s), self.limit)
        lay = task.observation_layout
        ix = lay.index
        self.cols = ESOCols(np.array([ix("pitch_attitude_error"), ix("yaw_attitude_error")], np.int64),
                            np.array([ix("pitch_rate_error"), ix("yaw_rate_error")], np.int64),
                            np.array([ix("gimbal_pitch"), ix("gimbal_yaw")], np.int64), int(ix("time_fraction")),
                            int(ix("controller_on")))
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.state = new_state(n)

    @property
    def gimbal(self) -> np.ndarray:
        return self.state.gimbal

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode."""
        r = np.asarray(rows, dtype=np.int64).reshape(-1)
        for a in self.state:
            a[r] = 0

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations; ``info`` is not read."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations, dtype=np.float64).reshape(rows.size, -1)
        out = np.empty((rows.size, 2), np.float32)
        eso_act_k(self.tables, self.cols, self.state, rows, obs, out)
        return out


class ESOPolicy(RowFace):
    """``eso`` as a benchmark policy: one row of :class:`ESOLaw` (its arguments)."""

    def __init__(self, *, env: Any, schedule: str | Path | Mapping = "smile_eso", name: str = "eso") -> None:
        self.law = ESOLaw(env=env, schedule=schedule, name=name)


def smile_eso(env: Any, name: str = "eso", schedule: str = "smile_eso") -> ESOPolicy:
    """The schedule designed for SMILE v1 (``baselines/schedules/smile_eso.yaml``) on ``env``: it must fly the
    ``smile_v1`` vehicle with the flight observation."""
    spec = env.unwrapped.task
    if getattr(spec, "vehicle", None) != "smile_v1":
        raise ConfigError("env vehicle", getattr(spec, "vehicle", None), "'smile_v1' (eso is designed for SMILE v1)")
    if getattr(spec, "observation", None) != "flight":
        raise ConfigError("env observation", getattr(spec, "observation", None), "'flight' (eso reads the IMU's attitude)")
    return ESOPolicy(env=env, schedule=schedule, name=name)


smile_eso.kind = "classical"  # type: ignore[attr-defined]
