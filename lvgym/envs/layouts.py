"""Every packed vector of the ascent task, described once (see :mod:`lvgym.packing`).

- :data:`TASK`: the task's parameters, one vector per env (``task``), read by the compiled signals.
- :data:`OBSERVATIONS`: the observation of each ``observation`` mode (an interface: trained policies
  depend on it, so it is never padded and never reordered; a new channel is a new entry at the end and a
  new env version). Entries that mean the same in every mode have the same name and index; entries 5
  and 6 are the angles of attack in ``state`` and the accelerometers in ``sensors`` and ``flight``.
- :data:`FLIGHT_DRAWS`: one control step's random draws of the ``flight`` sensors; :data:`NAV` the flight
  computer's navigation state.
- :data:`SENSOR_NOISE`: which observation entries each sensor's noise is added to.
- :data:`REWARD`: the reward terms, in ``info["reward_terms"]`` and in the compiled kernel's order.
- :data:`REASONS`: the termination codes.

The env docstrings print these tables (:func:`observation_table`), so the docs are the layout.
"""

from __future__ import annotations

import functools

from lvgym.packing import Field, Packed, rst_table

__all__ = ["ACTIONS", "FLIGHT_DRAWS", "FLIGHT_SOURCE", "G0", "NAV", "OBSERVATIONS", "OBS_FLIGHT", "OBS_SENSORS", "OBS_STATE",
           "REASONS", "REWARD", "REWARD_TERMS", "SENSOR_NOISE",
           "TASK", "FAULT_INFO", "VEHICLE_INFO", "informed_layout", "FD", "NV", "O", "OF", "OS", "RW", "T",
           "observation_table"]

G0 = 9.80665

#: parameters of one ascent task (built from its :class:`~.spec.TaskSpec`)
TASK = Packed("task parameters", [
    Field("on_after", 1, "s", "the controller acts from this time on (and while an engine burns)"),
    Field("dt", 1, "s", "control period"),
    Field("mission", 1, "s", "mission time (truncation)"),
    Field("rate_weights", 3, "1/rad", "reward weights of the roll, pitch and yaw rate errors"),
    Field("effort_weight", 1, "1/(rad s)", "reward weight of the gimbal effort"),
    Field("effort_rate_weight", 1, "1/rad", "reward weight of the gimbal rate effort"),
    Field("failure_penalty", 1, "1/s", "reward charged per second of mission left at a termination"),
    Field("qalpha_limit", 1, "Pa deg", "structural limit of dynamic pressure times total angle of attack"),
    Field("qalpha_over", 1, "-", "0: qalpha_limit over the whole flight; 1: the table over Mach; 2: over time [s]"),
    Field("qalpha_n", 1, "-", "rows of the limit's table (at most 8)"),
    Field("qalpha_x", 8, "- or s", "the table's Mach numbers or times, increasing (the unused ones 0)"),
    Field("qalpha_y", 8, "Pa deg", "the limit at each (linear between, held beyond)"),
    Field("attitude_limit", 1, "deg", "largest attitude error"),
    Field("gimbal_limit", 1, "rad", "gimbal limit: the action's scale"),
    Field("gravity_turn", 1, "-", "1: the reference is the gravity-turn programme, 0: zero rate"),
    Field("earth_velocity", 1, "-", "1: the gravity turn follows the velocity relative to the Earth, 0: inertial"),
    Field("kick_start", 1, "s", "start of the pitch kick"),
    Field("kick_end", 1, "s", "end of the pitch kick"),
    Field("kick_angle", 1, "rad", "angle of the pitch kick"),
    Field("sensors", 1, "-", "1: the sensors observation, 0: the ideal state"),
    Field("n_steps", 1, "-", "control steps of the mission"),
    Field("flight", 1, "-", "1: the flight observation (IMU filters, drifting gyro, strapdown attitude)"),
])

_COMMON_HEAD = [
    Field("roll_rate", 1, "rad/s", "body roll rate"),
    Field("pitch_rate_error", 1, "rad/s", "pitch rate minus the reference pitch rate"),
    Field("yaw_rate_error", 1, "rad/s", "yaw rate"),
    Field("pitch_attitude_error", 1, "rad", "body axis against the reference axis, about body y"),
    Field("yaw_attitude_error", 1, "rad", "the same about body z"),
]
_COMMON_TAIL = [
    Field("mach_over_10", 1, "-", "Mach number / 10"),
    Field("qbar_over_1e5", 1, "-", "dynamic pressure / 1e5 Pa"),
    Field("gimbal_pitch", 1, "-", "actuator position over the gimbal limit, pitch"),
    Field("gimbal_yaw", 1, "-", "the same, yaw"),
    Field("time_fraction", 1, "-", "time / mission time"),
    Field("controller_on", 1, "-", "1 when the controller acts at the next step (off before controller_on_after_s "
          "and while no engine burns)"),
    Field("pitch_rate_reference", 1, "rad/s", "reference pitch rate (zero, or the gravity-turn programme)"),
]
#: ``observation="state"``: the ideal state of the vehicle, which no flight computer has (a research option)
OBS_STATE = Packed("observation (state)", _COMMON_HEAD + [
    Field("alpha", 1, "rad", "angle of attack"),
    Field("beta", 1, "rad", "sideslip"),
] + _COMMON_TAIL, interface=True)
#: ``observation="sensors"``: a rate gyro at the IMU station (it sees the bending slope rate; bias and noise
#: with ``sensor_noise``), a noisy attitude and two accelerometers
OBS_SENSORS = Packed("observation (sensors)", [
    Field("roll_rate", 1, "rad/s", "gyro roll rate at the IMU station (bias, noise)"),
    Field("pitch_rate_error", 1, "rad/s", "gyro pitch rate at the IMU (sees the bending slope rate) minus the "
          "reference"),
    Field("yaw_rate_error", 1, "rad/s", "gyro yaw rate at the IMU"),
    Field("pitch_attitude_error", 1, "rad", "body axis against the reference axis, about body y (noise)"),
    Field("yaw_attitude_error", 1, "rad", "the same about body z (noise)"),
    Field("accel_z", 1, "g0", "lateral specific force along body z over g0 (accelerometer, noise)"),
    Field("accel_y", 1, "g0", "lateral specific force along body y over g0 (accelerometer, noise)"),
] + _COMMON_TAIL, interface=True)
#: ``observation="flight"`` (protocol v1): what a flight computer samples: the IMU's gyros at their station
#: (bending slope rate, sensor bandwidth, anti-aliasing, drifting bias, angle random walk), the attitude
#: its strapdown integration of them gives, the IMU's accelerometers (lever arm, bending, anti-aliasing)
OBS_FLIGHT = Packed("observation (flight)", [
    Field("roll_rate", 1, "rad/s", "sampled gyro roll rate at the IMU (filters, drifting bias, angle random walk)"),
    Field("pitch_rate_error", 1, "rad/s", "sampled gyro pitch rate at the IMU (sees the bending slope rate) minus "
          "the reference"),
    Field("yaw_rate_error", 1, "rad/s", "sampled gyro yaw rate at the IMU"),
    Field("pitch_attitude_error", 1, "rad", "strapdown attitude (integrated gyro rates) against the reference "
          "axis, about body y"),
    Field("yaw_attitude_error", 1, "rad", "the same about body z"),
    Field("accel_z", 1, "g0", "sampled lateral specific force along body z at the IMU over g0 (lever arm, "
          "bending, anti-aliasing, noise)"),
    Field("accel_y", 1, "g0", "the same along body y"),
] + _COMMON_TAIL, interface=True)
OBSERVATIONS = {"state": OBS_STATE, "sensors": OBS_SENSORS, "flight": OBS_FLIGHT}
#: ``vehicle_info=True``: the vehicle's design parameters at lift-off after the observation mode's entries
#: (:mod:`lvgym.vehicle.designinfo`; the nominal vehicle file's, not an episode's dispersed draw)
VEHICLE_INFO = Packed("vehicle design parameters", [
    Field("vehicle_mass_t", 1, "t", "lift-off mass"),
    Field("vehicle_pitch_inertia_log10", 1, "log10 kg m^2", "lift-off pitch inertia about the CG, as log10"),
    Field("vehicle_slenderness_over_10", 1, "-", "length over the largest outer diameter, over 10"),
    Field("vehicle_thrust_to_weight", 1, "-", "lift-off thrust at sea level over the lift-off weight"),
    Field("vehicle_control_power_over_10", 1, "1/s^2", "pitch control power T_v (x_cg - x_gimbal) / J_yy, over 10"),
    Field("vehicle_bending_hz_over_10", 1, "Hz", "first free-free bending frequency at lift-off, over 10"),
    Field("vehicle_slosh_mass_share", 1, "-", "slosh pendulum masses over the lift-off mass"),
    Field("vehicle_slosh_hz", 1, "Hz", "the largest slosh pendulum's frequency at the lift-off thrust acceleration"),
], interface=True)


#: ``fault_info=True`` (privileged: a teacher's observation, never a scored causal policy's): the row's in-flight
#: fault once it has struck (:mod:`.faults`), after the observation mode's entries (and the vehicle block);
#: every entry is zero before the onset and for a kind the row does not have
FAULT_INFO = Packed("in-flight fault (privileged)", [
    Field("fault_active", 1, "-", "1 once the row's fault has struck"),
    Field("fault_effectiveness_loss_pitch", 1, "-", "lost actuator effectiveness on the pitch axis (0.3-0.7)"),
    Field("fault_effectiveness_loss_yaw", 1, "-", "the same on the yaw axis"),
    Field("fault_bandwidth_loss_pitch", 1, "-", "lost share of the pitch servo's natural frequency (0.5-0.8)"),
    Field("fault_bandwidth_loss_yaw", 1, "-", "the same on the yaw axis"),
    Field("fault_thrust_loss", 1, "-", "lost share of the thrust (0.1-0.3)"),
    Field("fault_gyro_bias_pitch", 1, "deg/s", "the pitch gyro's bias step, signed"),
    Field("fault_gyro_bias_yaw", 1, "deg/s", "the yaw gyro's bias step, signed"),
    Field("fault_misalignment_pitch", 1, "deg", "the thrust-direction step on the pitch axis, signed"),
    Field("fault_misalignment_yaw", 1, "deg", "the same on the yaw axis"),
    Field("fault_stuck_pitch", 1, "-", "1: the pitch actuator is jammed"),
    Field("fault_stuck_yaw", 1, "-", "1: the yaw actuator is jammed"),
], interface=True)


@functools.lru_cache(maxsize=16)
def informed_layout(base: Packed, vehicle: bool = True, fault: bool = False) -> Packed:
    """The observation ``base`` followed by :data:`VEHICLE_INFO` (``vehicle``: the option ``vehicle_info``)
    and then :data:`FAULT_INFO` (``fault``: the option ``fault_info``): ``base``'s entries keep their names
    and indices."""
    blocks = [b for b, on in ((VEHICLE_INFO, vehicle), (FAULT_INFO, fault)) if on]
    if not blocks:
        return base
    title = ", ".join([base.title, *(b.title for b in blocks)])
    return Packed(title, [*base.fields, *(f for b in blocks for f in b.fields)], interface=True)


#: the action as an observation with ``history`` records it (:mod:`.history`), per ``control``: the TVC
#: command clipped to [-1, 1] (what the flight computer sent, before the controller-off gating and the
#: ``action_delay_steps`` queue), the RCS pulse as the action minus 1 (so that the zero of a reset is "no pulse")
ACTIONS = {"tvc": Packed("action (tvc)", [
    Field("action_pitch", 1, "-", "gimbal pitch command over the gimbal limit, clipped to [-1, 1]"),
    Field("action_yaw", 1, "-", "gimbal yaw command over the gimbal limit, clipped to [-1, 1]"),
], interface=True), "rcs": Packed("action (rcs)", [
    Field("action_roll", 1, "-", "roll pulse: -1 negative, 0 none, +1 positive (the action minus 1)"),
], interface=True)}
#: where a flight computer gets each entry of the ``sensors`` and ``flight`` modes (the ``state`` mode's
#: entries 0-6 are the ideal state: no flight computer has them)
FLIGHT_SOURCE = {
    "roll_rate": "gyro", "pitch_rate_error": "gyro, guidance", "yaw_rate_error": "gyro",
    "pitch_attitude_error": "navigation (flight: strapdown gyro integration)", "yaw_attitude_error": "navigation",
    "accel_z": "accelerometer", "accel_y": "accelerometer",
    "mach_over_10": "navigation and air-data model (taken exact)", "qbar_over_1e5": "navigation and air-data "
    "model (taken exact)", "gimbal_pitch": "actuator position feedback", "gimbal_yaw": "actuator position feedback",
    "time_fraction": "clock", "controller_on": "sequencer", "pitch_rate_reference": "guidance (taken exact)",
}
#: the flight computer's navigation state of a row (``observation="flight"``)
NAV = Packed("navigation state", [
    Field("q_nav", 4, "-", "strapdown attitude, the estimate of q_bi (scalar first)"),
    Field("gyro", 3, "rad/s", "the last gyro sample (bias and noise included), body axes"),
])
#: one control step's draws of the ``flight`` sensors of a row (from its generator, already scaled)
FLIGHT_DRAWS = Packed("flight sensor draws", [
    Field("gyro_noise", 3, "rad/s", "angle random walk: white rate noise of the sample, sigma ARW / sqrt(dt)"),
    Field("bias_step", 3, "rad/s", "the gyro bias's random-walk step over the period, sigma sigma_b sqrt(dt) "
          "(zero at a reset)"),
    Field("accel_noise", 2, "m/s^2", "accelerometer white noise (body y, z)"),
])
#: per sensor: the TaskSpec key of its noise's standard deviation, the observation entries it is added
#: to (consecutive) and the divisor that takes it to the entries' unit
SENSOR_NOISE = (("gyro_noise_radps", ("roll_rate", "pitch_rate_error", "yaw_rate_error"), 1.0),
                ("attitude_noise_rad", ("pitch_attitude_error", "yaw_attitude_error"), 1.0),
                ("accel_noise_mps2", ("accel_z", "accel_y"), G0))

#: the reward terms; they add up to the reward
REWARD = Packed("reward terms", [
    Field("rate_roll", 1, "rad", "-w_roll |roll rate error| dt"),
    Field("rate_pitch", 1, "rad", "-w_pitch |pitch rate error| dt"),
    Field("rate_yaw", 1, "rad", "-w_yaw |yaw rate error| dt"),
    Field("effort", 1, "-", "-effort_weight * integral of (|gimbal pitch| + |gimbal yaw|) dt over the step"),
    Field("effort_rate", 1, "-", "-effort_rate_weight * integral of |gimbal rates| dt over the step"),
    Field("failure", 1, "rad", "on termination, -failure_penalty_rad_per_s * the mission time left"),
], interface=True)
REWARD_TERMS = REWARD.names
#: termination codes (the order is the precedence: a later one overrides an earlier one)
#: (``gimbal command unflyable``: only with the score reward, ``reward_kind="score_v2"``, :mod:`.scorereward`)
REASONS = ("", "attitude error beyond the limit", "q-alpha beyond the structural limit", "non-finite state",
           "gimbal command unflyable")

T, O, OS, OF, RW, FD, NV = (TASK.at, OBS_STATE.at, OBS_SENSORS.at, OBS_FLIGHT.at, REWARD.at, FLIGHT_DRAWS.at,
                             NAV.at)
assert all(lay.size == OBS_STATE.size and all(OBS_STATE.offset(n) == lay.offset(n) for n in OBS_STATE.names if n in lay)
           for lay in (OBS_SENSORS, OBS_FLIGHT))
assert OBS_SENSORS.names == OBS_FLIGHT.names
assert OF.yaw_attitude_error == OF.pitch_attitude_error + 1     # the attitude error is written as one pair


def observation_table() -> str:
    """The observation of every mode as one reStructuredText table (for the env docstrings), with what a
    flight computer reads each entry from (``state``'s entries 0-6 are the ideal state, for research)."""
    rows = []
    for (o, f), (_, g), (_, h) in zip(OBS_STATE.leaves(), OBS_SENSORS.leaves(), OBS_FLIGHT.leaves()):
        name = f"``{f.name}``" if f.name == g.name else f"``{f.name}`` / ``{g.name}``"
        if f.name == g.name and f.doc == g.doc == h.doc:
            meaning = f.doc
        else:
            meaning = f"state: {f.doc}; sensors: {g.doc}; flight: {h.doc}"
        unit = f.unit if f.unit == g.unit else f"{f.unit} / {g.unit}"
        source = FLIGHT_SOURCE[g.name] if f.name == g.name and f.doc == g.doc else f"state: none (ideal); " \
            f"sensors, flight: {FLIGHT_SOURCE[g.name]}"
        rows.append([str(o), name, unit, meaning, source])
    return rst_table(["index", "name (state / sensors, flight)", "unit", "meaning", "flight computer source"], rows)
