"""Discrete PID rate controllers for thrust-vector control (thesis 6.3), as benchmark policies.

The law of one axis (:class:`DiscretePID`), on the error ``e = reference - measured`` sampled every ``dt``
seconds, discretised with backward Euler (Simulink's "backward Euler" discrete PID, parallel form)::

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

The compiled batch (:mod:`.pidbatch`) flies up to :data:`.pidkernel.FILTERS_MAX` filters per row; a schedule
with more flies as one copy of the policy per row.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.envs.layouts import G0
from lvgym.envs.presets import SLENDER_V1
from lvgym.errors import ConfigError

from .batch import RowCopies
from .filters import FilterChain
from .gainschedule import INTERPOLATIONS, ROW_COLUMNS, SCHEDULES, VARIABLES, GainSchedule  # noqa: F401  (here as before)
from .pidbatch import PIDBatch
from .pidkernel import FILTERS_MAX

#: per axis (pitch, yaw): the sign ``s_axis`` of the load-relief term, so that ``+k_a s f`` commands the
#: body rate that turns the nose into the relative wind. A positive angle of attack (the air from below,
#: ``+z_b``) gives a normal force and so a specific force along ``-z_b``; a negative pitch rate turns
#: the nose towards ``+z_b``, so pitch takes ``+accel_z``; yaw: ``+beta`` gives a force along ``-y_b`` and
#: a positive yaw rate turns the nose towards ``+y_b``, so yaw takes ``-accel_y``
#: (``tests/test_load_relief.py`` checks both in a gust)
ACCEL_SIGNS = (1.0, -1.0)
#: the thesis's single gain set (6.3.1), tuned on the rigid SMILE at 28.8 s; N as Table 6.10's 28.8 s row
THESIS_SINGLE = {"kp": 8.98, "ki": 3.92, "kd": 4.57, "n": 500.0}


class DiscretePID:
    """One axis of the discrete PID law (see the module docstring): ``update(e) -> u``."""

    def __init__(self, kp: float, ki: float = 0.0, kd: float = 0.0, n: float | None = None, dt: float = 0.02,
                 u_min: float = -math.inf, u_max: float = math.inf) -> None:
        if not dt > 0.0:
            raise ValueError(f"dt = {dt!r}: a sampling period > 0 s")
        if not u_min < u_max:
            raise ValueError(f"output limits ({u_min!r}, {u_max!r}): u_min must be below u_max")
        self.dt, self.u_min, self.u_max = float(dt), float(u_min), float(u_max)
        self.set_gains(kp, ki, kd, n)
        self.reset()

    def set_gains(self, kp: float, ki: float, kd: float, n: float | None = None) -> None:
        """New gains (bumpless for Ki: the integral state holds the integrated ``Ki e``)."""
        n = math.inf if n is None else float(n)
        for key, v in (("kp", kp), ("ki", ki), ("kd", kd)):
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"{key} = {v!r}: a finite gain >= 0")
        if not n > 0.0:
            raise ValueError(f"n = {n!r}: a derivative filter coefficient > 0 rad/s (inf: unfiltered)")
        self.kp, self.ki, self.kd, self.n = float(kp), float(ki), float(kd), n

    def reset(self) -> None:
        self.integral = 0.0
        self.deriv = 0.0
        self.e_prev: float | None = None
        self.saturated = False

    def update(self, e: float, enabled: bool = True) -> float:
        e = float(e)
        if not enabled:
            self.deriv, self.e_prev, self.saturated = 0.0, None, False
            return 0.0
        de = 0.0 if self.e_prev is None else e - self.e_prev
        if math.isinf(self.n):
            d = self.kd * de / self.dt
        else:
            d = (self.deriv + self.kd * self.n * de) / (1.0 + self.n * self.dt)
        p = self.kp * e
        i = self.integral + self.ki * self.dt * e
        v = p + i + d
        if (v > self.u_max and e * self.ki > 0.0) or (v < self.u_min and e * self.ki < 0.0):
            i = self.integral                       # clamp: do not integrate further into the limit
            v = p + i + d
        self.integral, self.deriv, self.e_prev = i, d, e
        u = min(max(v, self.u_min), self.u_max)
        self.saturated = u != v
        return u


class PIDPolicy:
    """Pitch and yaw rate PID (identical gains per axis, the vehicle being axisymmetric) as a benchmark
    :class:`~lvgym.benchmark.policy.Policy` of the TVC envs.

    ``env``: the lvgym env (single or vector) it flies; the gimbal limit (the action is gimbal / limit,
    also the output limit), the control period and the observation's layout come from it. The controller
    acts while the observation's ``controller_on`` entry is 1. ``act`` needs ``info["time"]`` (every lvgym
    ``info`` has it, the reset's too).
    """

    def __init__(self, kp: float = THESIS_SINGLE["kp"], ki: float = THESIS_SINGLE["ki"],
                 kd: float = THESIS_SINGLE["kd"], n: float | None = THESIS_SINGLE["n"], *, env: Any,
                 name: str = "pid") -> None:
        task = env.unwrapped
        self.name = name
        self.dt = float(task.task.control_dt_s)
        self.limit = float(task.gimbal_limit)
        lay = task.observation_layout
        self._i_err = [lay.index("pitch_rate_error"), lay.index("yaw_rate_error")]
        self._i_on, self._i_mach = lay.index("controller_on"), lay.index("mach_over_10")
        self.axes = [DiscretePID(kp, ki, kd, n, self.dt, -self.limit, self.limit) for _ in range(2)]
        #: the accelerometers (pitch: accel_z, yaw: accel_y) where the observation has them
        self._i_acc = [lay.index("accel_z"), lay.index("accel_y")] if "accel_z" in lay.names else None
        #: the attitude errors (pitch, yaw) where the observation has them
        self._i_att = ([lay.index("pitch_attitude_error"), lay.index("yaw_attitude_error")]
                       if "pitch_attitude_error" in lay.names else None)
        self.accel_gain = 0.0                             # load relief [rad/s per m/s^2], see the module docstring
        self.attitude_gain = 0.0                          # attitude channel [rad/s per rad], see the module docstring
        self.accel_signs = np.asarray(ACCEL_SIGNS)        # s_axis of the load-relief term, per axis
        self.chains: list[FilterChain] | None = None      # structural filters of the error, per axis
        self._filtering = False
        self.last_gimbal = np.zeros(2)

    def reset(self) -> None:
        for pid in self.axes:
            pid.reset()
        self._filtering = False
        self.last_gimbal = np.zeros(2)

    def filtered(self, errors: np.ndarray, on: bool) -> np.ndarray:
        """The errors through the axes' structural filters (unchanged without filters or while off);
        the filters start in the steady state of the error when the controller switches on."""
        if self.chains is None or not on:
            self._filtering = False
            return errors
        if not self._filtering:
            for chain, e in zip(self.chains, errors):
                chain.reset(e)
            self._filtering = True
        return np.array([chain.update(e) for chain, e in zip(self.chains, errors)])

    def enabled(self, observation: np.ndarray) -> bool:
        """The env's controller-on flag for the coming step."""
        return float(observation[self._i_on]) >= 0.5

    def schedule_gains(self, observation: np.ndarray, info: dict[str, Any]) -> None:
        """Hook for gain scheduling (nothing for fixed gains)."""

    def errors(self, obs: np.ndarray) -> np.ndarray:
        """The loop's errors [rad/s], pitch and yaw: reference - rate, minus ``k_theta`` times the attitude
        error when ``attitude_gain`` is not zero, plus the load-relief rate command ``k_a s_axis f_axis``
        when ``accel_gain`` is not zero (module docstring)."""
        e = -obs[self._i_err]
        if self.attitude_gain != 0.0:
            e = e - self.attitude_gain * obs[self._i_att]
        if self.accel_gain != 0.0:
            e = e + self.accel_gain * G0 * self.accel_signs * obs[self._i_acc]
        return e

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        on = self.enabled(obs)
        self.schedule_gains(obs, info)
        errors = self.filtered(self.errors(obs), on)
        self.last_gimbal = np.array([pid.update(e, on) for pid, e in zip(self.axes, errors)])
        return np.clip(self.last_gimbal / self.limit, -1.0, 1.0).astype(np.float32)

    def batch(self, n: int) -> PIDBatch | RowCopies:
        """The same controller for ``n`` rows of a batched env, stepped together (:mod:`.batch`): the compiled
        :class:`.pidbatch.PIDBatch` for a PIDPolicy or GainScheduledPIDPolicy as built (both axes with the
        same gains, limits and period; filters only from a schedule), else one copy of the policy per row."""
        return PIDBatch(self, n) if self._batchable() else RowCopies(self, n)

    def _batchable(self) -> bool:
        kind = type(self)
        if kind not in (PIDPolicy, GainScheduledPIDPolicy):        # a subclass may change the law
            return False
        a, b = self.axes
        if not (a.dt == b.dt and a.u_min == b.u_min == -self.limit and a.u_max == b.u_max == self.limit):
            return False
        if kind is GainScheduledPIDPolicy:
            return (self.chains is None) == (self.schedule.filters is None) and self.schedule.filter_count <= FILTERS_MAX
        return self.chains is None and (a.kp, a.ki, a.kd, a.n) == (b.kp, b.ki, b.kd, b.n)


class GainScheduledPIDPolicy(PIDPolicy):
    """:class:`PIDPolicy` with gains from a :class:`GainSchedule` updated at every step: on ``mass``
    (``info["mass"]`` [kg]), ``time`` (``info["time"]`` [s]) or ``mach`` (the observation's Mach entry)."""

    def __init__(self, schedule: GainSchedule | str | Path, *, env: Any, name: str = "gs-pid") -> None:
        self.schedule = schedule if isinstance(schedule, GainSchedule) else GainSchedule.load(schedule)
        g = self.schedule.gains(self.schedule.points[0])
        super().__init__(*g, env=env, name=name)
        if self.schedule.accel_gain is not None and self._i_acc is None:
            raise ConfigError("accel_gain", list(self.schedule.accel_gain), "a schedule without load relief: the "
                              "env's observation has no accelerometers (observation 'sensors' or 'flight')")
        if self.schedule.attitude_gain is not None and self._i_att is None:
            raise ConfigError("attitude_gain", list(self.schedule.attitude_gain), "a schedule without an attitude "
                              "channel: the env's observation has no attitude errors")
        if self.schedule.filters is not None:
            f0 = self.schedule.filter_at(self.schedule.points[0])
            self.chains = [FilterChain(f0, self.dt) for _ in self.axes]
        self.value = float("nan")

    def variable(self, observation: np.ndarray, info: dict[str, Any]) -> float:
        v = self.schedule.variable
        if v == "mass":
            return float(info["mass"])
        if v == "time":
            return float(info["time"])
        return float(observation[self._i_mach]) * 10.0

    def schedule_gains(self, observation: np.ndarray, info: dict[str, Any]) -> None:
        self.value = self.variable(observation, info)
        g = self.schedule.gains(self.value)
        for pid in self.axes:
            pid.set_gains(*g)
        self.accel_gain = self.schedule.accel_gain_at(self.value)
        self.attitude_gain = self.schedule.attitude_gain_at(self.value)
        if self.chains is not None:
            filt = self.schedule.filter_at(self.value)
            if filt == self.chains[0].filter:             # unchanged (a nearest-row schedule, mostly)
                return
            coeffs = filt.discrete(self.dt)               # the same filter on both axes
            for chain in self.chains:
                chain.set_filter(filt, coeffs)


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

