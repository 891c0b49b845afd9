"""Task options of the ascent environments: one frozen, validated dataclass per env instance.

Every keyword an env takes lands here; a bad value raises :class:`~lvgym.errors.ConfigError` naming the
key, the value and what is allowed. Defaults of each env are set by its class (see ``ascent.py``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from lvgym.errors import ConfigError, check_bool, check_choice, check_number, did_you_mean
from lvgym.simulator import MODE_BASES, MODELS, SLOSH_FREQUENCIES

#: protocol v0's wind tiers, then v1's, then ``random_gust`` (v1's gust alone, for the error budget)
WIND_TIERS = ("none", "profile", "gust", "turbulence", "random", "turbulence_gust", "maxq_gust", "random_gust")
#: the onset altitudes [m] of the ``maxq_gust`` tier's gust: SMILE's max q is at 9.8 km (docs/vehicles.md)
MAXQ_GUST_ONSET_M = (8000.0, 11500.0)
#: protocol v0's randomisations (what ``randomize=True`` means)
RANDOMIZE_V0 = ("wind", "thrust_misalignment", "mass", "slosh_damping", "bending_frequency", "sensor_noise")
#: every randomisation by name (``lvgym.envs.functional.AscentFuncEnv.dispersions`` draws them)
RANDOMIZE = RANDOMIZE_V0 + ("aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency", "bending_damping",
                            "servo_bandwidth", "servo_delay", "imu_station")
#: the ``imu_station`` dispersion: the IMU station shifted along x_b by N(0, sigma) with sigma this fraction
#: of the vehicle's length, clipped at 3 sigma (docs/benchmark.md "Dispersions"); the timeline tabulates the
#: mode shapes at ``IMU_STATION_INTERVALS`` + 1 evenly spaced stations over the +-3 sigma range (the
#: nominal one among them) and a row interpolates linearly between them
IMU_STATION_SIGMA = 0.005
IMU_STATION_INTERVALS = 24
OBSERVATIONS = ("state", "sensors", "flight")
REFERENCES = ("zero_rate", "gravity_turn")
REFERENCE_VELOCITIES = ("inertial", "earth")
CONTROLS = ("tvc", "rcs")


def wind_spec(tier: str, mission_time: float) -> Any:
    """The wind model (a mapping for ``lvgym.environment.make``) of a wind tier.

    ``profile``: a fixed 20 m/s west wind above a power-law boundary layer; ``gust``: a 15 m/s
    1-cosine gust 200 m long at 3 km; ``turbulence``: moderate Dryden turbulence (MIL-F-8785C) over a
    10 m/s west wind; ``random``: a random jet-stream profile plus moderate Dryden turbulence.
    Protocol v1's: ``turbulence_gust``: ``turbulence`` plus a random 1-cosine gust (``random_gust``: 5-15 m/s,
    30-300 m, from any direction, onset 1-15 km); ``maxq_gust``: a random jet-stream profile plus a random
    gust whose onset lies in the max-q region (``MAXQ_GUST_ONSET_M``); ``random_gust``: the random gust of
    ``turbulence_gust`` alone (``experiments.error_budget.budget`` flies it to share out the error)."""
    profile = {"model": "profile", "altitude_m": [0.0, 1000.0, 10000.0, 100000.0],
               "speed": [5.0, 12.0, 20.0, 20.0], "direction_deg": [270.0, 270.0, 270.0, 270.0]}
    if tier == "none":
        return "none"
    if tier == "profile":
        return profile
    if tier == "gust":
        return {"model": "gust", "amplitude": 15.0, "length": 200.0, "direction_deg": 270.0, "onset": 3000.0}
    if tier == "turbulence":
        return {"model": "sum", "models": [{"model": "profile", "altitude_m": [0.0, 100000.0],
                                            "speed": [10.0, 10.0], "direction_deg": [270.0, 270.0]},
                                           {"model": "dryden", "intensity": "moderate", "wind_from_deg": 270.0}]}
    if tier == "random":
        return {"model": "sum", "models": [{"model": "jet_stream"}, {"model": "dryden", "intensity": "moderate"}]}
    if tier == "turbulence_gust":
        return {"model": "sum", "models": [*wind_spec("turbulence", mission_time)["models"], {"model": "random_gust"}]}
    if tier == "random_gust":
        return {"model": "sum", "models": [{"model": "random_gust"}]}
    if tier == "maxq_gust":
        return {"model": "sum", "models": [{"model": "jet_stream"},
                                           {"model": "random_gust", "onset_m": list(MAXQ_GUST_ONSET_M)}]}
    raise ConfigError("wind", tier, f"one of {WIND_TIERS}")


#: options of the ``flight`` observation for a tactical-grade IMU where the v0 defaults of the shared keys
#: are not (see :class:`TaskSpec`): a turn-on gyro bias of 3 deg/h per axis (1-10 deg/h for tactical FOG
#: and MEMS gyros after calibration) and accelerometer noise of 0.02 m/s^2 per 50 Hz sample (a
#: tactical accelerometer's 0.05-0.1 m/s/sqrt(h) velocity random walk gives about 0.01 m/s^2 at 50 Hz;
#: doubled for the vibration of a burning motor)
FLIGHT_DEFAULTS = {"observation": "flight", "gyro_bias_radps": 1.5e-5, "accel_noise_mps2": 0.02}


@dataclass(frozen=True)
class TaskSpec:
    """Options of an ascent task (units in the names; angles in degrees only where the name says so).

    vehicle: shipped name or path; model: ``rigid | slosh | flex | nonrigid``; site: key of
    ``lvgym.simulator.SITES``; elevation_deg, rail_length_m: the launcher; mission_time_s: episode length
    (truncation); control_dt_s / physics_dt_s: policy period and largest RK4 step; controller_on_after_s:
    the controller is off (gimbal held at zero) before this time and while no engine burns (staging coast);
    wind: a tier of ``WIND_TIERS``; randomize: the set of ``RANDOMIZE`` names drawn from the env's generator
    at every reset (``True``: protocol v0's six, ``RANDOMIZE_V0``); observation: ``state`` (the ideal
    state, for research: no flight computer has it), ``sensors`` (v0: a gyro at ``imu_station_m`` that sees the bending slope rate, constant bias, white
    noise, the true attitude plus noise) or ``flight`` (protocol v1: what a flight computer samples, see
    below and docs/sensors.md);
    reference: ``zero_rate`` or ``gravity_turn`` (pitch kick, then the rate that keeps the flight-path
    angle's turn); reference_velocity: the velocity whose angle from the vertical the gravity turn
    follows, ``inertial`` (v0) or ``earth`` (relative to the rotating Earth: at Andøya the inertial one
    carries about 160 m/s of Earth rotation); action_delay_steps: control periods between sampling and
    actuation (the flight computer's computational delay; 0: an action acts at once); control: ``tvc``
    (Box(-1, 1) per gimbal axis) or ``rcs`` (MultiDiscrete([3]) roll pulses);
    actuator: natural frequency [rad/s], damping, gimbal limit [deg] (None: the engine's), rate limit
    [deg/s]; rcs_torque_nm: roll torque of a pulse; reward: rate_weights (roll, pitch, yaw) per rad,
    effort_weight per rad of gimbal per second, effort_rate_weight per rad/s of gimbal rate per second,
    failure_penalty_rad_per_s times the remaining mission time on termination; qalpha_limit_pa_deg:
    structural limit of dynamic pressure times total angle of attack; attitude_limit_deg: largest
    attitude error; n_modes: bending modes per plane (None: the vehicle's); coast_control: while no engine
    burns after ``controller_on_after_s`` (a staging coast), reaction control holds the vehicle into the
    relative wind (:mod:`.coast`: a proportional-derivative law on the angle of attack, the sideslip and the
    body rates of bandwidth ``coast_bandwidth_radps`` [rad/s], each of pitch and yaw limited to
    ``coast_torque_nm`` [N m]);
    settling_thrust_n: axial thrust [N] of ullage motors along +x_b through the same coasts, so that the
    propellant stays settled against the drag (0: none); aeroelastic: the strip-theory
    aeroelastic loads (True, False, None: the vehicle file's flag; False in v0); mode_interval_s, mode_basis,
    slosh_frequency: the Simulator's ``mode_interval`` (None: the vehicle's), ``mode_basis`` (``held`` v0,
    ``projected``) and ``slosh_frequency`` (``vacuum_thrust`` v0, ``specific_force``); history: the
    observation is the last ``history`` samples and actions (:mod:`.history`; 0: off, the sample alone).

    Sensors. ``sensors`` adds, with ``sensor_noise`` randomised, a constant gyro bias
    N(0, ``gyro_bias_radps``) and white noise ``gyro_noise_radps``, ``attitude_noise_rad``,
    ``accel_noise_mps2`` per sample. ``flight`` models a tactical-grade strapdown IMU at
    ``imu_station_m`` (:mod:`lvgym.simulator.imu`, :mod:`lvgym.envs.flightcomputer`): gyros that see the
    bending slope rate through a second-order bandwidth (``gyro_bandwidth_hz`` = 80 Hz,
    ``gyro_damping`` = 0.7: tactical FOG/MEMS gyros have 50-500 Hz bandwidths, the low end taken) and
    a second-order Butterworth anti-aliasing low-pass (``antialias_hz`` = 20 Hz: below the 25 Hz
    Nyquist frequency of the 50 Hz control sampling; it lets the 9-14 Hz bending modes through with
    phase lag, as flight IMUs do), both advanced at every physics step; accelerometers at the same
    station with lever arm and bending through the same low-pass, plus ``accel_noise_mps2`` per sample;
    with ``sensor_noise`` randomised, an initial gyro bias N(0, ``gyro_bias_radps``) per axis that then
    drifts as a random walk (``gyro_bias_rw_radps_per_sqrt_s`` = 1.5e-6 rad/s/sqrt(s): a 1-sigma wander
    over a 100 s flight of 3 deg/h, the bias instability of a tactical-grade gyro, 1-10 deg/h) and an
    angle random walk (``gyro_arw_rad_per_sqrt_s`` = 4.4e-5 rad/sqrt(s) = 0.15 deg/sqrt(h), tactical
    grade 0.1-0.3 deg/sqrt(h): white rate noise ARW / sqrt(control_dt_s) per sample); the attitude is
    the strapdown integration of the sampled gyro rates from the true attitude at the reset. The v0
    defaults of the shared keys stay: ``gyro_bias_radps`` = 1e-3 rad/s (206 deg/h, an industrial
    MEMS) is far above a tactical IMU's turn-on bias; :data:`FLIGHT_DEFAULTS` holds the tactical-grade
    values for the v1 envs.
    """

    vehicle: Any
    model: str = "nonrigid"
    site: str = "andoya"
    elevation_deg: float = 90.0
    rail_length_m: float = 0.0
    mission_time_s: float = 60.0
    control_dt_s: float = 0.02
    physics_dt_s: float = 0.01
    controller_on_after_s: float = 2.0
    wind: str = "none"
    randomize: frozenset = field(default_factory=frozenset)
    observation: str = "state"
    imu_station_m: float | None = None
    reference: str = "zero_rate"
    reference_velocity: str = "inertial"
    kick_start_s: float = 5.0
    kick_end_s: float = 15.0
    kick_angle_deg: float = 5.0
    control: str = "tvc"
    actuator_frequency: float = 15.0
    actuator_damping: float = 0.7
    gimbal_limit_deg: float | None = None
    gimbal_rate_limit_degps: float = 30.0
    rcs_torque_nm: float = 2.0
    rate_weights: tuple = (0.0, 1.0, 1.0)
    effort_weight: float = 1e-3
    effort_rate_weight: float = 1e-4
    failure_penalty_rad_per_s: float = 0.1
    qalpha_limit_pa_deg: float = 250e3
    attitude_limit_deg: float = 30.0
    n_modes: int | None = None
    action_delay_steps: int = 0
    coast_control: bool = False
    coast_torque_nm: float = 1000.0
    coast_bandwidth_radps: float = 3.0
    settling_thrust_n: float = 0.0
    gyro_noise_radps: float = 2e-4
    gyro_bias_radps: float = 1e-3
    accel_noise_mps2: float = 0.05
    attitude_noise_rad: float = 1e-3
    aeroelastic: bool | None = False
    mode_interval_s: float | None = None
    mode_basis: str = "held"
    slosh_frequency: str = "vacuum_thrust"
    gyro_bandwidth_hz: float = 80.0
    gyro_damping: float = 0.7
    antialias_hz: float = 20.0
    gyro_arw_rad_per_sqrt_s: float = 4.4e-5
    gyro_bias_rw_radps_per_sqrt_s: float = 1.5e-6
    history: int = 0

    def __post_init__(self) -> None:
        check_choice("model", self.model, MODELS)
        check_choice("wind", self.wind, WIND_TIERS)
        check_choice("observation", self.observation, OBSERVATIONS)
        check_choice("reference", self.reference, REFERENCES)
        check_choice("reference_velocity", self.reference_velocity, REFERENCE_VELOCITIES)
        check_number("action_delay_steps", self.action_delay_steps, 0, 50, integer=True)
        check_number("history", self.history, 0, 64, integer=True)
        check_choice("control", self.control, CONTROLS)
        check_bool("coast_control", self.coast_control)
        check_choice("mode_basis", self.mode_basis, MODE_BASES)
        check_choice("slosh_frequency", self.slosh_frequency, SLOSH_FREQUENCIES)
        if self.mode_interval_s is not None:
            check_number("mode_interval_s", self.mode_interval_s, 0.0, 1e5, lo_open=True)
        r = self.randomize
        names = set(RANDOMIZE_V0) if r is True else set() if r in (False, None) else set(r) if not isinstance(r, str) else {r}
        bad = sorted(names - set(RANDOMIZE))
        if bad:
            raise ConfigError("randomize", bad[0], f"True (the v0 set {RANDOMIZE_V0}), False or a set of {RANDOMIZE}")
        object.__setattr__(self, "randomize", frozenset(names))
        check_number("mission_time_s", self.mission_time_s, 0.0, 3600.0, lo_open=True)
        check_number("physics_dt_s", self.physics_dt_s, 0.0, 0.05, lo_open=True)
        check_number("control_dt_s", self.control_dt_s, self.physics_dt_s, 1.0)
        n = self.control_dt_s / self.physics_dt_s
        if abs(n - round(n)) > 1e-6:
            raise ConfigError("control_dt_s", self.control_dt_s,
                              f"a whole multiple of physics_dt_s = {self.physics_dt_s}")
        for key, lo, hi in (("elevation_deg", 1.0, 90.0), ("rail_length_m", 0.0, 1000.0),
                            ("controller_on_after_s", 0.0, 3600.0), ("actuator_frequency", 0.1, 1000.0),
                            ("actuator_damping", 0.05, 10.0), ("gimbal_rate_limit_degps", 0.1, 1000.0),
                            ("rcs_torque_nm", 0.0, 1e6), ("effort_weight", 0.0, 1e6),
                            ("effort_rate_weight", 0.0, 1e6), ("failure_penalty_rad_per_s", 0.0, 1e6),
                            ("qalpha_limit_pa_deg", 0.0, 1e9), ("attitude_limit_deg", 0.1, 180.0),
                            ("kick_start_s", 0.0, 3600.0), ("kick_end_s", 0.0, 3600.0),
                            ("kick_angle_deg", -90.0, 90.0), ("gyro_noise_radps", 0.0, 1.0),
                            ("gyro_bias_radps", 0.0, 1.0), ("accel_noise_mps2", 0.0, 100.0),
                            ("attitude_noise_rad", 0.0, 1.0), ("coast_torque_nm", 0.0, 1e6), ("settling_thrust_n", 0.0, 1e7),
                            ("coast_bandwidth_radps", 0.01, 100.0), ("gyro_damping", 0.05, 10.0),
                            ("gyro_arw_rad_per_sqrt_s", 0.0, 0.1), ("gyro_bias_rw_radps_per_sqrt_s", 0.0, 0.1)):
            check_number(key, getattr(self, key), lo, hi)
        for key in ("gyro_bandwidth_hz", "antialias_hz"):
            check_number(key, getattr(self, key), 0.0, 1e4, lo_open=True)
        if self.kick_end_s <= self.kick_start_s:
            raise ConfigError("kick_end_s", self.kick_end_s, f"a time after kick_start_s = {self.kick_start_s}")
        if self.gimbal_limit_deg is not None:
            check_number("gimbal_limit_deg", self.gimbal_limit_deg, 0.0, 30.0, lo_open=True)
        w = tuple(self.rate_weights)
        if len(w) != 3 or any(not isinstance(v, (int, float)) or v < 0 for v in w):
            raise ConfigError("rate_weights", self.rate_weights, "three numbers >= 0 (roll, pitch, yaw) per rad")
        object.__setattr__(self, "rate_weights", tuple(float(v) for v in w))
        if self.aeroelastic not in (None, True, False):
            raise ConfigError("aeroelastic", self.aeroelastic, "True, False or None (the vehicle file's flag)")
        if self.n_modes is not None and (not isinstance(self.n_modes, int) or not 0 <= self.n_modes <= 10):
            raise ConfigError("n_modes", self.n_modes, "None or an integer in [0, 10]")

    @property
    def substeps(self) -> int:
        return int(round(self.control_dt_s / self.physics_dt_s))

    @classmethod
    def build(cls, defaults: Mapping[str, Any], overrides: Mapping[str, Any], also: tuple[str, ...] = ()) -> TaskSpec:
        """Defaults of an env updated by the user's keywords. An unknown keyword raises a one-line
        :class:`~lvgym.errors.ConfigError` with the closest option (of the fields and of ``also``, the
        env's own keywords) and where the options are documented."""
        known = set(cls.__dataclass_fields__)
        for key in overrides:
            if key not in known:
                raise ConfigError(key, overrides[key], f"unknown option{did_you_mean(key, sorted(known | set(also)))}; "
                                  f"the env options: {OPTIONS_DOC}")
        return cls(**{**defaults, **overrides})


#: where the env options are documented (what an unknown option's error points to)
OPTIONS_DOC = "help(lvgym.envs.TaskSpec)"
#: the keys ``reset(options=...)`` takes (none: every option is a keyword of the env's constructor)
RESET_OPTIONS: tuple[str, ...] = ()


def check_reset_options(options: Mapping[str, Any] | None) -> None:
    """Refuse a key of ``reset(options=...)`` that is not in :data:`RESET_OPTIONS`: a one-line
    :class:`~lvgym.errors.ConfigError` naming the key and the keys allowed (an option given there would
    otherwise be ignored without a word)."""
    for key, value in (options or {}).items():
        if key not in RESET_OPTIONS:
            allowed = f"one of {RESET_OPTIONS}" if RESET_OPTIONS else "none"
            hint = f"; {key!r} is an env keyword (gymnasium.make(env_id, {key}=...))" \
                if key in TaskSpec.__dataclass_fields__ else did_you_mean(key, RESET_OPTIONS)
            raise ConfigError(f"reset(options)[{key!r}]", value, f"unknown reset option (allowed keys: {allowed}){hint}; "
                              f"the env options: {OPTIONS_DOC}")
