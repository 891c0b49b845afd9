"""Discrete PID rate controllers for thrust-vector control (thesis 6.3): one batch law (:class:`PIDLaw`) for
fixed gains, gain schedules, structural filters, load relief and the attitude channel, its compiled inner loop
in :mod:`.pidkernel`; :class:`PIDPolicy` and :class:`GainScheduledPIDPolicy` are its one-row faces.

The law of one axis, on the error ``e = reference - measured`` sampled every ``dt`` seconds, discretised with
backward Euler (Simulink's "backward Euler" discrete PID, parallel form)::

    P_k = Kp e_k
    I_k = I_{k-1} + Ki dt e_k                                   (held while clamped, see below)
    D_k = (D_{k-1} + Kd N (e_k - e_{k-1})) / (1 + N dt)         (Kd N s / (s + N); N = inf: Kd (e_k - e_{k-1}) / dt)
    u_k = clip(P_k + I_k + D_k, u_min, u_max)

Backward Euler keeps the derivative filter stable for every N (the thesis's N = 500 to 2100 rad/s are
10 to 42 times the 50 Hz sampling rate, where forward Euler would diverge), and it makes the
derivative of a filter that fast almost the plain difference quotient.

Anti-windup by clamping (conditional integration): when the unclipped output is beyond a limit and the
error would push the integral further that way, the integral keeps its last value. Off (``enabled=False``):
the output is 0, the integral is frozen and the derivative is restarted, so switching back on gives no
derivative kick.

Units. The thesis's gains (Kp 8.98, Ki 3.92, Kd 4.57) map a body-rate error to a gimbal angle in the SI
units of its Simulink model: rad of gimbal per rad/s of rate error (Kp), per rad (Ki) and per rad/s^2 (Kd).
The ratios are the same in degrees (deg of gimbal per deg/s). The policies below divide the gimbal angle
by the gimbal limit to give the env's action in [-1, 1].

Signs. The env's observation holds the rate error ``rate - reference`` (entries ``pitch_rate_error``
and ``yaw_rate_error`` of the env's observation layout); a positive pitch (yaw) gimbal gives a positive
pitch (yaw) rate (checked by experiment in the tests), so the policy feeds ``e = -(rate error)`` to the
law and commands ``u``.

Facts from the env. The policies are built for an env (``env=``, as the benchmark does) and take from it
what they would otherwise work out again: the gimbal limit (the action's scale and the output limit), the
control period, and the observation layout; at every step the env's ``info`` gives the time and the
stack's mass, and the observation the controller-on flag (off before the controller starts and during
staging coasts).

Scheduling (:class:`GainSchedule`, :mod:`.gainschedule`): gains interpolated linearly on a monotonic scheduling variable,
``mass`` (the default, as the thesis: ``info["mass"]``, the vehicle's mass at the current time), ``time``
[s] or ``mach``; beyond the table the end gains are held. ``interpolation: nearest`` takes the nearest
row instead (switching at the midpoints between breakpoints): each row is then a design for its own
stretch of the flight, as ``gs-pid-flex``'s are.

Structural filters (``gs-pid-flex``, :mod:`.flexdesign`): a schedule whose rows carry a ``filter``
(:class:`.filters.StructuralFilter`, its parameters interpolated like the gains) filters each axis's
error before the PID, ``u = PID(F(e))``; the filter starts in the steady state of the error whenever
the controller switches on. A row's ``filter`` may also be a list of filters applied in series,
``F = F_1 F_2 ...`` (:class:`.filters.FilterSeries`: a second notch for the second bending mode, a slosh
notch), the same number in every row, each filter's parameters interpolated on their own.

Attitude channel: a schedule whose rows carry ``attitude_gain`` ``k_theta`` [rad/s of rate command per rad
of attitude error] subtracts the attitude error from each axis's error, ``e = -(rate error) - k_theta
(attitude error)`` (the observation's ``pitch_attitude_error``, ``yaw_attitude_error`` [rad]), before the
accelerometer term, the structural filter and the PID: the rate loop then commands a turn back to the
reference attitude, ``-k_theta`` times its error, and no longer leaves the attitude to drift
(``tests/test_schedule_channels.py`` checks the sign in flight).

Load relief (:data:`ACCEL_SIGNS`): a schedule whose rows carry ``accel_gain`` ``k_a`` [rad/s of rate
command per m/s^2 of lateral specific force] adds the IMU's accelerometers to each axis's error,
``e = -(rate error) + k_a s_axis f_axis`` (``f`` [m/s^2] the observation's ``accel_z`` for pitch and
``accel_y`` for yaw, times g0; ``s_axis`` the sign that makes the commanded rate turn the nose into the
relative wind), before the structural filter and the PID. The rate loop then tracks a turn into the wind
proportional to the sensed normal load, and its integral, which otherwise holds the attitude, settles
where the lateral specific force is zero: the vehicle weathercocks at low frequency and the rate loop
still damps it at high frequency (the accelerometer load relief of the max-q region:
docs/flex-design.md, "The slender vehicle").

The schedule's YAML (:mod:`.gainschedule`; docs/flex-design.md, "The schedule file"), a row with two
filters in series and both channels::

    variable: mass
    interpolation: nearest
    rows:
    - mass_kg: 10164.7
      kp: 0.42                  # rad of gimbal per rad/s
      ki: 0.68                  # rad per rad
      kd: 0.016                 # rad per rad/s^2
      attitude_gain: 0.5        # rad/s per rad (optional, every row or none)
      accel_gain: 0.002         # rad/s per m/s^2 (optional, every row or none)
      filter:                   # one mapping, or a list of them applied in series
      - {lead_zero_radps: 8.4, lead_pole_radps: 1400.0, lowpass_radps: 126.0, lowpass_damping: 0.41,
         notch_radps: 59.7, notch_damping: 0.51, notch_depth: 0.022}
      - {lowpass_radps: 5000.0, notch_radps: 140.0, notch_damping: 0.2, notch_depth: 0.1}

The law flies up to :data:`.pidkernel.FILTERS_MAX` filters in series per row; a schedule with more is refused.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.envs.presets import SLENDER_V1
from lvgym.errors import ConfigError

from .filters import Filter
from .gainschedule import INTERPOLATIONS, ROW_COLUMNS, SCHEDULES, VARIABLES, GainSchedule  # noqa: F401  (here as before)
from .pidkernel import (FILTER_ROW, FILTERS_MAX, FILTERS_ROWS, PID_ROW, VAR_MACH, VAR_VALUE, coefficients, fixed_tables,
                        new_state, obs_columns, pid_act_k, schedule_tables)

#: per axis (pitch, yaw): the sign ``s_axis`` of the load-relief term, so that ``+k_a s f`` commands the
#: body rate that turns the nose into the relative wind. A positive angle of attack (the air from below,
#: ``+z_b``) gives a normal force and so a specific force along ``-z_b``; a negative pitch rate turns
#: the nose towards ``+z_b``, so pitch takes ``+accel_z``; yaw: ``+beta`` gives a force along ``-y_b`` and
#: a positive yaw rate turns the nose towards ``+y_b``, so yaw takes ``-accel_y``
#: (``tests/test_load_relief.py`` checks both in a gust)
ACCEL_SIGNS = (1.0, -1.0)
#: the thesis's single gain set (6.3.1), tuned on the rigid SMILE at 28.8 s; N as Table 6.10's 28.8 s row
THESIS_SINGLE = {"kp": 8.98, "ki": 3.92, "kd": 4.57, "n": 500.0}


#: the info key of each scheduling variable read from the info (Mach comes from the observation)
_INFO_KEY = {"mass": "mass", "time": "time"}


def _check_gains(kp: float, ki: float, kd: float, n: float | None) -> float:
    """Fixed gains checked by name; returns the derivative filter coefficient (None: inf, unfiltered)."""
    for key, v in (("kp", kp), ("ki", ki), ("kd", kd)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
            raise ConfigError(f"pid.{key}", v, "a finite gain >= 0")
    n = math.inf if n is None else float(n)
    if not n > 0.0:
        raise ConfigError("pid.n", n, "a derivative filter coefficient > 0 rad/s (inf or None: unfiltered)")
    return n


class PIDLaw(BatchLaw):
    """Pitch and yaw rate PID (the module docstring) for ``n`` rows of the TVC envs: fixed ``gains`` (kp, ki,
    kd, n) or a ``schedule`` (:class:`GainSchedule`, its structural filters and channels), the same law on both
    axes (the vehicle is axisymmetric). ``env``: the lvgym env (single or vector) it flies; the gimbal limit
    (the action is gimbal / limit, also the output limit), the control period and the observation's layout
    come from it. The controller acts while the observation's ``controller_on`` entry is 1; a schedule on mass
    or time reads ``info["mass"]`` or ``info["time"]`` of every row. :attr:`gimbal` (n, 2) [rad]: each row's
    last command."""

    def __init__(self, env: Any, *, gains: tuple[float, float, float, float | None] | None = None,
                 schedule: GainSchedule | None = None, name: str = "pid", n: int = 1) -> None:
        if (gains is None) == (schedule is None):
            raise ValueError("PIDLaw: give fixed gains or a schedule, not both")
        task = env.unwrapped
        lay = task.observation_layout
        self.name = name
        self.dt = float(task.task.control_dt_s)
        self.limit = float(task.gimbal_limit)
        self.oc = obs_columns(lay)
        self.schedule = schedule
        signs = np.asarray(ACCEL_SIGNS, dtype=float)
        if schedule is None:
            kp, ki, kd, d = gains
            self.tb, self.su = fixed_tables(float(kp), float(ki), float(kd), _check_gains(kp, ki, kd, d), self.dt,
                                            self.limit, signs)
            self._key = None
        else:
            if schedule.accel_gain is not None and self.oc.acc[0] < 0:
                raise ConfigError("accel_gain", list(schedule.accel_gain), "a schedule without load relief: the "
                                  "env's observation has no accelerometers (observation 'sensors' or 'flight')")
            if schedule.attitude_gain is not None and self.oc.att[0] < 0:
                raise ConfigError("attitude_gain", list(schedule.attitude_gain), "a schedule without an attitude "
                                  "channel: the env's observation has no attitude errors")
            if schedule.filter_count > FILTERS_MAX:
                raise ConfigError("filter", schedule.filter_count, f"at most {FILTERS_MAX} filters in series per row")
            self.tb, self.su = schedule_tables(schedule, self.dt, self.limit, signs)
            self._key = _INFO_KEY.get(schedule.variable)
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.st = new_state(n)
        self._filters: list[Filter | None] = [None] * n      # FILTERS_ROWS: each row's filter
        self._none = np.zeros(n)

    @property
    def gimbal(self) -> np.ndarray:
        return PID_ROW.view(self.st.pid, "gimbal")

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode: the PIDs and the filters' start (the filter in use stays)."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        filt = self.st.pid[w, PID_ROW.index("filt")]
        self.st.pid[w] = PID_ROW.zeros()
        self.st.pid[w, PID_ROW.index("filt")] = filt

    def values(self, info: Mapping[str, Any]) -> np.ndarray:
        """Each row's scheduling value (n,) from the batched ``info`` (mass [kg] or time [s]), or zeros."""
        if self.su.variable != VAR_VALUE:
            return self._none
        return np.asarray(info[self._key], dtype=np.float64)

    def prepare(self, rows: np.ndarray, obs: np.ndarray, value: np.ndarray) -> None:
        """Before the kernel: the filter of each row of a linearly interpolated schedule with filters, at its
        value of the scheduling variable, discretised when it changed (no shipped schedule is such a one)."""
        if self.su.filters != FILTERS_ROWS:
            return
        coeffs = self.st.filters[:, FILTER_ROW.slice("coeffs")]
        for j, b in enumerate(rows.tolist()):
            v = float(obs[j, self.oc.mach]) * 10.0 if self.su.variable == VAR_MACH else float(value[b])
            filt = self.schedule.filter_at(v)
            if filt != self._filters[b]:
                coeffs[b] = coefficients(filt, self.dt)
                self._filters[b] = filt

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations (len(rows), n_obs)."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations).reshape(rows.size, -1)
        value = self.values(info)
        self.prepare(rows, obs, value)
        out = np.empty((rows.size, 2), np.float32)
        pid_act_k(self.tb, self.su, self.oc, self.st, rows, obs, value, out)
        return out


class PIDPolicy(RowFace):
    """Fixed-gain pitch and yaw rate PID as a benchmark :class:`~lvgym.benchmark.policy.Policy` of the TVC envs:
    one row of :class:`PIDLaw` (``act`` needs ``info["time"]``, as every lvgym ``info`` has it).
    ``last_gimbal`` (2,) [rad]: the last command."""

    def __init__(self, kp: float = THESIS_SINGLE["kp"], ki: float = THESIS_SINGLE["ki"],
                 kd: float = THESIS_SINGLE["kd"], n: float | None = THESIS_SINGLE["n"], *, env: Any,
                 name: str = "pid") -> None:
        self.law = PIDLaw(env, gains=(kp, ki, kd, n), name=name)

    @property
    def last_gimbal(self) -> np.ndarray:
        return self.law.gimbal[0].copy()


class GainScheduledPIDPolicy(PIDPolicy):
    """:class:`PIDPolicy` with gains from a :class:`GainSchedule` (a schedule object, a name in
    ``baselines/schedules`` or a path) on ``mass`` (``info["mass"]`` [kg]), ``time`` (``info["time"]`` [s]) or
    ``mach`` (the observation's Mach entry): one row of :class:`PIDLaw`."""

    def __init__(self, schedule: GainSchedule | str | Path, *, env: Any, name: str = "gs-pid") -> None:
        schedule = schedule if isinstance(schedule, GainSchedule) else GainSchedule.load(schedule)
        self.law = PIDLaw(env, schedule=schedule, name=name)


# ---------------------------------------------------------------------------- presets
def smile_single_pid(env: Any, name: str = "pid-thesis") -> PIDPolicy:
    """The thesis's single gain set (Kp 8.98, Ki 3.92, Kd 4.57, N 500) on SMILE's ``env``."""
    return PIDPolicy(env=env, name=name)


def smile_scheduled_pid(env: Any, schedule: str = "smile_thesis", name: str | None = None) -> GainScheduledPIDPolicy:
    """Gain-scheduled PID on SMILE's ``env``: ``smile_thesis`` (Table 6.10, on mass) or ``smile`` (our tuning)."""
    return GainScheduledPIDPolicy(schedule, env=env, name=name or f"gs-pid-{schedule}")


#: the gs-pid-flex schedule (``baselines/schedules/<name>.yaml``, written by ``python -m lvgym.baselines.design.flexdesign``)
#: of each vehicle a v1 env flies, keyed by the env's ``task.vehicle`` (a name, or the slender vehicle's
#: SlenderGeometry: ``SlenderAscent-v1``'s default 8.5 m x 0.2833 m, 4.5 mm tube, with load relief;
#: docs/flex-design.md)
FLEX_SCHEDULES: dict = {"smile_v1": "smile_flex", "stratos3": "stratos3_flex", SLENDER_V1.vehicle: "slender_flex"}
#: the same designs held to protocol v2's flyability (``flexdesign --noise-rate``: the gyro noise's commanded
#: gimbal rate at most 20 % of the rate limit for SMILE, 10 % for Stratos III, whose turbulence response asks
#: more), for ``gs-pid-flex-quiet`` and ``aac-quiet``; the slender vehicle has none (docs/benchmark.md)
QUIET_SCHEDULES: dict = {"smile_v1": "smile_flex_quiet", "stratos3": "stratos3_flex_quiet"}


def flex_pid(env: Any, name: str = "gs-pid-flex", schedule: str | None = None,
             quiet: bool = False) -> GainScheduledPIDPolicy:
    """``gs-pid-flex``: the filtered gain-scheduled PID designed on the non-rigid v1 flight loop of the
    vehicle ``env`` flies (:data:`FLEX_SCHEDULES`; ``quiet``: :data:`QUIET_SCHEDULES`, ``gs-pid-flex-quiet``);
    a vehicle without such a design is refused. ``schedule``: another flex schedule of that vehicle instead
    (a name in ``baselines/schedules`` or a YAML path)."""
    if schedule is not None:
        return GainScheduledPIDPolicy(schedule, env=env, name=name)
    table = QUIET_SCHEDULES if quiet else FLEX_SCHEDULES
    vehicle = getattr(env.unwrapped.task, "vehicle", None)
    if not isinstance(vehicle, Hashable) or vehicle not in table:
        raise ConfigError("env vehicle", vehicle, f"one of {list(table)}: the vehicles of a v1 env with a "
                          f"{name} schedule (python -m lvgym.baselines.design.flexdesign --vehicle ...)")
    return GainScheduledPIDPolicy(table[vehicle], env=env, name=name)


def smile_tuned_pid(env: Any, schedule: str = "smile", t_design: float = 28.8, name: str = "pid") -> PIDPolicy:
    """One gain set from our rigid tuning: the row of ``schedules/<schedule>.yaml`` nearest ``t_design``
    [s] (28.8 s, the thesis's design point), held over the flight of ``env``."""
    ours = GainSchedule.load(schedule)
    rows = ours.meta["rows"]
    i = int(np.argmin(np.abs(np.array([r["time_s"] for r in rows]) - t_design)))
    return PIDPolicy(*ours.gains(ours.points[i]), env=env, name=name)

