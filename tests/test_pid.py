"""Tests of baselines: the discrete PID law against hand numbers, schedules, the linearisation, the
bang-bang law and a short closed loop."""

import math
import warnings
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.design import linearize as lin
from lvgym.baselines.design import tune
from lvgym.baselines.bangbang import NEGATIVE, NONE, POSITIVE, BangBangRollPolicy
from lvgym.baselines.pid import GainSchedule, GainScheduledPIDPolicy, PIDLaw, PIDPolicy, smile_scheduled_pid
from lvgym.baselines.pidkernel import PID_ROW
from lvgym.envs.layouts import OBS_FLIGHT
from lvgym.errors import ConfigError
from lvgym.benchmark.policy import Policy, ZeroPolicy


def _law(kp, ki, kd, n=None, dt=0.1, limit=1e6):
    """The PID law for one row on an env of SMILE's flight observation, control period ``dt`` [s] and gimbal
    limit ``limit`` [rad] (the law's output limit)."""
    env = SimpleNamespace(unwrapped=SimpleNamespace(observation_layout=OBS_FLIGHT, gimbal_limit=limit,
                                                    task=SimpleNamespace(control_dt_s=dt)))
    return PIDLaw(env, gains=(kp, ki, kd, n))


def _update(law, e, on=True):
    """One step of the pitch axis on the error ``e = -(rate error)``; the command [rad]."""
    obs = OBS_FLIGHT.pack({"pitch_rate_error": -e, "controller_on": 1.0 if on else 0.0})[None].astype(np.float32)
    law.act([0], obs, {})
    return float(law.gimbal[0, 0])


def _state(law, field):
    return float(PID_ROW.view(law.st.pid, field)[0, 0])


def test_pid_step_response_by_hand():
    pid = _law(2.0, 1.0, 0.5, n=None, dt=0.1)
    # e = 1 from the first sample: P 2, I 0.1 per step (backward Euler), D 0 at the first sample
    assert _update(pid, 1.0) == pytest.approx(2.1)
    assert _update(pid, 1.0) == pytest.approx(2.2)
    # a step to e = 3: D = 0.5 * 2 / 0.1 = 10, I = 0.2 + 0.3
    assert _update(pid, 3.0) == pytest.approx(6.0 + 0.5 + 10.0)


def test_filtered_derivative_by_hand():
    pid = _law(0.0, 0.0, 1.0, n=10.0, dt=0.1)                # N dt = 1
    _update(pid, 0.0)
    d1 = _update(pid, 1.0)                                    # (0 + 1*10*1) / 2 = 5
    d2 = _update(pid, 1.0)                                    # (5 + 0) / 2 = 2.5
    assert (d1, d2) == (pytest.approx(5.0), pytest.approx(2.5))
    big = _law(0.0, 0.0, 1.0, n=1e9, dt=0.1)                  # N -> inf: the difference quotient
    _update(big, 0.0)
    assert _update(big, 1.0) == pytest.approx(10.0, rel=1e-6)


def test_output_limits_and_anti_windup():
    pid = _law(1.0, 10.0, 0.0, dt=0.1, limit=1.0)
    outs = [_update(pid, 5.0) for _ in range(20)]
    assert max(outs) == 1.0 and _state(pid, "saturated") == 1.0
    assert _state(pid, "integral") == 0.0                     # clamped from the first (saturated) sample
    # the error reverses: without windup the output leaves the limit at once
    assert _update(pid, -0.5) < 0.0


def test_off_freezes_integral_and_avoids_kick():
    pid = _law(1.0, 1.0, 1.0, n=None, dt=0.1)
    _update(pid, 1.0)
    i = _state(pid, "integral")
    assert _update(pid, 5.0, on=False) == 0.0 and _state(pid, "integral") == i
    assert _update(pid, 5.0) == pytest.approx(5.0 + i + 0.5)   # no derivative kick on switching on
    pid.reset([0])
    assert _state(pid, "integral") == 0.0 and _state(pid, "has_prev") == 0.0


def test_gains_are_checked_by_name():
    with pytest.raises(ConfigError, match=r"pid.kd = -1"):
        _law(1.0, 0.0, -1)
    with pytest.raises(ConfigError, match=r"pid.n = 0.0"):
        _law(1.0, 0.0, 0.0, n=0.0)


@pytest.fixture(scope="module")
def smile_env():
    return gym.make("lvgym/SmileAscent-v0", model="rigid")


def test_policy_reads_the_env_and_its_sign(smile_env):
    env = smile_env
    pol = PIDPolicy(1.0, 0.0, 0.0, None, env=env)
    assert isinstance(pol, Policy)
    assert pol.limit == env.unwrapped.gimbal_limit == pytest.approx(math.radians(5.0))
    assert pol.dt == env.unwrapped.task.control_dt_s
    lay = env.unwrapped.observation_layout
    obs = lay.pack({"pitch_rate_error": 0.01, "controller_on": 1.0}).astype(np.float32)
    a = pol.act(obs, {"time": 10.0})
    assert a[0] == pytest.approx(-0.01 / math.radians(5.0), rel=1e-5)   # positive pitch-rate error -> down
    obs[lay.index("controller_on")] = 0.0                     # the env's flag switches it off
    assert np.all(pol.act(obs, {"time": 10.0}) == 0)


def test_controller_flag_of_the_env_is_off_at_start_and_in_the_staging_coast(smile_env):
    """The PID keeps no off-windows of its own: the env's flag is off for the first 2 s and from burnout
    (43 s) to second-stage ignition (45 s), the thesis's windows (6.3)."""
    env = smile_env
    obs, info = env.reset(seed=0)
    lay = env.unwrapped.observation_layout
    flags = [(info["time"], obs[lay.index("controller_on")])]
    while True:
        obs, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        flags.append((info["time"], obs[lay.index("controller_on")]))
        if term or trunc:
            break
    t, on = np.array(flags).T
    assert np.all(on[(t < 1.99) | ((t > 43.01) & (t < 44.99))] == 0.0)
    assert np.all(on[((t > 2.01) & (t < 42.99)) | (t > 45.01)] == 1.0)


def test_schedule_interpolation_and_monotonic_check():
    s = GainSchedule("mass", (10.0, 8.0, 4.0), (1.0, 2.0, 4.0), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (100., 100., 300.))
    assert s.gains(9.0)[0] == pytest.approx(1.5)
    assert s.gains(6.0)[3] == pytest.approx(200.0)
    assert s.gains(20.0)[0] == 1.0 and s.gains(1.0)[0] == 4.0  # ends held
    with pytest.raises(ValueError, match="monotonic"):
        GainSchedule("mass", (10.0, 8.0, 9.0), (1, 1, 1), (0, 0, 0), (0, 0, 0), (1, 1, 1))
    thesis = GainSchedule.load("smile_thesis")
    assert thesis.gains(6347.0)[:3] == pytest.approx((8.98, 3.92, 4.57))
    env = gym.make("lvgym/SmileAscent-v0", model="rigid")
    pol = smile_scheduled_pid(env)                            # mass from the env: 6346 kg at 28.8 s
    mass = float(env.unwrapped.timeline.interp("mass", [28.8])[0])
    assert mass == pytest.approx(6347.0, abs=5.0)
    kp, ki, kd, n = pol.schedule.gains(mass)
    assert kp == pytest.approx(8.98, abs=0.02)
    lay = env.unwrapped.observation_layout
    e = float(np.float32(1e-4))
    pol.reset()
    pol.act(lay.pack({"pitch_rate_error": -e, "controller_on": 1.0}).astype(np.float32), {"mass": mass, "time": 28.8})
    assert pol.last_gimbal[0] == pytest.approx((kp + ki * pol.dt) * e, rel=1e-9)   # the first sample: P + I, no D
    tuned = GainScheduledPIDPolicy("smile", env=env)
    assert tuned.schedule.variable == "mass" and len(tuned.schedule.points) >= 4


@pytest.fixture(scope="module")
def op_rigid():
    return lin.operating_point("smile", 28.8, "rigid")


def test_rigid_linearisation_matches_analytic(op_rigid):
    num = lin.linearize(op=op_rigid)
    ana = lin.analytic_rigid(op_rigid)
    assert num.nstates == 3
    pn, pa = np.sort_complex(lin.control.poles(num)), np.sort_complex(lin.control.poles(ana))
    # the numerical model also has the pitch damping the textbook model leaves out: compare frequencies
    assert np.abs(pn).max() == pytest.approx(np.abs(pa).max(), rel=0.01)
    assert pn.real.max() == pytest.approx(pa.real.max(), rel=0.05)   # the slow drift pole
    for w in (1.0, 10.0, 75.0):
        assert abs(num(1j * w)) == pytest.approx(abs(ana(1j * w)), rel=0.02)
    assert num.B[2, 0] > 0                                            # positive gimbal: nose up


def test_margins_finite_rigid_and_nonrigid(op_rigid):
    rigid = lin.linearize(op=op_rigid)
    res = tune.tune(rigid, 75.0, 35.0, 0.02)
    assert res["phase_margin_deg"] == pytest.approx(35.0, abs=0.5)
    assert 5.0 < res["crossover_radps"] < 75.0 and not res["target_met"]
    nonrigid = lin.linearize("smile", 28.8, "nonrigid")
    assert nonrigid.nstates > 3                                       # slosh and bending
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = lin.margins(lin.loop(nonrigid, res["gains"], 0.02))
    assert math.isfinite(m["gain_margin_db"]) and math.isfinite(m["phase_margin_deg"])


def test_bangbang_law():
    law = BangBangRollPolicy(deadband_degps=1.0, release_fraction=0.5).law.batch(3)
    d = math.radians(1.0)
    on = np.ones(3, bool)
    # three rows at once: each row's pulse from its own rate and its own history
    assert law.command([0, 1, 2], [2 * d, -2 * d, 0.0], on).tolist() == [NEGATIVE, POSITIVE, NONE]
    assert law.command([0, 1, 2], [0.8 * d, -0.8 * d, 0.8 * d], on).tolist() == [NEGATIVE, POSITIVE, NONE]  # hysteresis
    assert law.command([0, 1], [0.4 * d, -2 * d], on[:2]).tolist() == [NONE, POSITIVE]
    assert law.command([1], [-2 * d], [False]).tolist() == [NONE]
    env = gym.make("lvgym/StratosIII-v0", model="rigid")
    obs, info = env.reset(seed=0)
    for _ in range(60):                                               # spin up with positive pulses
        obs, *_, info = env.step(np.array([POSITIVE]))
    roll = env.unwrapped.observation_layout.index("roll_rate")
    spun = abs(obs[roll])
    bb = BangBangRollPolicy(deadband_degps=0.5)
    for _ in range(100):
        obs, *_, info = env.step(bb.act(obs, info))
    assert abs(obs[roll]) < 0.2 * spun


def test_closed_loop_pid_beats_zero_under_wind():
    sched = GainSchedule.load("smile")
    gains = sched.gains(sched.points[2])

    def run(policy):
        env = gym.make("lvgym/SmileAscent-v0", model="rigid", wind="profile")
        policy = policy(env)
        obs, info = env.reset(seed=0)
        policy.reset()
        for _ in range(400):                                          # 8 s
            obs, *_, info = env.step(policy.act(obs, info))
        return float(info["cumulative_rate_error"][1:].sum())

    zero, pid = run(lambda env: ZeroPolicy()), run(lambda env: PIDPolicy(*gains, env=env))
    assert pid < 0.7 * zero


def test_old_package_name_still_works():
    """``baselines_pid`` (the controllers' old name, kept in a checkout, not installed) gives the same objects
    as ``lvgym.baselines``."""
    import baselines_pid
    import baselines_pid.pid
    import baselines_pid.tune

    import lvgym.baselines
    import lvgym.baselines.design.tune
    import lvgym.baselines.pid

    assert baselines_pid.GainScheduledPIDPolicy is lvgym.baselines.GainScheduledPIDPolicy
    assert baselines_pid.pid.GainSchedule is lvgym.baselines.pid.GainSchedule
    assert baselines_pid.tune.main is lvgym.baselines.design.tune.main
