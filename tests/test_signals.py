"""The compiled task signals and step against independent numpy formulas and hand numbers.

The env's observation, reference and reward come from one compiled call (lvgym.envs.signals), the
gimbal servo and the rail from the simulator's compiled step (lvgym.simulator.advance); these tests
recompute them here from the simulator's state with plain numpy.
"""

import math

import gymnasium as gym
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import lvgym  # noqa: F401  (registers the envs)
from lvgym.simulator import LaunchSpec, PhysicsSpec, Simulator, TimelineSpec
from lvgym.simulator.core import dcm_batch
from lvgym.simulator.layouts import ACTUATOR
from lvgym.simulator.servo import DIRECT, Servo, servo_step_k

G0 = 9.80665


def _reference_pitch_rate(core, t, v, g, spec):
    if spec.kick_start_s <= t < spec.kick_end_s:
        return -math.radians(spec.kick_angle_deg) / (spec.kick_end_s - spec.kick_start_s)
    if t < spec.kick_end_s:
        return 0.0
    up = -g / np.linalg.norm(g)
    speed = max(np.linalg.norm(v), 1.0)
    cos_th = np.clip(v @ up / speed, -1.0, 1.0)
    return -np.linalg.norm(g) * math.sqrt(1.0 - cos_th**2) / speed


@pytest.mark.parametrize("observation", ["state", "sensors"])
def test_observation_and_reference_equal_numpy_formulas(observation):
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="gust", reference="gravity_turn",
                   observation=observation, randomize=["wind", "mass", "thrust_misalignment"])
    env.reset(seed=3)
    core = env.unwrapped
    spec, lay = core.task, core.observation_layout
    rng = np.random.default_rng(0)
    checked = 0
    for k in range(700):
        axis_before = core.state.task.axis_ref_i[0].copy()
        obs, _, term, trunc, info = env.step(rng.uniform(-0.3, 0.3, 2).astype(np.float32))
        assert not term and not trunc
        if k % 70 != 69:
            continue
        sim = core.flight                                         # the episode's rows, read by name
        t = float(sim.t[0])
        x_b = sim.state("v_zw_i")[0]
        ref = _reference_pitch_rate(core, t, x_b, sim.conditions("g_i")[0], spec)
        C = dcm_batch(sim.state("q_bi")[:1])[0]
        # the reference axis turned by ref * dt about the body pitch axis
        turn = Rotation.from_rotvec(ref * spec.control_dt_s * C[:, 1])
        np.testing.assert_allclose(core.state.task.axis_ref_i[0], turn.apply(axis_before), atol=1e-12)
        e_b = C.T @ np.cross(C[:, 0], core.state.task.axis_ref_i[0])
        w = sim.state("omega_bi_b")[0].copy()
        if observation == "sensors":
            dphi = core.timeline.left("dphi_sensor", sim.t)[0, 0]            # IMU slopes (K,)
            eta_dot = sim.state("eta_dot")[0]                              # (2, K): y, z planes
            w += np.array([0.0, -dphi @ eta_dot[1], dphi @ eta_dot[0]])
            f = sim.conditions("f_aero_b")[0] + sim.conditions("thrust_b")[0]
            m = core.timeline.interp("mass", sim.t)[0]
            flow = {"accel_z": f[2] / m / G0, "accel_y": f[1] / m / G0}
        else:
            flow = {"alpha": sim.conditions("alpha")[0], "beta": sim.conditions("beta")[0]}
        on = float(t >= spec.controller_on_after_s and bool(core.timeline.left("burning", sim.t)[0]))
        g = sim.gimbal[0] / core.gimbal_limit
        expected = lay.pack({"roll_rate": w[0], "pitch_rate_error": w[1] - ref, "yaw_rate_error": w[2],
                             "pitch_attitude_error": -e_b[1], "yaw_attitude_error": -e_b[2], **flow,
                             "mach_over_10": sim.conditions("mach")[0] / 10, "qbar_over_1e5": sim.conditions("qbar")[0] / 1e5,
                             "gimbal_pitch": g[0], "gimbal_yaw": g[1], "time_fraction": t / spec.mission_time_s,
                             "controller_on": on, "pitch_rate_reference": ref})
        assert set(lay.names) == {"roll_rate", "pitch_rate_error", "yaw_rate_error", "pitch_attitude_error",
                                  "yaw_attitude_error", *flow, "mach_over_10", "qbar_over_1e5", "gimbal_pitch",
                                  "gimbal_yaw", "time_fraction", "controller_on", "pitch_rate_reference"}
        np.testing.assert_allclose(obs, expected.astype(np.float32), rtol=2e-6, atol=1e-7)
        assert info["attitude_error"] == pytest.approx(-e_b[1:], abs=1e-12)
        checked += 1
    assert checked == 10


def test_servo_hand_numbers():
    s = Servo(frequency=15.0, damping=0.7, limit=math.radians(5.0), rate_limit=math.radians(30.0)).params()
    act = ACTUATOR.zeros()
    cmd, pos, rate = (ACTUATOR.view(act, n) for n in ("command", "gimbal", "gimbal_rate"))
    cmd[:] = [math.radians(0.1), -math.radians(0.1)]
    servo_step_k(s, act, 0.01, 0)
    # semi-implicit Euler from rest: rate = h w^2 c, position = h rate
    np.testing.assert_allclose(rate, 0.01 * 225.0 * cmd)
    np.testing.assert_allclose(pos, 0.01 * 0.01 * 225.0 * cmd)
    # a large command is clipped to the 5 deg limit; the rate saturates at 30 deg/s on the way, then the
    # position stops at 5 deg (rate zeroed there)
    pos[:], rate[:] = 0.0, 0.0
    small = cmd.copy()
    cmd[:] = [1.0, -1.0]
    servo_step_k(s, act, 0.01, 0)
    np.testing.assert_allclose(np.abs(rate), 0.01 * 225.0 * math.radians(5.0))
    peak = 0.0
    for _ in range(100):
        servo_step_k(s, act, 0.01, 0)
        peak = max(peak, np.abs(rate).max())
    assert peak == pytest.approx(math.radians(30.0), rel=1e-12)
    np.testing.assert_allclose(pos, [math.radians(5.0), -math.radians(5.0)])
    np.testing.assert_allclose(rate, 0.0)
    # no servo: the position is the command
    cmd[:] = small
    servo_step_k(DIRECT, act, 0.01, 0)
    np.testing.assert_array_equal(pos, small)


def test_servo_rejects_bad_values():
    with pytest.raises(ValueError, match="servo.damping"):
        Servo(damping=-0.1)


def test_rail_exit_is_found_at_the_physics_step():
    """Travel along the rail is checked after every RK4 step, not only at the end of a step() call."""
    sim = Simulator("stratos3", "rigid", launch=LaunchSpec("el_arenosillo", 85.0, 10.0),
                    timeline=TimelineSpec(t_end=3.0), physics=PhysicsSpec(0.01))
    d = sim.reset()
    exit_t = None
    while exit_t is None:
        for t, e in sim.step(d, [[0.0, 0.0]], 0.1)[0]:         # 10 physics steps per call
            if e == "rail exit":
                exit_t = t
    v = sim.view(d)
    speed = np.linalg.norm(v.state("v_zw_i")[0] - np.cross([0, 0, sim.omega_e], v.state("r_zw_i")[0]))
    assert 10.0 <= v.rail_s[0] < 10.0 + 0.01 * speed           # within one physics step of travel
    assert abs(exit_t / 0.01 - round(exit_t / 0.01)) < 1e-6      # on a physics step, inside the call


def test_batched_row_infos_equal_single_row_infos():
    from lvgym import make_vector
    from lvgym.envs.core import row_info, row_infos
    env = make_vector("lvgym/SmileAscent-v0", num_envs=3, model="nonrigid", wind="gust")
    env.reset(seed=1)
    for _ in range(120):
        _, _, _, _, info = env.step(np.full((3, 2), 0.1, dtype=np.float32))
    rows = row_infos(info, 3)
    for b in range(3):
        one = row_info(info, b)
        assert rows[b].keys() == one.keys()
        for key, value in one.items():
            if isinstance(value, np.ndarray):
                np.testing.assert_array_equal(rows[b][key], value)
            else:
                assert rows[b][key] == value, key
