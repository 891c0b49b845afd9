"""Incremental nonlinear dynamic inversion (INDI) for thrust-vector control of pitch and yaw: one batch law
(:class:`INDILaw`, its compiled inner loop :func:`.indikernel.indi_act_k`), its one-row face :class:`INDIPolicy`.

The law of one plane at every control period ``T`` (Sieberling, Chu & Mulder 2010; Smeur, Chu & de Croon 2016; for
a launcher, ESA ESTEC's design, Aerospace 12(4):296, 2025)::

    omega     = e + r                      the flight gyro's rate: the observation's rate error e plus the
                                           pitch rate reference r (yaw: r = 0) [rad/s]
    omega_dot = (H omega)_k - (H omega)_{k-1}, over T       the filtered angular acceleration [rad/s^2]
    a_0       = H S (gimbal * limit)       the actuator position, through the same filter H (synchronised)
                                           and the sections S that put it in step with omega_dot [rad]
    omega_c   = -k_theta e_att + k_a s f   the outer loops' rate command: the attitude error, and optionally
                                           the load relief on the lateral specific force f (H-filtered)
    nu        = k_q (omega_c - e) + r_dot  the commanded angular acceleration (r_dot from H r)
    u         = a_0 + (nu - omega_dot) / G(t)              the increment on the measured position [rad]
    action    = clip(u, -limit, limit) / limit

``G(t)`` is the control power ``s T l / J`` [1/s^2] of the vehicle's design tables (the vectored thrust times
the gimbal-to-CG arm over the pitch inertia, :func:`.design.linearize.rigid_terms`), interpolated over the
flight time (the observation's time fraction times the mission time). ``H`` is a second-order low-pass with a
notch on the first bending mode (the gyro at the IMU sees its slope rate) and one on the slosh band
(:class:`.indikernel.INDIFilter`); ``S`` the gyro's anti-aliasing filter and the mean of two samples
(:class:`.indikernel.SyncSections`). Gains and filters are rows of a schedule over flight time (the nearest row),
written by :mod:`.design.indi_design` (``baselines/schedules/smile_indi.yaml``); the linear loop and its margins:
:mod:`.design.indiloop`, docs/indi.md.

The law reads only the observation: rate and attitude errors, accelerometers, the actuator position, the time
fraction, ``controller_on`` and the pitch rate reference. Off (``controller_on`` below 0.5, before the
controller starts and through the staging coast) the output is 0; at every engagement the filters restart in the
steady state of their inputs (the first angular acceleration is zero). A clipped command needs no anti-windup:
the next increment starts from the position the servo reached.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError, check_number

from .filecache import read_once
from .indikernel import (INDI_ROW, INDIFilter, INDIObs, INDISetup, INDITable, SyncSections, filter_coeffs,
                         indi_act_k, new_state)
from .pid import ACCEL_SIGNS

__all__ = ["INDILaw", "INDIPolicy", "INDISchedule", "SCHEDULES_BY_VEHICLE", "smile_indi"]

SCHEDULES = Path(__file__).resolve().parent / "schedules"
#: the schedule of each vehicle an env flies (``task.vehicle``)
SCHEDULES_BY_VEHICLE: dict = {"smile_v1": "smile_indi"}


@dataclass(frozen=True)
class INDIRowParams:
    """One schedule row: flight time ``time_s`` [s], gains ``k_rate``, ``k_attitude`` [1/s], ``k_accel`` [rad/s per
    m/s^2] and the filter ``filt``."""

    time_s: float
    k_rate: float
    k_attitude: float
    k_accel: float
    filt: INDIFilter


@dataclass(frozen=True)
class INDISchedule:
    """The rows (ascending flight time), the control-power table ``power`` ((p, 2): time [s], G [1/s^2]), the
    synchronisation sections and the control period the filters are designed for."""

    rows: tuple[INDIRowParams, ...]
    power: np.ndarray
    sync: SyncSections
    dt: float
    source: str = ""

    def __post_init__(self) -> None:
        times = [r.time_s for r in self.rows]
        if not times or times != sorted(times):
            raise ConfigError(f"{self.source}: rows.time_s", times, "at least one row, increasing")
        p = np.asarray(self.power, float)
        if p.ndim != 2 or p.shape[1] != 2 or not np.all(np.diff(p[:, 0]) > 0) or not np.all(p[:, 1] > 0):
            raise ConfigError(f"{self.source}: control_power", p.tolist(), "[[t, G], ...] with t increasing, G > 0")

    @classmethod
    def load(cls, path: str | Path = "smile_indi") -> "INDISchedule":
        """A schedule written by :mod:`.design.indi_design` (a path, or a name in ``baselines/schedules``)."""
        p = Path(path)
        if not p.exists():
            p = SCHEDULES / (str(path) if str(path).endswith(".yaml") else f"{path}.yaml")
        if not p.exists():
            raise FileNotFoundError(f"INDI schedule {str(path)!r}: no such file (nor {p}); write one with "
                                    "`lvgym design indi --vehicle smile`")
        return read_once(p, cls._read, "INDISchedule")

    @classmethod
    def _read(cls, p: Path) -> "INDISchedule":
        doc = yaml.safe_load(p.read_text())
        return cls.from_dict(doc, str(p))

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any], source: str = "") -> "INDISchedule":
        """From the document :mod:`.design.indi_design` writes."""
        rows = []
        for i, r in enumerate(doc["rows"]):
            key = f"{source}: rows[{i}]"
            rows.append(INDIRowParams(check_number(f"{key}.time_s", r["time_s"], 0.0, 1e4),
                                      check_number(f"{key}.k_rate", r["k_rate"], 0.0, 1e3),
                                      check_number(f"{key}.k_attitude", r["k_attitude"], 0.0, 1e3),
                                      check_number(f"{key}.k_accel", r.get("k_accel", 0.0), 0.0, 10.0),
                                      INDIFilter.from_dict(r["filter"], f"{key}.filter")))
        s = doc.get("sync", {})
        sync = SyncSections(float(s.get("antialias_radps", 0.0)), float(s.get("antialias_damping", 2 ** -0.5)),
                            bool(s.get("average", True)))
        return cls(tuple(rows), np.asarray(doc["control_power"], float), sync, float(doc["control_dt_s"]), source)

    def with_accel(self, k_accel: float) -> "INDISchedule":
        """The same schedule with the load-relief gain ``k_accel`` [rad/s per m/s^2] on every row."""
        k = check_number("k_accel", k_accel, 0.0, 10.0)
        rows = tuple(INDIRowParams(r.time_s, r.k_rate, r.k_attitude, k, r.filt) for r in self.rows)
        return INDISchedule(rows, self.power, self.sync, self.dt, self.source)

    def tables(self, dt: float) -> INDITable:
        """The kernel's table at the control period ``dt`` [s]."""
        coeffs, sections = [], []
        for r in self.rows:
            c, h, a = filter_coeffs(r.filt, self.sync, dt)
            coeffs.append(c)
            sections.append((h, a))
        gains = np.array([[r.k_rate for r in self.rows], [r.k_attitude for r in self.rows],
                          [r.k_accel for r in self.rows]])
        tb = INDITable(np.array([r.time_s for r in self.rows]), gains, np.ascontiguousarray(np.stack(coeffs, axis=1)),
                       np.ascontiguousarray(np.array(sections, np.int64).T), np.ascontiguousarray(self.power[:, 0]),
                       np.ascontiguousarray(self.power[:, 1]))
        return tb


class INDILaw(BatchLaw):
    """INDI of pitch and yaw (module docstring) for ``n`` rows of the TVC envs with the flight observation.
    ``env``: the env it flies (gimbal limit, control period, mission time, the observation's layout);
    ``schedule``: an :class:`INDISchedule`, a path or a name in ``baselines/schedules``; ``k_accel``: the
    load-relief gain [rad/s per m/s^2] on every row instead of the schedule's (None: the schedule's).
    :attr:`gimbal` (n, 2) [rad]: each row's last command."""

    def __init__(self, *, env: Any, schedule: INDISchedule | str | Path = "smile_indi", name: str = "indi",
                 k_accel: float | None = None, n: int = 1) -> None:
        task = env.unwrapped
        self.name = name
        sched = schedule if isinstance(schedule, INDISchedule) else INDISchedule.load(schedule)
        if k_accel is not None:
            sched = sched.with_accel(k_accel)
        self.schedule = sched
        self.dt = float(task.task.control_dt_s)
        if abs(self.dt - sched.dt) > 1e-12:
            raise ConfigError("env control_dt_s", self.dt,
                              f"the schedule's control period {sched.dt} s ({sched.source})")
        self.limit = float(task.gimbal_limit)
        lay = task.observation_layout
        for key in ("pitch_attitude_error", "accel_z", "gimbal_pitch", "time_fraction"):
            if key not in lay.names:
                raise ConfigError("env observation", getattr(task.task, "observation", None),
                                  f"an observation with {key!r} (observation='flight')")
        self.oc = INDIObs(np.asarray([lay.index("pitch_rate_error"), lay.index("yaw_rate_error")], np.int64),
                          np.asarray([lay.index("pitch_attitude_error"), lay.index("yaw_attitude_error")], np.int64),
                          np.asarray([lay.index("accel_z"), lay.index("accel_y")], np.int64),
                          np.asarray([lay.index("gimbal_pitch"), lay.index("gimbal_yaw")], np.int64),
                          int(lay.index("controller_on")), int(lay.index("time_fraction")),
                          int(lay.index("pitch_rate_reference")))
        self.tb = sched.tables(self.dt)
        self.su = INDISetup(self.dt, self.limit, float(task.task.mission_time_s),
                            np.asarray(ACCEL_SIGNS, float), bool(np.any(self.tb.gains[2] != 0.0)))
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.st = new_state(n)

    @property
    def gimbal(self) -> np.ndarray:
        return INDI_ROW.view(self.st.law, "gimbal")

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        fresh = new_state(1)
        self.st.law[w] = fresh.law[0]
        self.st.filters[w] = fresh.filters[0]

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations (len(rows), n_obs); ``info``
        is not read."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations, dtype=np.float64).reshape(rows.size, -1)
        out = np.empty((rows.size, 2), np.float32)
        indi_act_k(self.tb, self.su, self.oc, self.st, rows, obs, out)
        return out


class INDIPolicy(RowFace):
    """INDI as a benchmark :class:`~lvgym.benchmark.policy.Policy`: one row of :class:`INDILaw` (its arguments)."""

    def __init__(self, *, env: Any, schedule: INDISchedule | str | Path = "smile_indi", name: str = "indi",
                 k_accel: float | None = None) -> None:
        self.law = INDILaw(env=env, schedule=schedule, name=name, k_accel=k_accel)

    @property
    def last_gimbal(self) -> np.ndarray:
        return self.law.gimbal[0].copy()


def smile_indi(env: Any, name: str = "indi", schedule: str | None = None, k_accel: float | None = None) -> INDIPolicy:
    """``indi`` on ``env``: the schedule of its vehicle (:data:`SCHEDULES_BY_VEHICLE`; another with ``schedule``);
    a vehicle without one is refused."""
    if schedule is None:
        vehicle = getattr(env.unwrapped.task, "vehicle", None)
        if not isinstance(vehicle, Hashable) or vehicle not in SCHEDULES_BY_VEHICLE:
            raise ConfigError("env vehicle", vehicle, f"one of {list(SCHEDULES_BY_VEHICLE)} (an INDI schedule: "
                              "lvgym design indi)")
        schedule = SCHEDULES_BY_VEHICLE[vehicle]
    return INDIPolicy(env=env, schedule=schedule, name=name, k_accel=k_accel)
