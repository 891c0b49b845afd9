"""The protocols' presets: the options of each env id as a named value.

A preset is a :class:`~.spec.TaskSpec`, frozen: an env class flies its ``PRESET`` updated by the user's
keywords (``gymnasium.make("lvgym/SmileAscent-v1", wind="turbulence")`` is
``SMILE_V1.with_options(wind="turbulence")``). Protocol v1's shared parts are named too: the flight
computer's sensors (:data:`FLIGHT_SENSORS`), its physics (:data:`V1_PHYSICS`) and guidance
(:data:`V1_GUIDANCE`), and its one period of computational delay. docs/rl.md's presets table is generated
from these values; a frozen protocol's presets never change (``tests/test_protocol_fingerprint.py``).
"""

from __future__ import annotations

from lvgym.vehicle.slender import SlenderGeometry

from .options import (ActuatorOptions, CoastOptions, GuidanceOptions, LaunchOptions, LimitOptions, PhysicsOptions,
                      RewardOptions, SensorOptions, TimingOptions)
from .spec import TaskSpec

__all__ = ["DEFAULT_AERO_MACH", "FLIGHT_DEFAULTS", "FLIGHT_SENSORS", "SLENDER_V0", "SLENDER_V1", "SMILE_V0",
           "SMILE_V1", "STRATOS3_V0", "STRATOS3_V1", "V1_GUIDANCE", "V1_PHYSICS"]

#: Mach number at which the slender envs freeze the vehicle's aerodynamic tables by default [-]
DEFAULT_AERO_MACH = 2.0

#: the ``flight`` observation with a tactical-grade IMU where the v0 defaults of the keys it shares with
#: ``sensors`` are not: a turn-on gyro bias of 3 deg/h per axis and accelerometer noise of 0.02 m/s^2 per
#: 50 Hz sample (the fields' docstrings give the reasoning)
FLIGHT_SENSORS = SensorOptions(observation="flight", gyro_bias_radps=1.5e-5, accel_noise_mps2=0.02)
#: :data:`FLIGHT_SENSORS` as flat keywords (``gymnasium.make(env_id, **FLIGHT_DEFAULTS)``)
FLIGHT_DEFAULTS = FLIGHT_SENSORS.changes()
#: protocol v1's physics: modes recomputed every 2 s and projected, slosh dampers on the specific force,
#: the aeroelastic strip loads as the vehicle file says (issue 16; docs/benchmark.md)
V1_PHYSICS = PhysicsOptions(aeroelastic=None, mode_interval_s=2.0, mode_basis="projected",
                            slosh_frequency="specific_force")
#: protocol v1's guidance: the gravity turn, where asked for, follows the Earth-relative velocity
V1_GUIDANCE = GuidanceOptions(reference_velocity="earth")

#: ``lvgym/SmileAscent-v0``: SMILE's first-stage flight, 60 s from Andøya
SMILE_V0 = TaskSpec("smile", launch=LaunchOptions(site="andoya"), timing=TimingOptions(mission_time_s=60.0))
#: ``lvgym/SmileAscent-v1``: ``smile_v1``, 70 s, one period of delay, the flight computer's sensors, coast
#: control and 18 kN of settling thrust through the coast
SMILE_V1 = TaskSpec("smile_v1", launch=SMILE_V0.launch, timing=TimingOptions(mission_time_s=70.0, action_delay_steps=1),
                    physics=V1_PHYSICS, sensors=FLIGHT_SENSORS, guidance=V1_GUIDANCE,
                    coast=CoastOptions(coast_control=True, settling_thrust_n=18000.0))
#: ``lvgym/StratosIII-v0``: Stratos III, 30 s from El Arenosillo at 85 deg off a 10 m rail, roll pulses
STRATOS3_V0 = TaskSpec("stratos3", launch=LaunchOptions(site="el_arenosillo", elevation_deg=85.0, rail_length_m=10.0),
                       timing=TimingOptions(mission_time_s=30.0, controller_on_after_s=1.0),
                       actuator=ActuatorOptions(control="rcs"), reward=RewardOptions(rate_weights=(1.0, 1.0, 1.0)),
                       limits=LimitOptions(qalpha_limit_pa_deg=150e3))
#: ``lvgym/StratosIII-v1``: Stratos III with TVC and protocol v1's physics, sensors and delay
STRATOS3_V1 = TaskSpec("stratos3", launch=STRATOS3_V0.launch,
                       timing=TimingOptions(mission_time_s=30.0, controller_on_after_s=1.0, action_delay_steps=1),
                       physics=V1_PHYSICS, sensors=FLIGHT_SENSORS, guidance=V1_GUIDANCE, limits=STRATOS3_V0.limits)
#: ``lvgym/SlenderAscent-v0``: the slender vehicle of thesis chapter 6 (8.5 m x 0.3 m, tables frozen at
#: Mach 2, the thesis's 2 mm wall), 10 s
SLENDER_V0 = TaskSpec(SlenderGeometry(8.5, 0.3, aero_mach=DEFAULT_AERO_MACH), launch=LaunchOptions(site="andoya"),
                      timing=TimingOptions(mission_time_s=10.0))
#: ``lvgym/SlenderAscent-v1``: the L/D 30 slender vehicle (8.5 m x 0.2833 m) with a 4.5 mm wall, protocol
#: v1's physics, sensors and delay
SLENDER_V1 = TaskSpec(SlenderGeometry(8.5, 0.2833, aero_mach=DEFAULT_AERO_MACH, wall_thickness=0.0045),
                      launch=SLENDER_V0.launch, timing=TimingOptions(mission_time_s=10.0, action_delay_steps=1),
                      physics=V1_PHYSICS, sensors=FLIGHT_SENSORS, guidance=V1_GUIDANCE)
