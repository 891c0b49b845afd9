"""Coast attitude control (lvgym/envs/coast.py): the law against hand numbers, and in flight."""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.envs.coast import DAMPING, coast_moment
from lvgym.errors import ConfigError
from lvgym.simulator.layouts import CONTEXT


def test_coast_law_hand_numbers():
    # J = 1000 kg m^2, w = 2 rad/s: M = -1000 (4 * 0.01 + 2 * 0.7 * 2 * 0.02) = -96 N m (pitch)
    m = coast_moment(np.array([[0.01, -0.005]]), np.array([[0.02, 0.0]]), np.array([[1000.0, 2000.0]]), 2.0, 500.0)
    assert m[0, 0] == pytest.approx(-1000.0 * (4.0 * 0.01 + 2.0 * DAMPING * 2.0 * 0.02))
    assert m[0, 1] == pytest.approx(2000.0 * 4.0 * 0.005)
    limited = coast_moment(np.array([[1.0, -1.0]]), np.zeros((1, 2)), np.array([[1000.0, 1000.0]]), 2.0, 300.0)
    np.testing.assert_array_equal(limited, [[-300.0, 300.0]])


def _coast(**options) -> tuple[float, float, float, float]:
    """SMILE rigid, gimbal held at zero, to 44.9 s (burnout at 43 s, separation at 44 s, ignition at 45 s):
    the attitude error [deg] at burnout and at the end, the largest |moment| [N m] before burnout and in
    the coast."""
    env = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=44.9, randomize=["thrust_misalignment"], qalpha_limit_pa_deg=1e9, attitude_limit_deg=90.0,
                   **options)
    env.reset(seed=3)
    u = env.unwrapped
    at_burnout, before, during = 0.0, 0.0, 0.0
    done = False
    while not done:
        _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        done = term or trunc
        m = float(np.abs(CONTEXT.view(u.sim.data.ctx[:, :CONTEXT.size], "moment_b")[0]).max())
        if info["time"] < 43.0 - 1e-9:
            before = max(before, m)
            at_burnout = float(np.degrees(np.hypot(*info["attitude_error"])))
        else:
            during = max(during, m)
    assert not term
    return at_burnout, float(np.degrees(np.hypot(*info["attitude_error"]))), before, during


def test_coast_control_acts_only_in_the_coast_and_turns_the_vehicle_back():
    start, end, before, during = _coast()
    assert before == during == 0.0                              # off by default (v0)
    start, end_strong, before, during = _coast(coast_control=True, coast_torque_nm=1e6, coast_bandwidth_radps=15.0)
    assert before == 0.0 and during > 0.0                       # the policy has the vehicle while an engine burns
    # an RCS as stiff as the fins (J w_n^2 ~ 3 MN m/rad, limited to 1 MN m, against ~1 MN m/rad) brings the axis back to the reference
    assert end_strong < 0.6 * start and end_strong < 0.6 * end, (start, end, end_strong)
    _, _, _, during = _coast(coast_control=True)
    assert during == pytest.approx(300.0)                       # the default torque saturates here


def test_coast_control_options_are_checked():
    with pytest.raises(ConfigError, match="coast_control"):
        gym.make("lvgym/SmileAscent-v0", coast_control=1)
    with pytest.raises(ConfigError, match="coast_torque_nm"):
        gym.make("lvgym/SmileAscent-v0", coast_torque_nm=-1.0)
