"""LQG rate control of pitch and yaw, scheduled over the flight: one batch law (:class:`LQGLaw`, its compiled
inner loop :func:`.lqgkernel.lqg_act_k`), its one-row face :class:`LQGPolicy`.

The compensators are designed by :mod:`.lqg_design` (``python -m lvgym.baselines.design.lqg_design --vehicle smile``)
on the flight computer's non-rigid plant at frozen flight times (the rows of
``baselines/schedules/smile_lqg.npz``). Per plane and control period (the design's law, with the gyro
sample ``y`` [rad/s] the observation's rate error, ``rate - reference``)::

    x_f = x_p + M (y - C x_p)              measurement update (steady-state Kalman gain M)
    v   = -K_x x_f - K_i xi                LQR on the filtered state and the rate-error integral
    u   = clip(v, -limit, limit)           the gimbal command [rad]; the action is u / limit
    x_p <- A x_f + B u                     time update with the command sent (the model's delay state
                                           carries it to the plant one period later)
    xi  <- a xi - dt y                     leaky integral of the rate error (held while the output is
                                           clipped and the integral would push it further)

``lqi`` flies the same law on its own schedule (``baselines/schedules/smile_lqi.npz``, docs/lqi.md), whose rows
integrate the observation's strapdown attitude error ``e`` [rad] instead, without a leak: ``xi <- xi - dt e``
(the rows' ``integral``, :data:`.lqgkernel.INTEGRAL_SOURCES`), so that a constant disturbance moment leaves
no attitude offset; it flies with ``lqg-aw``'s anti-windup.

Without clipping this is exactly :func:`.lqg_design.compensator` (checked in the tests). ``lqg-aw`` flies the
same law with anti-windup (``back_gain``: the command also held to the servo's rate limit, the integral
back-calculated; :class:`.lqgkernel.AntiWindup`, docs/mpc.md); ``lqg`` without.

Scheduling: the row in use is the one whose interval (from the midpoints between the rows of a
thrusting phase, :func:`.lqg_design.row_intervals`) holds ``info["time"]``; beyond the intervals the
nearest row. The rows' state dimensions differ between the boost and the upper stage (other pendulums,
no bending modes in the band), so at a switch the integral is carried and the estimate is carried state
by state where the two rows name the same states, and set to zero where they do not.

Off (the observation's ``controller_on`` below 0.5: before the controller starts and through the
staging coast): the output is 0 and the estimate and the integral are frozen; at every engagement
they restart from zero (a new flight phase: the upper stage's trim is not the boost's).

Both planes fly their own design (pitch and yaw plants of the axisymmetric vehicle agree to 1e-9 in the
boost, 1 % in the upper stage; :mod:`.lqg_design` uses the pitch weights for yaw). Signs: a positive
pitch (yaw) gimbal gives a positive pitch (yaw) rate, as the plant models (checked against the env in
the tests).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError, check_number

from .filecache import read_once
from .lqgkernel import (INTEGRAL_SOURCES, NO_ANTI_WINDUP, AntiWindup, LQGState, LQGTables, from_engagement,
                        lqg_act_k, lqg_step_k, lqg_tables, row_index)
from .pidkernel import ObsColumns

SCHEDULES = Path(__file__).resolve().parent / "schedules"
PLANES = ("pitch", "yaw")
#: where :class:`LQGLaw` reads the flight time: the step's ``info`` or the observation's time fraction
CLOCKS = ("info", "observation")
#: the reference of an attitude integral (:class:`LQGLaw`): the attitude error itself (``zero``) or the error less
#: its value at the engagement (``engagement``: the attitude the vehicle holds when the law engages)
ATTITUDE_FROM = ("zero", "engagement")


@dataclass(frozen=True)
class LQGRow:
    """One row's compensator of one plane (the names of :class:`.lqg_design.RowDesign`)."""

    time_s: float
    interval_s: tuple[float, float]
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    Kx: np.ndarray
    Ki: float
    M: np.ndarray
    a: float
    dt: float
    labels: tuple[str, ...]
    weights: tuple[float, ...] = ()
    """the design's :class:`.lqg_row.LQGWeights` in field order (empty if the file has none)"""
    integral: str = "rate"
    """what the integral integrates (:data:`.lqgkernel.INTEGRAL_SOURCES`): the rate error (leaky, ``lqg``) or the
    attitude error (pure, ``lqi``)"""

    def __post_init__(self) -> None:
        n = self.A.shape[0]
        for key, shape in (("A", (n, n)), ("B", (n, 1)), ("C", (1, n)), ("Kx", (1, n)), ("M", (n, 1))):
            if getattr(self, key).shape != shape:
                raise ConfigError(f"row {self.time_s:g} s.{key}", getattr(self, key).shape, f"shape {shape}")
        if len(self.labels) != n:
            raise ConfigError(f"row {self.time_s:g} s.labels", len(self.labels), f"{n} state names")
        if not (self.dt > 0 and 0.0 < self.a <= 1.0):
            raise ConfigError(f"row {self.time_s:g} s.a", self.a, "an integrator factor in (0, 1] at dt > 0")
        if self.integral not in INTEGRAL_SOURCES:
            raise ConfigError(f"row {self.time_s:g} s.integral", self.integral, f"one of {INTEGRAL_SOURCES}")


@dataclass(frozen=True)
class LQGSchedule:
    """The rows of each plane (:data:`PLANES`), in flight-time order."""

    rows: dict[str, tuple[LQGRow, ...]]
    source: str = ""

    def __post_init__(self) -> None:
        for plane in PLANES:
            if plane not in self.rows or not self.rows[plane]:
                raise ConfigError(f"{self.source}: rows.{plane}", None, "at least one row per plane")
        times = [r.time_s for r in self.rows["pitch"]]
        if times != sorted(times) or [r.time_s for r in self.rows["yaw"]] != times:
            raise ConfigError(f"{self.source}: time_s", times, "increasing and the same in both planes")

    @property
    def dt(self) -> float:
        return self.rows["pitch"][0].dt

    def index(self, t: float) -> int:
        """The row in use at flight time ``t`` [s]: the one whose interval holds it, else the nearest (the
        law's own choice, :func:`.lqgkernel.row_index`)."""
        return int(row_index(self.tables(self.rows["pitch"]), float(t)))

    @cached_property
    def _tables(self) -> dict[int, LQGTables]:
        return {}

    def tables(self, rows: tuple[LQGRow, ...]) -> LQGTables:
        """The stacked tables of ``rows`` (one plane's, :func:`.lqgkernel.lqg_tables`), built once per
        schedule object and plane."""
        key = id(rows)
        if key not in self._tables:
            self._tables[key] = lqg_tables(rows)
        return self._tables[key]

    @classmethod
    def load(cls, path: str | Path = "smile_lqg") -> "LQGSchedule":
        """A schedule written by :func:`.lqg_design.save_schedule` (a path, or a name in
        ``baselines/schedules``)."""
        p = Path(path)
        if not p.exists():
            p = SCHEDULES / (str(path) if str(path).endswith(".npz") else f"{path}.npz")
        if not p.exists():
            raise FileNotFoundError(f"LQG schedule {str(path)!r}: no such file (nor {p}); write one with "
                                    "`python -m lvgym.baselines.design.lqg_design --vehicle smile` (--overwrite to ship it)")
        return read_once(p, cls._read, "LQGSchedule")              # read once per process

    @classmethod
    def _read(cls, p: Path) -> "LQGSchedule":
        """The schedule in the file ``p`` (an ``.npz`` of :func:`.lqg_design.save_schedule`)."""
        with np.load(p, allow_pickle=False) as z:
            times, intervals = z["time_s"], z["interval_s"]
            rows = {}
            for plane in PLANES:
                rows[plane] = tuple(LQGRow(
                    float(t), (float(lo), float(hi)), *(_read_only(z[f"{plane}_{i}_{k}"]) for k in ("A", "B", "C", "Kx")),
                    float(z[f"{plane}_{i}_Ki"]), _read_only(z[f"{plane}_{i}_M"]), float(z[f"{plane}_{i}_a"]),
                    float(z[f"{plane}_{i}_dt"]), tuple(str(s) for s in z[f"{plane}_{i}_labels"]),
                    tuple(float(v) for v in z[f"{plane}_{i}_weights"]) if f"{plane}_{i}_weights" in z else (),
                    str(z[f"{plane}_{i}_integral"]) if f"{plane}_{i}_integral" in z else "rate")
                    for i, (t, (lo, hi)) in enumerate(zip(times, intervals)))
        return cls(rows, str(p))


def _read_only(a: np.ndarray) -> np.ndarray:
    """``a`` as a float array that cannot be written (the schedule is shared by every policy built from
    it, :func:`.filecache.read_once`)."""
    out = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


class LQGPlane:
    """One plane's law (module docstring) for ``n`` independent rows (episodes) of one schedule, its state in
    :attr:`state` (:class:`.lqgkernel.LQGState`): ``update(y, t, on, which) -> u`` [rad] steps the rows
    ``which`` with their gyro samples ``y`` [rad/s], flight times ``t`` [s] and switches ``on`` (the compiled
    :func:`.lqgkernel.lqg_step_k`, the step :class:`LQGLaw` runs for each plane; ``e`` [rad]: the attitude
    error samples a row integrating the attitude reads, zero if not given); ``aw``: its anti-windup
    (:class:`.lqgkernel.AntiWindup`; the default is ``lqg``'s plain law)."""

    def __init__(self, rows: tuple[LQGRow, ...], schedule: LQGSchedule, u_limit: float, n: int = 1,
                 aw: AntiWindup = NO_ANTI_WINDUP, attitude_from: str = "zero") -> None:
        if not u_limit > 0.0:
            raise ConfigError("u_limit", u_limit, "a gimbal limit > 0 rad")
        if int(n) < 1:
            raise ConfigError("n", n, "at least one row")
        self.rows, self.schedule, self.u_limit, self.n, self.aw = rows, schedule, float(u_limit), int(n), aw
        self.tables = schedule.tables(rows)
        if attitude_from == "engagement":
            self.tables = from_engagement(self.tables)
        N = self.tables.A.shape[1]
        self.state = LQGState(np.zeros((self.n, N)), np.zeros(self.n), np.full(self.n, -1, dtype=np.int64),
                              np.zeros(self.n, bool), np.zeros(self.n, bool), np.zeros(self.n), np.zeros(self.n))
        self._all = np.arange(self.n, dtype=np.int64)

    @property
    def saturated(self) -> np.ndarray:
        """Whether each row's last command was clipped."""
        return self.state.saturated

    def reset(self, which: Any = None) -> None:
        """Restart the rows ``which`` (None: all) as at the start of an episode."""
        w = slice(None) if which is None else np.asarray(which, dtype=np.int64)
        st = self.state
        st.row[w], st.x[w], st.xi[w], st.was_on[w], st.saturated[w] = -1, 0.0, 0.0, False, False
        st.u[w], st.e0[w] = 0.0, 0.0

    def update(self, y: Any, t: Any, on: Any, which: Any = None, e: Any = None) -> np.ndarray:
        """The commands [rad] of the rows ``which`` (None: all) for their gyro samples ``y`` [rad/s] and
        attitude error samples ``e`` [rad] (None: zeros) at flight times ``t`` [s], the law on where ``on``."""
        which = self._all if which is None else np.asarray(which, dtype=np.int64).reshape(-1)
        y = np.asarray(y, dtype=float).reshape(-1)
        e = np.zeros(y.size) if e is None else np.asarray(e, dtype=float).reshape(-1)
        t = np.asarray(t, dtype=float).reshape(-1)
        on = np.asarray(on, dtype=bool).reshape(-1)
        u = np.empty(which.size)
        lqg_step_k(self.tables, self.state, which, y, e, t, on, self.u_limit, self.aw, u)
        return u


class LQGLaw(BatchLaw):
    """Pitch and yaw LQG (module docstring) for ``n`` rows of the TVC envs. ``env``: the lvgym env it flies
    (the gimbal limit, the control period, the delay and the observation's layout come from it, checked
    against the schedule); ``schedule``: an :class:`LQGSchedule`, a path or a name in ``baselines/schedules``;
    ``back_gain``: None for ``lqg``'s plain law, else the anti-windup of ``lqg-aw`` with this back-calculation
    gain per period [-] in [0, 1] and the command held to the env's gimbal rate limit
    (:class:`.lqgkernel.AntiWindup`); ``clock``: where the flight time comes from, ``info`` (``info["time"]`` of
    every row, as ``lqg`` and ``lqg-aw`` have always flown) or ``observation`` (its ``time_fraction`` times the
    env's mission time: the law then reads nothing but the observation, ``lqi``); ``attitude_from``: the
    reference of a schedule that integrates the attitude error, ``zero`` (``lqi``: the attitude error itself) or
    ``engagement`` (``lqi-hold``: the error less its value when the law engages, :data:`ATTITUDE_FROM`).
    :attr:`gimbal` (n, 2) [rad]: each row's last command."""

    def __init__(self, *, env: Any, schedule: LQGSchedule | str | Path = "smile_lqg", name: str = "lqg",
                 back_gain: float | None = None, n: int = 1, clock: str = "info", attitude_from: str = "zero") -> None:
        task = env.unwrapped
        self.name = name
        self.schedule = schedule if isinstance(schedule, LQGSchedule) else LQGSchedule.load(schedule)
        self.dt = float(task.task.control_dt_s)
        if abs(self.dt - self.schedule.dt) > 1e-12:
            raise ConfigError("env control_dt_s", self.dt, f"the schedule's control period {self.schedule.dt} s "
                              f"({self.schedule.source})")
        delay = int(getattr(task.task, "action_delay_steps", 0))
        n_delay = sum(1 for s in self.schedule.rows["pitch"][0].labels if s.startswith("command_delay_"))
        if delay != n_delay:
            raise ConfigError("env action_delay_steps", delay, f"the schedule's {n_delay} ({self.schedule.source})")
        self.limit = float(task.gimbal_limit)
        self.aw = NO_ANTI_WINDUP
        if back_gain is not None:
            gain = check_number("back_gain", back_gain, 0.0, 1.0)
            rate = math.radians(float(task.task.gimbal_rate_limit_degps))        # rad/s
            self.aw = AntiWindup(True, rate * self.dt, gain)
        lay = task.observation_layout
        if clock not in CLOCKS:
            raise ConfigError("clock", clock, f"one of {CLOCKS}")
        if attitude_from not in ATTITUDE_FROM:
            raise ConfigError("attitude_from", attitude_from, f"one of {ATTITUDE_FROM}")
        self.attitude_from = attitude_from
        #: the observation's time_fraction column and the mission time [s] it is a fraction of (-1: info's time)
        self.time_col = int(lay.index("time_fraction")) if clock == "observation" else -1
        self.mission_s = float(task.task.mission_time_s)
        none = np.full(2, -1, np.int64)
        att = np.asarray([lay.index(k) if k in lay.names else -1
                          for k in ("pitch_attitude_error", "yaw_attitude_error")], np.int64)
        if any(r.integral == "attitude" for p in PLANES for r in self.schedule.rows[p]) and np.any(att < 0):
            raise ConfigError("env observation", getattr(lay, "title", ""), "one with pitch_attitude_error and "
                              f"yaw_attitude_error (the schedule {self.schedule.source} integrates the attitude error)")
        self.oc = ObsColumns(np.asarray([lay.index("pitch_rate_error"), lay.index("yaw_rate_error")], np.int64),
                             none, int(lay.index("controller_on")), -1, -1, att)
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.planes = [LQGPlane(self.schedule.rows[p], self.schedule, self.limit, n, self.aw, self.attitude_from)
                       for p in PLANES]
        self.gimbal = np.zeros((n, 2))
        self.time = np.zeros(n)                      # the rows' flight times [s] of the observation clock

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode."""
        for plane in self.planes:
            plane.reset(rows)
        self.gimbal[np.asarray(rows, dtype=np.int64).reshape(-1)] = 0.0

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations (len(rows), n_obs) and
        the batched env's ``info`` (every row's ``time``; not read with the observation's clock): one call of
        :func:`.lqgkernel.lqg_act_k`."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations).reshape(rows.size, -1)
        out = np.empty((rows.size, 2), np.float32)
        pitch, yaw = self.planes
        if self.time_col >= 0:
            self.time[rows] = obs[:, self.time_col].astype(np.float64) * self.mission_s
            t = self.time
        else:
            t = np.asarray(info["time"], dtype=np.float64)
        lqg_act_k(pitch.tables, yaw.tables, pitch.state, yaw.state, self.oc, rows, obs, t, self.limit, self.aw,
                  self.gimbal, out)
        return out


class LQGPolicy(RowFace):
    """Pitch and yaw LQG as a benchmark :class:`~lvgym.benchmark.policy.Policy` of the TVC envs: one row of
    :class:`LQGLaw` (its arguments). ``act`` needs ``info["time"]`` unless ``clock="observation"``;
    ``last_gimbal`` (2,) [rad]: the last command."""

    def __init__(self, *, env: Any, schedule: LQGSchedule | str | Path = "smile_lqg", name: str = "lqg",
                 back_gain: float | None = None, clock: str = "info", attitude_from: str = "zero") -> None:
        self.law = LQGLaw(env=env, schedule=schedule, name=name, back_gain=back_gain, clock=clock,
                          attitude_from=attitude_from)

    @property
    def last_gimbal(self) -> np.ndarray:
        return self.law.gimbal[0].copy()


def smile_lqg(env: Any, name: str = "lqg", schedule: str = "smile_lqg", back_gain: float | None = None,
              clock: str = "info", attitude_from: str = "zero") -> LQGPolicy:
    """The LQG schedule designed for SMILE v1 (``baselines/schedules/smile_lqg.npz``; ``smile_lqi``: ``lqi``'s) on
    ``env``; the env must fly the ``smile_v1`` vehicle. ``back_gain``: the anti-windup of ``lqg-aw``, ``clock``:
    where the flight time is read, ``attitude_from``: the attitude integral's reference (:class:`LQGLaw`)."""
    vehicle = getattr(env.unwrapped.task, "vehicle", None)
    if vehicle != "smile_v1":
        raise ConfigError("env vehicle", vehicle, "'smile_v1' (the LQG schedule is designed for SMILE v1, "
                          "lvgym/SmileAscent-v1)")
    return LQGPolicy(env=env, schedule=schedule, name=name, back_gain=back_gain, clock=clock,
                     attitude_from=attitude_from)
