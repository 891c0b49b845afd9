"""The option groups of an ascent task: one frozen, validated dataclass per group.

A :class:`~.spec.TaskSpec` is the vehicle, the flight model and one value of each group below. Every
field has its own docstring (the options table of docs/rl.md is generated from them) and, where it has
one, its allowed range next to it (:func:`option`); a bad value raises
:class:`~lvgym.errors.ConfigError` naming the key, the value and what is allowed, in one line. A field's
name is also its keyword: ``gymnasium.make(env_id, mission_time_s=30.0)`` sets ``timing.mission_time_s``
(the names are unique across the groups). Units are in the names; angles are in degrees only where the
name says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from lvgym.errors import ConfigError, check_bool, check_choice, check_number
from lvgym.simulator import MODE_BASES, SITES, SLOSH_FREQUENCIES
from lvgym.simulator.spec import LaunchSite

from .dispersions import RANDOMIZE, RANDOMIZE_V0
from .faults import FAULT_NAMES

#: the rewards an env gives (``reward_kind``; :mod:`.scorereward`)
REWARD_KINDS = ("weighted", "score_v2")

__all__ = ["ActuatorOptions", "AtmosphereOptions", "CoastOptions", "DispersionOptions", "FaultOptions",
           "GuidanceOptions", "LaunchOptions", "LimitOptions", "Options", "PhysicsOptions", "RewardOptions", "Rule",
           "SensorOptions", "TimingOptions", "option", "rule_of", "CONTROLS", "OBSERVATIONS", "REFERENCES", "REFERENCE_VELOCITIES",
           "REWARD_KINDS", "WIND_TIERS"]

#: protocol v0's wind tiers, then v1's, then ``random_gust`` (v1's gust alone, for the error budget)
WIND_TIERS = ("none", "profile", "gust", "turbulence", "random", "turbulence_gust", "maxq_gust", "random_gust")
OBSERVATIONS = ("state", "sensors", "flight")
REFERENCES = ("zero_rate", "gravity_turn")
REFERENCE_VELOCITIES = ("inertial", "earth")
CONTROLS = ("tvc", "rcs")
_META = "lvgym.option"


@dataclass(frozen=True)
class Rule:
    """What values a field takes: a number in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``; whole with
    ``integer``), one of ``choices``, a bool (``boolean``); ``optional``: None is allowed too."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    integer: bool = False
    choices: tuple | None = None
    boolean: bool = False
    optional: bool = False

    def check(self, key: str, value: Any) -> None:
        """Raise a one-line :class:`~lvgym.errors.ConfigError` naming ``key`` unless ``value`` is allowed."""
        if value is None and self.optional:
            return
        try:
            if self.choices is not None:
                check_choice(key, value, self.choices)
            elif self.boolean:
                check_bool(key, value)
            elif self.lo is not None:
                check_number(key, value, self.lo, self.hi, integer=self.integer, lo_open=self.lo_open)
        except ConfigError as exc:
            if not self.optional:
                raise
            raise ConfigError(key, value, "true, false or None" if self.boolean else f"None or {exc.allowed}") from None

    def allowed(self) -> str:
        """What is allowed, in words (the options table's column)."""
        if self.choices is not None:
            text = ", ".join(f"`{c}`" for c in self.choices)
        elif self.boolean:
            return "true, false or None" if self.optional else "true or false"
        elif self.lo is not None:
            left = "(" if self.lo_open else "["
            text = f"{'integer' if self.integer else 'number'} in {left}{self.lo:g}, {self.hi:g}]"
        else:
            return "None" if self.optional else ""
        return f"None or {text}" if self.optional else text


def option(default: Any, **rule: Any) -> Any:
    """A field with its :class:`Rule` (checked by :class:`Options`)."""
    return field(default=default, metadata={_META: Rule(**rule)})


def rule_of(f: Any) -> Rule | None:
    """The :class:`Rule` of a dataclass field (None: checked by its group's own code)."""
    return f.metadata.get(_META)


class Options:
    """Base of the option groups: checks every field that has a :class:`Rule`, then :meth:`check`."""

    def __post_init__(self) -> None:
        for f in fields(self):
            rule = rule_of(f)
            if rule is not None:
                rule.check(f.name, getattr(self, f.name))
        self.check()

    def check(self) -> None:
        """The group's own checks (between fields, or of a value no :class:`Rule` describes)."""

    def changes(self) -> dict[str, Any]:
        """The fields that differ from the group's defaults, by name (in field order)."""
        base = type(self)()
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) != getattr(base, f.name)}


@dataclass(frozen=True)
class LaunchOptions(Options):
    """Where and how the vehicle leaves the ground."""

    site: Any = "andoya"
    """the launch site: a key of ``lvgym.simulator.SITES`` (or a ``LaunchSite``)"""
    elevation_deg: float = option(90.0, lo=1.0, hi=90.0)
    """the launcher's elevation [deg] (90: vertical)"""
    rail_length_m: float = option(0.0, lo=0.0, hi=1000.0)
    """the launch rail's length [m] (0: lift-off straight from the pad)"""

    def check(self) -> None:
        if not isinstance(self.site, LaunchSite) and (not isinstance(self.site, str) or self.site not in SITES):
            raise ConfigError("site", self.site, f"one of {sorted(SITES)} or a LaunchSite")


@dataclass(frozen=True)
class TimingOptions(Options):
    """The episode's clock: its length, the policy's period, the integrator's step, when the policy acts."""

    mission_time_s: float = option(60.0, lo=0.0, hi=3600.0, lo_open=True)
    """the episode's length [s]; reaching it truncates the episode"""
    control_dt_s: float = 0.02
    """the policy's period [s]: a whole multiple of ``physics_dt_s``, at most 1 s"""
    physics_dt_s: float = option(0.01, lo=0.0, hi=0.05, lo_open=True)
    """the largest RK4 step [s] of the physics (the servo's and the IMU filters' step too)"""
    controller_on_after_s: float = option(2.0, lo=0.0, hi=3600.0)
    """the policy is off (gimbal held at zero) before this time [s], and while no engine burns (a staging coast)"""
    action_delay_steps: int = option(0, lo=0, hi=50, integer=True)
    """control periods between sampling and actuation: the flight computer's computational delay (0: an
    action acts at once; protocol v1: 1)"""

    def check(self) -> None:
        check_number("control_dt_s", self.control_dt_s, self.physics_dt_s, 1.0)
        n = self.control_dt_s / self.physics_dt_s
        if abs(n - round(n)) > 1e-6:
            raise ConfigError("control_dt_s", self.control_dt_s,
                              f"a whole multiple of physics_dt_s = {self.physics_dt_s}")

    @property
    def substeps(self) -> int:
        """Physics steps per control period."""
        return int(round(self.control_dt_s / self.physics_dt_s))


@dataclass(frozen=True)
class PhysicsOptions(Options):
    """The flight model's options besides its name (``model``): bending modes, aeroelastic loads, slosh
    dampers (the Simulator's, :mod:`lvgym.simulator`)."""

    n_modes: int | None = option(None, lo=0, hi=10, integer=True, optional=True)
    """bending modes per plane (None: the vehicle file's)"""
    aeroelastic: bool | None = option(False, boolean=True, optional=True)
    """the strip-theory aeroelastic loads: on, off, or None (the vehicle file's flag); off in v0"""
    mode_interval_s: float | None = option(None, lo=0.0, hi=1e5, lo_open=True, optional=True)
    """how often [s] the bending modes are recomputed along the flight (None: the vehicle file's)"""
    mode_basis: str = option("held", choices=MODE_BASES)
    """across a recomputation the modal state is ``held`` (v0) or ``projected`` onto the new modes"""
    slosh_frequency: str = option("vacuum_thrust", choices=SLOSH_FREQUENCIES)
    """the slosh dampers' frequency: tabulated from the ``vacuum_thrust`` (v0) or from the axial
    ``specific_force`` the pendulums feel"""


@dataclass(frozen=True)
class AtmosphereOptions(Options):
    """The air the vehicle flies through: the wind (:func:`~.spec.wind_spec` gives each tier's model)."""

    wind: str = option("none", choices=WIND_TIERS)
    """the wind tier: ``profile`` (a fixed 20 m/s west wind), ``gust`` (a 15 m/s 1-cosine gust at 3 km),
    ``turbulence`` (moderate Dryden over 10 m/s), ``random`` (a random jet stream plus Dryden); v1's
    ``turbulence_gust``, ``maxq_gust``; ``random_gust`` (v1's gust alone)"""


@dataclass(frozen=True)
class DispersionOptions(Options):
    """Which of the Monte Carlo dispersions (:mod:`.dispersions`) each reset draws from the env's generator."""

    randomize: frozenset = frozenset()
    """the names drawn at every reset, a set of ``RANDOMIZE`` (``True``: protocol v0's six,
    ``RANDOMIZE_V0``; ``False`` or None: none; one name alone is a set of one)"""

    def check(self) -> None:
        r = self.randomize
        names = (set(RANDOMIZE_V0) if r is True else set() if r in (False, None) else {r} if isinstance(r, str)
                 else set(r))
        bad = sorted(names - set(RANDOMIZE))
        if bad:
            raise ConfigError("randomize", bad[0], f"True (the v0 set {RANDOMIZE_V0}), False or a set of {RANDOMIZE}")
        object.__setattr__(self, "randomize", frozenset(names))


@dataclass(frozen=True)
class SensorOptions(Options):
    """What the policy observes and the sensors' errors (docs/sensors.md). ``sensors`` adds, with
    ``sensor_noise`` randomised, a constant gyro bias N(0, ``gyro_bias_radps``) and white noise per sample.
    ``flight`` models a tactical-grade strapdown IMU at ``imu_station_m`` (:mod:`lvgym.simulator.imu`,
    :mod:`lvgym.envs.flightcomputer`): gyros that see the bending slope rate through their bandwidth and
    an anti-aliasing low-pass, both advanced at every physics step; accelerometers at the same station with
    lever arm and bending through the same low-pass; with ``sensor_noise`` randomised, a drifting gyro bias
    and angle random walk; the attitude is the strapdown integration of the sampled rates from the true
    attitude at the reset. The v0 defaults of the keys ``sensors`` and ``flight`` share stay;
    :data:`~.presets.FLIGHT_SENSORS` holds the tactical-grade values of the v1 envs."""

    observation: str = option("state", choices=OBSERVATIONS)
    """``state`` (the ideal state, for research: no flight computer has it), ``sensors`` (v0: a gyro that
    sees the bending slope rate, constant bias, white noise, the true attitude plus noise) or ``flight``
    (protocol v1: what a flight computer samples)"""
    imu_station_m: float | None = option(None, lo=-1e4, hi=1e4, optional=True)
    """the IMU's station along x_b [m] (None: a quarter of the vehicle's length aft of the nose)"""
    history: int = option(0, lo=0, hi=64, integer=True)
    """the observation is the last ``history`` samples and actions (:mod:`.history`; 0: the sample alone)"""
    gyro_noise_radps: float = option(2e-4, lo=0.0, hi=1.0)
    """``sensors``: the gyro's white noise [rad/s] per sample"""
    gyro_bias_radps: float = option(1e-3, lo=0.0, hi=1.0)
    """the gyro's turn-on bias [rad/s], N(0, this) per axis; v0's 1e-3 rad/s (206 deg/h, an industrial
    MEMS part) is far above a tactical IMU's; the v1 envs take 1.5e-5 (3 deg/h; tactical FOG and MEMS
    gyros after calibration: 1-10 deg/h)"""
    accel_noise_mps2: float = option(0.05, lo=0.0, hi=100.0)
    """the accelerometers' white noise [m/s^2] per sample; the v1 envs take 0.02 (a tactical
    accelerometer's 0.05-0.1 m/s/sqrt(h) velocity random walk is about 0.01 m/s^2 at 50 Hz, doubled for
    the vibration of a burning motor)"""
    attitude_noise_rad: float = option(1e-3, lo=0.0, hi=1.0)
    """``sensors``: the attitude's white noise [rad] per sample"""
    gyro_bandwidth_hz: float = option(80.0, lo=0.0, hi=1e4, lo_open=True)
    """``flight``: the gyros' second-order bandwidth [Hz] (tactical FOG and MEMS gyros have 50-500 Hz;
    the low end taken)"""
    gyro_damping: float = option(0.7, lo=0.05, hi=10.0)
    """``flight``: the gyros' damping ratio [-]"""
    antialias_hz: float = option(20.0, lo=0.0, hi=1e4, lo_open=True)
    """``flight``: the second-order Butterworth anti-aliasing low-pass [Hz] of gyros and accelerometers
    (below the 25 Hz Nyquist frequency of 50 Hz sampling; the 9-14 Hz bending modes pass with phase lag,
    as in flight)"""
    gyro_arw_rad_per_sqrt_s: float = option(4.4e-5, lo=0.0, hi=0.1)
    """``flight``: the gyros' angle random walk [rad/sqrt(s)] (0.15 deg/sqrt(h); tactical grade
    0.1-0.3): white rate noise ARW / sqrt(control_dt_s) per sample"""
    gyro_bias_rw_radps_per_sqrt_s: float = option(1.5e-6, lo=0.0, hi=0.1)
    """``flight``: the gyro bias's random walk [rad/s/sqrt(s)] (a 1-sigma wander of 3 deg/h over a 100 s
    flight: the bias instability of a tactical-grade gyro, 1-10 deg/h)"""
    privileged_info: bool = option(False, boolean=True)
    """the step's ``info`` also holds what no flight sensor gives (``omega_bi_b``, ``m_aero_b``, ``thrust``,
    ``gimbal_arm``, ``vectored_share``, ``J_b_diag``, ``v_air_b``, ``misalignment``, ``actuator_effectiveness``
    and the wind ahead, ``wind_ahead_n`` and ``m_aero_ahead_b``): for a privileged reference or a teacher
    policy, never for a scored causal one"""
    vehicle_info: bool = option(False, boolean=True)
    """the observation ends with the vehicle's design parameters at lift-off, constant over the episode
    (:data:`~.layouts.VEHICLE_INFO`: mass, pitch inertia, L/D, thrust-to-weight, control power, the first
    bending and slosh frequencies, the slosh mass share; :mod:`lvgym.vehicle.designinfo`): what a flight
    computer can be loaded with, the ``informed`` track of the launcher family's suite"""
    fault_info: bool = option(False, boolean=True)
    """privileged: the observation ends with the row's in-flight fault once it has struck
    (:data:`~.layouts.FAULT_INFO`: its kind's size on its axis, zeros before the onset; after the
    ``vehicle_info`` block): what a teacher policy may see and no flight computer knows, never a scored
    causal policy's observation"""


@dataclass(frozen=True)
class ActuatorOptions(Options):
    """How the policy acts: the thrust-vector servo, or roll pulses of reaction control."""

    control: str = option("tvc", choices=CONTROLS)
    """``tvc`` (Box(-1, 1) per gimbal axis, scaled to the gimbal limit) or ``rcs`` (MultiDiscrete([3]) roll
    pulses: negative, none, positive)"""
    actuator_frequency: float = option(15.0, lo=0.1, hi=1000.0)
    """the servo's natural frequency [rad/s] (second order)"""
    actuator_damping: float = option(0.7, lo=0.05, hi=10.0)
    """the servo's damping ratio [-]"""
    gimbal_limit_deg: float | None = option(None, lo=0.0, hi=30.0, lo_open=True, optional=True)
    """the gimbal limit [deg] (None: the engine's, 5 deg if it has none)"""
    gimbal_rate_limit_degps: float = option(30.0, lo=0.1, hi=1000.0)
    """the servo's rate limit [deg/s]"""
    rcs_torque_nm: float = option(2.0, lo=0.0, hi=1e6)
    """``rcs``: the roll torque of a pulse [N m] (an assumption: the thesis gives no thruster size)"""


@dataclass(frozen=True)
class GuidanceOptions(Options):
    """The reference the policy tracks (the reward's rate errors are against it)."""

    reference: str = option("zero_rate", choices=REFERENCES)
    """``zero_rate`` (hold the attitude) or ``gravity_turn`` (a pitch kick, then the rate that keeps the
    flight-path angle's turn)"""
    reference_velocity: str = option("inertial", choices=REFERENCE_VELOCITIES)
    """the velocity whose angle from the vertical the gravity turn follows: ``inertial`` (v0) or ``earth``
    (relative to the rotating Earth: at Andøya the inertial one carries some 160 m/s of its rotation)"""
    kick_start_s: float = option(5.0, lo=0.0, hi=3600.0)
    """the gravity turn's pitch kick starts [s]"""
    kick_end_s: float = option(15.0, lo=0.0, hi=3600.0)
    """the pitch kick ends [s] (after ``kick_start_s``)"""
    kick_angle_deg: float = option(5.0, lo=-90.0, hi=90.0)
    """the pitch kick's angle [deg]"""

    def check(self) -> None:
        if self.kick_end_s <= self.kick_start_s:
            raise ConfigError("kick_end_s", self.kick_end_s, f"a time after kick_start_s = {self.kick_start_s}")


@dataclass(frozen=True)
class RewardOptions(Options):
    """The reward's weights (docs/rl.md, "Reward")."""

    rate_weights: tuple = (0.0, 1.0, 1.0)
    """the rate errors' weights (roll, pitch, yaw) per rad, each >= 0"""
    effort_weight: float = option(1e-3, lo=0.0, hi=1e6)
    """the weight per rad of gimbal per second"""
    effort_rate_weight: float = option(1e-4, lo=0.0, hi=1e6)
    """the weight per rad/s of gimbal rate per second"""
    failure_penalty_rad_per_s: float = option(0.1, lo=0.0, hi=1e6)
    """on termination, the penalty per second of mission time left [rad/s]"""
    reward_kind: str = option("weighted", choices=REWARD_KINDS)
    """``weighted``: the weighted terms above; ``score_v2``: minus each step's increment of protocol v2's score
    (:mod:`.scorereward`: the pitch and yaw rate errors, the failure penalty, and a break of the flyability rule
    charged as a failure that ends the episode; the weights are not used)"""

    def check(self) -> None:
        try:
            w = tuple(self.rate_weights)
        except TypeError:
            w = ()
        if len(w) != 3 or any(not isinstance(v, (int, float)) or v < 0 for v in w):
            raise ConfigError("rate_weights", self.rate_weights, "three numbers >= 0 (roll, pitch, yaw) per rad")
        object.__setattr__(self, "rate_weights", tuple(float(v) for v in w))


@dataclass(frozen=True)
class LimitOptions(Options):
    """The limits whose crossing terminates an episode (beside a non-finite state)."""

    qalpha_limit_pa_deg: float = option(250e3, lo=0.0, hi=1e9)
    """the structural limit of dynamic pressure times total angle of attack [Pa deg]"""
    attitude_limit_deg: float = option(30.0, lo=0.1, hi=180.0)
    """the largest attitude error [deg] against the reference axis"""


@dataclass(frozen=True)
class CoastOptions(Options):
    """What holds the vehicle while no engine burns after ``controller_on_after_s`` (a staging coast)."""

    coast_control: bool = option(False, boolean=True)
    """reaction control holds the vehicle into the relative wind (:mod:`.coast`: a proportional-derivative
    law on the angle of attack, the sideslip and the body rates)"""
    coast_torque_nm: float = option(1000.0, lo=0.0, hi=1e6)
    """the coast control's largest moment [N m] in each of pitch and yaw"""
    coast_bandwidth_radps: float = option(3.0, lo=0.01, hi=100.0)
    """the coast control's bandwidth [rad/s]"""
    settling_thrust_n: float = option(0.0, lo=0.0, hi=1e7)
    """ullage motors' axial thrust [N] along +x_b through the coast, so that the propellant stays settled
    against the drag (0: none)"""


@dataclass(frozen=True)
class FaultOptions(Options):
    """The in-flight fault each reset draws when ``randomize`` holds ``fault`` (:mod:`.faults`)."""

    fault_kinds: tuple = FAULT_NAMES
    """the kinds a fault is drawn from, an equal share each: names of ``FAULT_KINDS`` (``effectiveness``,
    ``bandwidth``, ``stuck``, ``thrust``, ``gyro_bias``, ``misalignment``)"""
    fault_onset_s: tuple = (5.0, 40.0)
    """the window of flight time [s] the onset is drawn in, uniformly (low, high)"""

    def check(self) -> None:
        kinds = (self.fault_kinds,) if isinstance(self.fault_kinds, str) else tuple(self.fault_kinds)
        if not kinds or any(k not in FAULT_NAMES for k in kinds) or len(set(kinds)) != len(kinds):
            raise ConfigError("fault_kinds", self.fault_kinds, f"distinct names of {FAULT_NAMES}, at least one")
        object.__setattr__(self, "fault_kinds", kinds)
        try:
            lo, hi = (float(v) for v in self.fault_onset_s)
        except (TypeError, ValueError):
            lo, hi = math.nan, math.nan
        if not 0.0 <= lo <= hi <= 1e5:
            raise ConfigError("fault_onset_s", self.fault_onset_s, "two times 0 <= low <= high [s]")
        object.__setattr__(self, "fault_onset_s", (lo, hi))
