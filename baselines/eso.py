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
from .filters import StructuralFilter

SCHEDULES = Path(__file__).resolve().parent / "schedules"
__all__ = ["ESOLaw", "ESOPolicy", "eso_model", "observer_gain", "observer_matrices", "servo_model", "smile_eso"]


def eso_model(dt: float, stiffness: float = 0.0, damping: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``Phi`` (3, 3) and ``Gam`` (3,) of the observer's model at the period ``dt`` [s]: the exact discretisation
    of ``theta_dot = omega``, ``omega_dot = -m theta - c omega + f + u``, ``f_dot = 0`` (``u = b0 delta``) with
    the known aerodynamic ``stiffness`` ``m`` [1/s^2] and ``damping`` ``c`` [1/s] (0, 0: Gao's plain ESO,
    ``Phi = [[1, dt, dt^2/2], [0, 1, dt], [0, 0, 1]]``, ``Gam = [dt^2/2, dt, 0]``)."""
    if not (math.isfinite(dt) and dt > 0.0):
        raise ConfigError("dt", dt, "a finite period > 0 s")
    for key, v in (("stiffness_per_s2", stiffness), ("damping_per_s", damping)):
        if not math.isfinite(v):
            raise ConfigError(key, v, "a finite number")
    a = np.array([[0.0, 1.0, 0.0, 0.0], [-stiffness, -damping, 1.0, 1.0], [0.0] * 4, [0.0] * 4])
    e = sla.expm(a * dt)
    return e[:3, :3].copy(), e[:3, 3].copy()


def _place(phi: np.ndarray, c: np.ndarray, beta: float) -> np.ndarray:
    """The gain ``L`` with every eigenvalue of ``(I - L c) phi`` at ``beta`` (Ackermann on ``(phi, c phi)``)."""
    n = phi.shape[0]
    o = np.vstack([c @ np.linalg.matrix_power(phi, k + 1) for k in range(n)])
    coeff = np.poly([beta] * n)
    p = sum(coeff[k] * np.linalg.matrix_power(phi, n - k) for k in range(n + 1))
    return p @ np.linalg.solve(o, np.eye(n)[-1])


def observer_gain(wo: float, dt: float, stiffness: float = 0.0, damping: float = 0.0) -> np.ndarray:
    """The attitude-fed observer's gain (3,) of bandwidth ``wo`` [rad/s] at ``dt`` [s] on the model of
    :func:`eso_model`: the three eigenvalues of the error's map ``(I - L C) Phi`` at ``exp(-wo dt)``."""
    if not (math.isfinite(wo) and wo > 0.0):
        raise ConfigError("observer_bandwidth_radps", wo, "a finite bandwidth > 0 rad/s")
    phi, _ = eso_model(dt, stiffness, damping)
    return _place(phi, np.array([1.0, 0.0, 0.0]), math.exp(-wo * dt))


def observer_matrices(kind: str, wo: float, dt: float, stiffness: float = 0.0,
                      damping: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``F`` (3, 3), ``H`` (3, 2), ``G`` (3,) of the observer ``x_k = F x_{k-1} + H (theta_k, omega_k) +
    G b0 (delta_{k-1} + delta_k) / 2`` with ``x = (theta, omega, f)`` estimates:

    * ``kind="attitude"``: the full-order ESO on the attitude (gain :func:`observer_gain`, triple pole);
    * ``kind="rate"``: the reduced-order ESO on the gyro's rate, the attitude taken as measured (``x[0] =
      theta_k``) and known to the model (``-m theta`` its mean over the period); rate and disturbance
      estimated with a double pole at ``exp(-wo dt)``."""
    if not (math.isfinite(wo) and wo > 0.0):
        raise ConfigError("observer_bandwidth_radps", wo, "a finite bandwidth > 0 rad/s")
    phi, gam = eso_model(dt, stiffness, damping)
    if kind == "attitude":
        lg = _place(phi, np.array([1.0, 0.0, 0.0]), math.exp(-wo * dt))
        ilc = np.eye(3) - np.outer(lg, [1.0, 0.0, 0.0])
        h = np.zeros((3, 2))
        h[:, 0] = lg
        return ilc @ phi, h, ilc @ gam
    if kind == "rate":
        a = np.array([[-damping, 1.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
        e = sla.expm(a * dt)
        p2, g2 = e[:2, :2], e[:2, 2]
        l2 = _place(p2, np.array([1.0, 0.0]), math.exp(-wo * dt))
        ilc = np.eye(2) - np.outer(l2, [1.0, 0.0])
        f, g = np.zeros((3, 3)), np.zeros(3)
        h = np.zeros((3, 2))
        f[1:, 1:] = ilc @ p2
        g[1:] = ilc @ g2
        f[1:, 0] = -0.5 * stiffness * g[1:]
        h[0, 0] = 1.0
        h[1:, 0] = -0.5 * stiffness * g[1:]
        h[1:, 1] = l2
        return f, h, g
    raise ConfigError("observer", kind, "'attitude' or 'rate'")


def servo_model(frequency: float, damping: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``As`` (2, 2), ``Bs`` (2,): the servo ``w^2 / (s^2 + 2 z w s + w^2)`` (states position, rate) with its
    command held over ``dt`` [s] (the exact zero-order hold)."""
    w, z = float(frequency), float(damping)
    a = np.array([[0.0, 1.0], [-w * w, -2.0 * z * w]])
    m = sla.expm(np.block([[a, np.array([[0.0], [w * w]])], [np.zeros((1, 3))]]) * dt)
    return m[:2, :2].copy(), m[:2, 2].copy()


def notch_section(notch: Mapping | None, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(b, a)`` (3,) of a row's slosh notch ``notch`` (``frequency_radps`` w_n, ``damping`` z_n, ``depth`` r:
    ``(s^2 + 2 r z_n w_n s + w_n^2) / (s^2 + 2 z_n w_n s + w_n^2)``, Tustin prewarped at w_n, the notch section of
    :class:`.filters.StructuralFilter`) at ``dt`` [s]; None: the identity ``(1, 0, 0), (1, 0, 0)``."""
    if notch is None:
        return np.array([1.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    try:
        f = StructuralFilter(notch_radps=float(notch["frequency_radps"]), notch_damping=float(notch["damping"]),
                             notch_depth=float(notch["depth"]))
    except (KeyError, TypeError, ValueError) as e:
        raise ConfigError("schedule notch", notch, f"frequency_radps, damping, depth: positive numbers ({e})") from e
    b, a = f.discrete(dt)[2]
    return np.asarray(b, float), np.asarray(a, float)


def row_gains(rows: list[Mapping], dt: float) -> tuple[np.ndarray, ...]:
    """The schedule's rows as the kernel's tables at the period ``dt`` [s]: ``kp`` (m,), ``kd`` (m,), ``F``
    (m, 3, 3), ``H`` (m, 3, 2), ``G`` (m, 3) (:func:`observer_matrices`). A row: ``observer`` ('attitude',
    default, or 'rate'), ``controller_bandwidth_radps`` ``wc`` and ``controller_damping`` ``zeta`` (default 1),
    ``observer_bandwidth_radps``, the model's known ``stiffness_per_s2`` ``m`` and ``damping_per_s`` ``c``
    (default 0: Gao's plain ESO), ``notch`` (:func:`notch_section`, default none); the law closes the observer's
    model at ``s^2 + 2 zeta wc s + wc^2``: ``kp = wc^2 - m``, ``kd = 2 zeta wc - c``. Also ``fb``, ``fa`` (m, 3)."""
    kp, kd, F, H, G, fb, fa = [], [], [], [], [], [], []
    for r in rows:
        wc, zeta = float(r["controller_bandwidth_radps"]), float(r.get("controller_damping", 1.0))
        if not (math.isfinite(wc) and wc > 0.0 and math.isfinite(zeta) and zeta > 0.0):
            raise ConfigError("schedule controller_bandwidth_radps, controller_damping", (wc, zeta),
                              "positive numbers [rad/s, -]")
        m, c = float(r.get("stiffness_per_s2", 0.0)), float(r.get("damping_per_s", 0.0))
        f, h, g = observer_matrices(str(r.get("observer", "attitude")), float(r["observer_bandwidth_radps"]), dt, m, c)
        kp.append(wc * wc - m)
        kd.append(2.0 * zeta * wc - c)
        F.append(f)
        H.append(h)
        G.append(g)
        nb_, na_ = notch_section(r.get("notch"), dt)
        fb.append(nb_)
        fa.append(na_)
    return np.array(kp), np.array(kd), np.array(F), np.array(H), np.array(G), np.array(fb), np.array(fa)


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
        kp, kd, F, H, G, fb, fa = row_gains(rows, self.dt)
        power = doc["control_power"]
        tb, b0 = np.array(power["time_s"], float), np.array(power["per_s2"], float)
        if tb.size < 1 or tb.shape != b0.shape or np.any(np.diff(tb) <= 0.0) or np.any(b0 <= 0.0):
            raise ConfigError("control_power", power, "increasing times [s] and positive powers [1/s^2], as many")
        As, Bs = servo_model(servo.frequency, servo.damping, self.dt)
        self.tables = ESOTables(t, kp, kd, F, H, G, fb, fa, tb, b0, As, Bs, self.dt, float(spec.mission_time_s), self.limit)
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
