"""Coast attitude control (lvgym/envs/coast.py): the law against hand numbers, and in flight."""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.pid import smile_scheduled_pid
from lvgym.envs.coast import DAMPING, coast_moment
from lvgym.errors import ConfigError
from lvgym.simulator.layouts import CONTEXT


def test_coast_law_hand_numbers():
    # J = 1000 kg m^2, w = 2 rad/s: M_y = -1000 (4 * 0.01 + 2 * 0.7 * 2 * 0.02); M_z = -2000 (4 * -0.005)
    m = coast_moment(np.array([0.01]), np.array([0.005]), np.array([[0.02, 0.0]]), np.array([[1000.0, 2000.0]]),
                     2.0, 500.0)
    assert m[0, 0] == pytest.approx(-1000.0 * (4.0 * 0.01 + 2.0 * DAMPING * 2.0 * 0.02))
    assert m[0, 1] == pytest.approx(2000.0 * 4.0 * 0.005)
    limited = coast_moment(np.array([1.0]), np.array([1.0]), np.zeros((1, 2)), np.array([[1000.0, 1000.0]]), 2.0, 300.0)
    np.testing.assert_array_equal(limited, [[-300.0, 300.0]])


def _coast(**options) -> tuple[float, float, float]:
    """SmileAscent-v1 rigid, the rigid-designed gs-pid flying, to its 54 s ignition (burnout 43 s, separation
    53 s, at 1.8 kPa on this nominal trajectory):
    the largest |moment| [N m] before burnout and in the coast, and the largest total angle of attack
    [deg] of the finless upper stack between separation and ignition."""
    env = gym.make("lvgym/SmileAscent-v1", model="rigid", mission_time_s=54.0, randomize=["thrust_misalignment"],
                   wind="turbulence", qalpha_limit_pa_deg=1e9, attitude_limit_deg=90.0, **options)
    obs, info = env.reset(seed=3)
    u = env.unwrapped
    pid = smile_scheduled_pid(u, "smile")
    pid.reset()
    before, during, alpha = 0.0, 0.0, 0.0
    done = False
    while not done:
        obs, _, term, trunc, info = env.step(pid.act(obs, info))
        done = term or trunc
        m = float(np.abs(CONTEXT.view(u.state.sim.ctx[:, :CONTEXT.size], "moment_b")[0]).max())
        if info["time"] < 43.0 - 1e-9:
            before = max(before, m)
        else:
            during = max(during, m)
        if info["time"] > 53.0:
            alpha = max(alpha, float(np.degrees(info["alpha_total"])))
    assert not term
    return before, during, alpha


def test_coast_control_holds_the_upper_stack_into_the_wind():
    before, during, free = _coast(coast_control=False)
    assert before == during == 0.0
    before, during, held = _coast()
    assert before == 0.0 and during > 0.0                 # the policy has the vehicle while an engine burns
    assert held < 1.0 and free > 3.0 * held, (held, free)  # the finless stack diverges without it


def test_coast_control_options_are_checked():
    with pytest.raises(ConfigError, match="coast_control"):
        gym.make("lvgym/SmileAscent-v0", coast_control=1)
    with pytest.raises(ConfigError, match="coast_torque_nm"):
        gym.make("lvgym/SmileAscent-v0", coast_torque_nm=-1.0)


def test_settling_thrust_is_a_body_force_at_the_cg():
    """The simulator's commanded body force: F along +x_b adds F / m to the acceleration along the body
    axis (checked against a flight without it over one short step on the pad-free upper stage coast)."""
    env = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=44.9, settling_thrust_n=1e4)
    ref = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=44.9)
    for e in (env, ref):
        e.reset(seed=1)
    u, r = env.unwrapped, ref.unwrapped
    lay = u.sim.layout.state
    while True:
        _, _, _, _, info = env.step(np.zeros(2, np.float32))
        ref.step(np.zeros(2, np.float32))
        if info["time"] >= 43.5 - 1e-9:
            break
    # equal until the burnout at 43 s (the force acts only in a coast), then the speed gain is F / m t
    v = u.flight.x[0, lay["v_zw_i"]]
    v_ref = r.flight.x[0, lay["v_zw_i"]]
    gain = float(np.linalg.norm(v) - np.linalg.norm(v_ref))
    assert gain == pytest.approx(1e4 / info["mass"] * 0.5, rel=0.05)


def test_smile_v1_defaults_and_staging():
    """SmileAscent-v1: the smile_v1 vehicle (separation at 53 s, ignition at 54 s), 70 s, reaction control
    and settling thrust in the coast, one control period of delay."""
    env = gym.make("lvgym/SmileAscent-v1", model="rigid").unwrapped
    spec = env.specs[0]
    assert spec.coast_control and spec.settling_thrust_n == 18000.0 and spec.action_delay_steps == 1
    assert spec.mission_time_s == 70.0 and spec.reference_velocity == "earth"
    assert (spec.mode_interval_s, spec.mode_basis, spec.slosh_frequency) == (2.0, "projected", "specific_force")
    assert spec.observation == "flight" and spec.gyro_bias_radps == 1.5e-5
    times = {e: t for t, e in env.timeline.events}
    assert times["stage 'stage1' burnout"] == pytest.approx(43.0)
    assert times["stage 'stage1' separation"] == pytest.approx(53.0)
    assert times["stage 'stage2' ignition"] == pytest.approx(54.0)
    assert env.sim.stage_aerodynamics[1] is not env.sim.stage_aerodynamics[0]   # the upper stack's own
