"""Every packed vector of the simulator, described once (names, sizes, units; see :mod:`lvgym.packing`).

Per row of a batch the simulator keeps one :class:`~.data.SimData` (the row state) whose arrays use
these layouts; the compiled functions read their offsets from the ``.at`` namedtuples below
(``ctx[CTX.gimbal + 1]``, ``cond[D.qbar]``), Python code reads by name
(``CONDITIONS.view(data.conditions, "qbar")``).

- :data:`CONTEXT` (``ctx``): what the loads function needs at every RK4 stage besides the state and
  the dynamics parameters: the commands held over a physics step, the thrust of the current piece,
  offsets of the environment models' parameter blocks packed behind this header, a cache and scratch.
- :data:`AERO` one aerodynamic block's offsets (the one in force is in the header; the table of
  contents holds one per stage).
- :data:`TRIG` the thrust direction's cached angles; :data:`DISPERSION` a row's load dispersions.
- :data:`AEROELASTIC` the strip-theory aeroelastic loads' block in the header (:mod:`.strips`): sizes,
  offsets of the mode shapes at the strips and of the loads' scratch, and the :data:`STRIPS` block of the
  stage in force (the table of contents holds one per stage).
- :data:`CONDITIONS` (``cond``): the flight conditions of one state, what the recorder, the task and a
  policy see.
- :data:`RAIL` the launch rail (one per simulator), :data:`RAIL_STATE` the row's motion along it.
- :data:`SERVO` the gimbal servo's parameters, :data:`ACTUATOR` the row's command, gimbal and effort.
- :data:`IMU` the inertial measurement unit's parameters (one per simulator; discrete filters of
  :mod:`.imu`), :data:`IMU_STATE` the row's gyro and accelerometer filter states and its station
  (:data:`IMU_STATION`, the ``imu_station`` dispersion).
"""

from __future__ import annotations

from lvgym.environment.aerokernels import FLOW
from lvgym.environment.atmosphere import AIR
from lvgym.packing import Field, Packed

__all__ = ["ACCEL_ORDER", "ACTUATOR", "AERO", "AEROELASTIC", "CONDITIONS", "CONTEXT", "DISPERSION", "GYRO_ORDER", "IMU",
           "IMU_STATE",
           "IMU_STATION", "RAIL", "RAIL_STATE", "SERVO", "STRIPS", "TRIG", "A", "AEL", "CTX", "D", "DS", "IM", "IS", "RL", "RS",
           "SV", "TG", "AE", "STR"]

#: flight conditions of one state at one time
CONDITIONS = Packed("flight conditions", [
    Field("altitude", 1, "m", "geodetic altitude above the WGS84 ellipsoid (or the flat Earth)"),
    Field("air", AIR.size, "-", "the atmosphere model's output (layout AIR)", sub=AIR),
    Field("wind_n", 3, "m/s", "wind velocity, local north-east-down"),
    Field("v_air_b", 3, "m/s", "velocity relative to the air, body frame"),
    Field("flow", FLOW.size, "-", "the aerodynamic model's flow state (layout FLOW)", sub=FLOW),
    Field("f_aero_b", 3, "N", "aerodynamic force, body frame"),
    Field("m_aero_b", 3, "N m", "aerodynamic moment about the CG of B, body frame"),
    Field("f_aero_i", 3, "N", "aerodynamic force, inertial frame"),
    Field("g_i", 3, "m/s^2", "gravitational acceleration, inertial frame"),
    Field("thrust", 1, "N", "thrust max(T_0 - A_e p, 0)"),
    Field("thrust_b", 3, "N", "thrust in the undeformed engine frame (body axes), gimbal and misalignment applied"),
])

#: offsets of one aerodynamic model's blocks in the context (entries are indices into ``ctx``)
AERO = Packed("aerodynamic block", [
    Field("params", 1, "-", "offset of the model's parameters"),
    Field("grid", 1, "-", "offset of the table's grid"),
    Field("dims", 1, "-", "offset of the grid's dimensions"),
    Field("table", 1, "-", "offset of the coefficient table"),
    Field("n_col", 1, "-", "columns of the table"),
    Field("end", 1, "-", "end of the block"),
])

#: thrust direction cache: recomputed only when the angles change (the gimbal is held over an RK4 step)
TRIG = Packed("thrust angle cache", [
    Field("pitch", 1, "rad", "gimbal + misalignment, pitch (NaN: empty)"),
    Field("yaw", 1, "rad", "gimbal + misalignment, yaw"),
    Field("cos_pitch", 1, "-", "its cosine"),
    Field("sin_pitch", 1, "-", "its sine"),
    Field("cos_yaw", 1, "-", ""),
    Field("sin_yaw", 1, "-", ""),
])

#: a row's dispersions of the loads (neutral: 1, 1, 1, 0), drawn at reset by the task
DISPERSION = Packed("load dispersions", [
    Field("thrust_scale", 1, "-", "factor on the thrust (the mass flow is the timeline's: an Isp dispersion)"),
    Field("normal_scale", 1, "-", "factor on the aerodynamic normal force (y_b, z_b) and on the moment about the CG"),
    Field("axial_scale", 1, "-", "factor on the aerodynamic axial force (x_b)"),
    Field("cp_shift", 1, "m", "shift of the normal force's point of action along +x_b (towards the nose)"),
])

#: one stage's strips (entries are indices into ``ctx``, but ``s_ref``)
STRIPS = Packed("strip block", [
    Field("x_strip", 1, "-", "offset of the strip stations (n) [m]"),
    Field("mach", 1, "-", "offset of the Mach grid of the CN-alpha table (n_mach)"),
    Field("n_mach", 1, "-", "Mach numbers of the grid"),
    Field("cna", 1, "-", "offset of the strips' CN-alpha shares (n_mach, n) [1/rad], row major"),
    Field("s_ref", 1, "m^2", "reference area of the shares"),
])

#: the aeroelastic strip loads of a row: sizes, offsets of the per-piece mode shapes and the scratch
AEROELASTIC = Packed("aeroelastic block", [
    Field("on", 1, "-", "1: strip-theory elastic loads and modal forces added to the table aerodynamics"),
    Field("n_modes", 1, "-", "bending modes per plane K of the dynamics layout"),
    Field("n_slosh", 1, "-", "slosh pendulums N of the dynamics layout"),
    Field("n_strip", 1, "-", "strips n (the same for every stage)"),
    Field("toc", 1, "-", "offset of the table of contents: one STRIPS row per stage"),
    Field("phi", 1, "-", "offset of the mode shapes at the strips (K, n) [1/sqrt(kg)] of the current piece"),
    Field("dphi", 1, "-", "offset of the mode slopes at the strips (K, n) [1/(m sqrt(kg))] of the current piece"),
    Field("f_eta", 1, "-", "offset of scratch: the generalised modal forces (2K) [sqrt(kg) m/s^2], up to df"),
    Field("df", 1, "-", "offset of scratch: the strip forces (n, 2) [N], up to end"),
    Field("end", 1, "-", "end of the aeroelastic blocks"),
    Field("f_b", 3, "N", "scratch: the elastic force increment, body frame"),
    Field("m_b", 3, "N m", "scratch: the elastic moment increment about the CG of B, body frame"),
    Field("strip", STRIPS.size, "-", "the strip block of the stage in force (layout STRIPS)", sub=STRIPS),
])

#: header of the per-row context; the models' parameter blocks follow it (their offsets are in it)
CONTEXT = Packed("simulator context", [
    Field("gimbal", 2, "rad", "gimbal angles in force (pitch, yaw): the servo's position, held over a physics step"),
    Field("misalignment", 2, "rad", "fixed thrust misalignment (pitch, yaw), drawn at reset"),
    Field("moment_b", 3, "N m", "commanded body moment (reaction control), held over the control period"),
    Field("force_b", 3, "N", "commanded body force at the CG, body frame (settling thrust), held over the control "
          "period"),
    Field("thrust0", 1, "N", "vacuum thrust T_0 of the current piece (timeline, at its middle)"),
    Field("exit_area", 1, "m^2", "total nozzle exit area of the current piece"),
    Field("vectored_share", 1, "-", "share of the thrust the gimbal turns (the rest along x_b) of the current piece"),
    Field("time0", 1, "s", "start time of the current piece: the stepper's time is relative to it"),
    Field("aero_on", 1, "-", "1: aerodynamic loads, 0: none (flow angles only)"),
    Field("dispersion", DISPERSION.size, "-", "the row's load dispersions (layout DISPERSION)", sub=DISPERSION),
    Field("site", 1, "-", "offset of the launch site's block"),
    Field("gravity", 1, "-", "offset of the gravity model's block"),
    Field("atmosphere", 1, "-", "offset of the atmosphere model's block"),
    Field("wind", 1, "-", "offset of the wind model's block"),
    Field("wind_end", 1, "-", "end of the wind model's block"),
    Field("aero", AERO.size, "-", "the aerodynamic block in force (layout AERO)"),
    Field("stage", 1, "-", "the stage whose aerodynamic block is in force (the lowest attached one)"),
    Field("n_stages", 1, "-", "rows of the aerodynamic table of contents"),
    Field("toc", 1, "-", "offset of the table of contents: one AERO row per stage"),
    Field("gravity_work", 1, "-", "offset of the gravity kernel's scratch block"),
    Field("trig", TRIG.size, "-", "thrust angle cache (layout TRIG)"),
    Field("aeroelastic", AEROELASTIC.size, "-", "strip-theory aeroelastic loads (layout AEROELASTIC)"),
    Field("scratch", CONDITIONS.size, "-", "flight conditions of the latest RK4 stage (layout CONDITIONS)"),
    Field("scratch_dcm", 9, "-", "a 3x3 matrix of scratch"),
])

#: the launch rail of a simulator
RAIL = Packed("launch rail", [
    Field("omega_e", 1, "rad/s", "Earth rotation rate (0 on a flat Earth)"),
    Field("x_base", 1, "m", "station of the vehicle's base"),
    Field("length", 1, "m", "rail length"),
    Field("r_pad_e", 3, "m", "pad position, Earth-fixed (the inertial frame at t = 0)"),
    Field("axis_e", 3, "-", "unit vector along the rail, Earth-fixed"),
    Field("q_bi0", 4, "-", "attitude on the rail at t = 0 (scalar first)"),
])

#: a row's motion on the pad and rail
RAIL_STATE = Packed("rail state", [
    Field("on", 1, "-", "1 while held on the pad or rail"),
    Field("lifted", 1, "-", "1 once lifted off"),
    Field("s", 1, "m", "travel of the structure along the rail (frozen at rail exit)"),
    Field("t_lift", 1, "s", "lift-off time (NaN before)"),
    Field("t_exit", 1, "s", "rail exit time (NaN before)"),
])

#: parameters of the gimbal servo (one per simulator)
SERVO = Packed("servo parameters", [
    Field("on", 1, "-", "1: second-order servo; 0: the gimbal takes the command at once"),
    Field("frequency", 1, "rad/s", "natural frequency"),
    Field("damping", 1, "-", "damping ratio"),
    Field("limit", 1, "rad", "position limit"),
    Field("rate_limit", 1, "rad/s", "rate limit"),
])

#: a row's actuator: the command, the servo's state and the effort over the last control period
ACTUATOR = Packed("actuator", [
    Field("command", 2, "rad", "gimbal command (pitch, yaw) held over the control period"),
    Field("gimbal", 2, "rad", "gimbal angles (pitch, yaw): the servo's position"),
    Field("gimbal_rate", 2, "rad/s", "gimbal rates"),
    Field("effort", 1, "rad s", "integral of |gimbal pitch| + |gimbal yaw| over the last control period"),
    Field("effort_rate", 1, "rad", "integral of |gimbal rate pitch| + |gimbal rate yaw| over the last control period"),
    Field("previous", 2, "rad", "the command of the period before (what a delayed servo still follows)"),
    Field("delay", 1, "-", "servo delay of the row in physics steps: the first so many steps of a period follow the "
          "previous command (dispersion; 0 nominal)"),
    Field("frequency_shift", 1, "-", "the row's servo natural frequency is the servo's times 1 + this (dispersion; "
          "0 nominal)"),
    Field("effectiveness_loss", 2, "-", "per axis, the share of the command the actuator no longer reaches: it "
          "drives towards (1 - this) times the command (a fault; 0 nominal)"),
    Field("bandwidth_loss", 2, "-", "per axis, the share of the servo's natural frequency lost (a fault; 0 "
          "nominal)"),
    Field("stuck", 2, "-", "per axis, 1: the actuator is jammed, the gimbal stays where it is (a fault; 0 "
          "nominal)"),
])

#: states of one gyro axis's filters (the second-order sensor bandwidth, then the second-order
#: anti-aliasing low-pass) and of one accelerometer axis's (the anti-aliasing low-pass)
GYRO_ORDER, ACCEL_ORDER = 4, 2

#: parameters of the inertial measurement unit (one per simulator): the exact discretisations over one
#: physics step of its continuous filters (:mod:`.imu`), the same for every axis
IMU = Packed("imu parameters", [
    Field("on", 1, "-", "1: the IMU's filters are advanced at every physics step; 0: no IMU"),
    Field("station", 1, "m", "IMU station on x_b"),
    Field("sensor", 1, "-", "index of the IMU station among the timeline's sensor stations"),
    Field("h", 1, "s", "the physics step the filters are discretised for"),
    Field("gyro_a", GYRO_ORDER * GYRO_ORDER, "-", "gyro filters: discrete state matrix, row major",
          shape=(GYRO_ORDER, GYRO_ORDER)),
    Field("gyro_b", GYRO_ORDER, "-", "gyro filters: discrete input vector"),
    Field("gyro_c", GYRO_ORDER, "-", "gyro filters: output vector (the sampled rate)"),
    Field("accel_a", ACCEL_ORDER * ACCEL_ORDER, "-", "accelerometer filter: discrete state matrix, row major",
          shape=(ACCEL_ORDER, ACCEL_ORDER)),
    Field("accel_b", ACCEL_ORDER, "-", "accelerometer filter: discrete input vector"),
    Field("accel_c", ACCEL_ORDER, "-", "accelerometer filter: output vector (the sampled specific force)"),
])

#: a row's IMU station (dispersion ``imu_station``): its shift from the nominal station and where it lies
#: between two of the timeline's sensor stations, whose mode shapes and slopes the row interpolates linearly
#: (``(1 - weight) lo + weight hi``); nominal: shift 0, ``lo = hi`` the IMU's own sensor index, weight 0
IMU_STATION = Packed("imu station", [
    Field("station_shift", 1, "m", "the row's IMU station minus the nominal one, along +x_b (towards the nose)"),
    Field("station_lo", 1, "-", "index of the tabulated sensor station at or aft of the row's station"),
    Field("station_hi", 1, "-", "index of the next tabulated sensor station forward of it (lo when the weight is 0)"),
    Field("station_weight", 1, "-", "linear weight of station_hi, in [0, 1)"),
])

#: a row's IMU: filter states (zero and unused without an IMU) and its station
IMU_STATE = Packed("imu state", [
    Field("gyro", 3 * GYRO_ORDER, "rad/s", "gyro filter states per body axis (x, y, z): sensor bandwidth "
          "(output, its rate), then anti-aliasing (output, its rate)", shape=(3, GYRO_ORDER)),
    Field("accel", 2 * ACCEL_ORDER, "m/s^2", "accelerometer anti-aliasing states per lateral body axis (y, z): "
          "output, its rate", shape=(2, ACCEL_ORDER)),
    Field("station", IMU_STATION.size, "-", "the row's IMU station (layout IMU_STATION)", sub=IMU_STATION),
])

#: offsets for compiled code
CTX, AE, TG, D, DS = CONTEXT.at, AERO.at, TRIG.at, CONDITIONS.at, DISPERSION.at
AEL, STR = AEROELASTIC.at, STRIPS.at
RL, RS, SV, A = RAIL.at, RAIL_STATE.at, SERVO.at, ACTUATOR.at
IM, IS = IMU.at, IMU_STATE.at


def _doc() -> str:
    return "\n\n".join(f"``{lay.title}`` ({lay.size} entries):\n\n{lay.table()}" for lay in
                       (CONTEXT, AERO, TRIG, DISPERSION, AEROELASTIC, STRIPS, CONDITIONS, RAIL, RAIL_STATE, SERVO,
                        ACTUATOR, IMU, IMU_STATION, IMU_STATE))


__doc__ = (__doc__ or "") + "\n" + _doc()
