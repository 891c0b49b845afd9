"""Tests of adaptive augmenting control (baselines/aac.py, docs/adaptive-control.md): one step of the law
by hand, the three behaviours (tracking error raises k_T, high-frequency content lowers it, leakage brings it
back to 1), bounds, the controller-on flag, determinism, parameter checks and a short v1 flight."""

import math
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.aac import (FLEX_AAC, AACParams, AdaptiveAugmentingPolicy, AdaptiveGainLaw, FirstOrderFilter, flex_aac,
                          smile_aac)
from lvgym.baselines.pid import FLEX_SCHEDULES, flex_pid
from lvgym.benchmark.policy import Policy
from lvgym.envs.layouts import OBS_FLIGHT
from lvgym.errors import ConfigError

DT, LIMIT = 0.02, math.radians(5.0)


def law(**changes):
    return AdaptiveGainLaw(AACParams().replace(**changes), DT, LIMIT)


def run(lw, u, err, on=True, ref=(0.0, 0.0)):
    """Steps of the law over rows of ``u`` and ``err`` (n, 2); returns the gains (n, 2)."""
    ks = []
    for ui, ei in zip(u, err):
        lw.step(ui, ei, np.asarray(ref), on)
        ks.append(lw.gains().copy())
    return np.array(ks)


def test_one_step_of_the_law_by_hand():
    lw = law(error_gain=3000.0, damper_gain=2.0e4, leak_rate=0.5, k_min=0.5, k_max=2.0)
    # a e^2 = 3000 * 0.01^2 = 0.3, no damper: r = c = 0.5, k_inf = (0.3 + 0.5) / 0.5 = 1.6
    k = lw.gain_step(np.array([1.0]), np.array([1e-4]), np.array([0.0]))
    assert k[0] == pytest.approx(1.6 - 0.6 * math.exp(-0.5 * DT), rel=1e-12)   # 1.0059700...
    assert k[0] == pytest.approx(1.0 + 0.3 * DT, rel=1e-4)                    # forward Euler, to first order
    # damper: b y = 2e4 * 1e-4 = 2, r = 2.5, k_inf = (0 + 2 * 0.5 + 0.5) / 2.5 = 0.6
    k = lw.gain_step(np.array([1.0]), np.array([0.0]), np.array([1e-4]))
    assert k[0] == pytest.approx(0.6 + 0.4 * math.exp(-2.5 * DT), rel=1e-12)  # 0.98039...
    # no leakage, no damper: k grows by a e^2 dt exactly
    lw0 = law(error_gain=3000.0, leak_rate=0.0)
    assert lw0.gain_step(np.array([1.0]), np.array([1e-4]), np.array([0.0]))[0] == pytest.approx(1.0 + 0.3 * DT)
    # the exact step never overshoots the lower bound, however stiff the damper
    assert law(damper_gain=1e12).gain_step(np.array([1.0]), np.array([0.0]), np.array([1.0]))[0] >= 0.5


def test_filters_by_hand():
    lo = FirstOrderFilter("low", 1.0, DT, 1)
    w = 2 * math.pi
    kk = w / math.tan(w * DT / 2)
    assert lo.step([1.0])[0] == pytest.approx(w / (kk + w))                  # first sample: previous input 0
    ys = [lo.step([1.0])[0] for _ in range(2000)]
    assert ys[-1] == pytest.approx(1.0)                                       # unit DC gain
    hi = FirstOrderFilter("high", 1.0, DT, 1)
    assert hi.step([3.0])[0] == 0.0                                           # a restart is not a step
    assert [hi.step([3.0])[0] for _ in range(5)] == [0.0] * 5
    with pytest.raises(ValueError):
        FirstOrderFilter("band", 1.0, DT, 1)


def test_nominal_gain_stays_at_one_and_leaks_back_after_a_disturbance():
    lw = law()
    n = 200
    ks = run(lw, np.full((n, 2), 0.01), np.full((n, 2), 0.005))     # steady command, error inside the dead zone
    assert np.all(ks == 1.0)
    # a 1 s disturbance: 3 deg/s of error raises k_T
    ks = run(lw, np.full((50, 2), 0.01), np.full((50, 2), math.radians(3.0)))
    k_peak = ks[-1, 0]
    assert k_peak > 1.2
    # then nominal again: k_T leaks back towards 1 at the leak rate c (the filtered error decays in ~0.2 s)
    ks = run(lw, np.full((1000, 2), 0.01), np.zeros((1000, 2)))
    t = DT * np.arange(1, 1001)
    assert np.all(np.diff(ks[25:, 0]) <= 0.0) and ks[-1, 0] == pytest.approx(1.0, abs=1e-3)
    late = t > 1.0
    ratio = (ks[late, 0] - 1.0) / (ks[np.argmax(late) - 1, 0] - 1.0)
    assert ratio[-1] == pytest.approx(math.exp(-0.5 * (t[late][-1] - t[np.argmax(late) - 1])), rel=0.02)


def test_tracking_error_raises_the_gain_and_the_dead_zone_holds_it():
    p = AACParams()
    e = p.error_deadzone_radps + 0.01                                  # 0.01 rad/s beyond the dead zone
    lw = law()
    ks = run(lw, np.zeros((1000, 2)), np.tile([e, 0.0], (1000, 1)))
    assert lw.e[0] == pytest.approx(-0.01, rel=1e-3)     # dead-zoned, filtered; e = model - gyro = -rate error
    k_inf = 1.0 + p.error_gain * 0.01 ** 2 / p.leak_rate               # equilibrium of a e^2 = c (k - 1): 1.6
    assert ks[-1, 0] == pytest.approx(k_inf, rel=1e-3)
    assert np.all(ks[:, 1] == 1.0)                                     # per axis: yaw saw no error
    below = law()
    assert np.all(run(below, np.zeros((300, 2)), np.full((300, 2), 0.9 * p.error_deadzone_radps)) == 1.0)
    shared = law(per_axis=False)
    ks = run(shared, np.zeros((1000, 2)), np.tile([e, 0.0], (1000, 1)))
    assert ks[-1, 0] == ks[-1, 1] == pytest.approx(k_inf, rel=1e-3)


def test_high_frequency_command_lowers_the_gain_and_low_frequency_does_not():
    t = DT * np.arange(500)
    amp = math.radians(1.0)
    fast = law()
    ks_fast = run(fast, np.column_stack([amp * np.sin(2 * math.pi * 10.0 * t), np.zeros_like(t)]), np.zeros((500, 2)))
    slow = law()
    ks_slow = run(slow, np.column_stack([amp * np.sin(2 * math.pi * 0.5 * t), np.zeros_like(t)]), np.zeros((500, 2)))
    assert ks_fast[-100:, 0].max() < 0.8                               # 10 Hz, a bending frequency of SMILE
    assert ks_slow[:, 0].min() > 0.97                                  # 0.5 Hz, the rigid-body band
    assert np.all(ks_fast[:, 1] == 1.0)


def test_bounds_hold_under_extreme_inputs():
    p = AACParams()
    big = law()
    ks = run(big, np.zeros((300, 2)), np.full((300, 2), 10.0))
    assert ks.max() == p.k_max and np.all(ks <= p.k_max)
    t = DT * np.arange(300)
    hf = law()
    u = np.column_stack([LIMIT * np.sign(np.sin(2 * math.pi * 12.5 * t + 0.3))] * 2)
    ks = run(hf, u, np.zeros((300, 2)))
    assert np.all(ks >= p.k_min) and ks.min() < 0.6
    out = big.step(np.array([1.0, -1.0]), np.zeros(2), np.zeros(2), True)
    assert np.all(np.abs(out) <= LIMIT)                                # the command stays within the gimbal limit


def test_controller_off_freezes_and_engagement_resets():
    lw = law()
    run(lw, np.zeros((100, 2)), np.full((100, 2), 0.05))
    k_on = lw.gains().copy()
    assert k_on[0] > 1.0
    out = lw.step(np.array([0.05, 0.05]), np.full(2, 0.5), np.zeros(2), False)
    ks_off = run(lw, np.zeros((50, 2)), np.full((50, 2), 0.5), on=False)
    assert np.all(out == 0.0) and np.all(ks_off == k_on)               # frozen while off, the gimbal at 0
    lw.step(np.zeros(2), np.zeros(2), np.zeros(2), True)
    assert np.all(lw.gains() < k_on) and lw.gains()[0] == pytest.approx(1.0, abs=1e-12)   # engaged again: from 1
    hold = law(reset_on_engage=False)
    run(hold, np.zeros((100, 2)), np.full((100, 2), 0.05))
    k_hold = hold.gains().copy()
    run(hold, np.zeros((10, 2)), np.zeros((10, 2)), on=False)
    hold.step(np.zeros(2), np.zeros(2), np.zeros(2), True)
    assert hold.gains()[0] == pytest.approx(k_hold[0], rel=0.02)       # held, then one step of leakage


class _Base:
    """A PID-type base for the policy wrapper: commands a fixed pattern of gimbal angles [rad]."""

    name, dt, limit = "stub", DT, LIMIT

    def __init__(self):
        self.reset()

    def reset(self):
        self.n = 0
        self.last_gimbal = np.zeros(2)

    def act(self, observation, info):
        self.last_gimbal = np.array([0.01 * math.sin(2 * math.pi * 9.0 * self.n * DT), 0.002])
        self.n += 1
        return self.last_gimbal / self.limit


def _fake_env():
    return SimpleNamespace(unwrapped=SimpleNamespace(observation_layout=OBS_FLIGHT, gimbal_limit=LIMIT,
                                                     task=SimpleNamespace(control_dt_s=DT)))


def test_policy_wrapper_is_deterministic_and_respects_controller_on():
    env = _fake_env()
    pol = AdaptiveAugmentingPolicy(_Base(), env=env, record=True)
    assert isinstance(pol, Policy) and pol.name == "aac(stub)"
    rng = np.random.default_rng(3)
    obs = np.zeros((300, OBS_FLIGHT.size))
    i_on, i_err = OBS_FLIGHT.index("controller_on"), OBS_FLIGHT.index("pitch_rate_error")
    obs[50:, i_on] = 1.0
    obs[:, i_err] = rng.normal(0.0, 0.03, 300)

    def fly():
        pol.reset()
        return np.array([pol.act(o, {"time": DT * j}) for j, o in enumerate(obs)]), pol.trajectory()

    a1, tr1 = fly()
    a2, tr2 = fly()
    assert np.array_equal(a1, a2) and np.array_equal(tr1["k"], tr2["k"])
    assert np.all(a1[:50] == 0.0) and np.all(tr1["k"][:50] == 1.0)     # off: no command, k_T untouched
    assert tr1["k"][-1, 0] < 1.0                                       # the 9 Hz pitch command is damped
    assert a1.dtype == np.float32 and np.all(np.abs(a1) <= 1.0)


def test_parameters_are_checked_by_name():
    with pytest.raises(ConfigError, match=r"aac.k_min = 1.2"):
        AACParams(k_min=1.2)
    with pytest.raises(ConfigError, match=r"aac.k_max = 0.9"):
        AACParams(k_max=0.9)
    with pytest.raises(ConfigError, match=r"aac.error_gain = -1"):
        AACParams(error_gain=-1)
    with pytest.raises(ConfigError, match=r"aac.per_axis = 1: true or false"):
        AACParams(per_axis=1)
    with pytest.raises(ConfigError, match=r"aac.damper_hp_hz = 30.0: must be below the Nyquist"):
        AdaptiveGainLaw(AACParams(damper_hp_hz=30.0), DT, LIMIT)
    with pytest.raises(ConfigError, match=r"aac.gain = 2"):
        smile_aac(_fake_env(), gain=2)
    assert AACParams().replace(k_max=1.5).k_max == 1.5


@pytest.fixture(scope="module")
def v1_rigid():
    return gym.make("lvgym/SmileAscent-v1", model="rigid", mission_time_s=6.0)


def test_aac_flies_smile_v1_rigid(v1_rigid):
    pol = smile_aac(v1_rigid, record=True)
    obs, info = v1_rigid.reset(seed=0)
    pol.reset()
    for _ in range(300):
        obs, reward, terminated, truncated, info = v1_rigid.step(pol.act(obs, info))
        if terminated or truncated:
            break
    assert truncated and not terminated                                # flew the whole 6 s
    tr = pol.trajectory()
    p = pol.params
    assert tr["on"].any() and np.all((tr["k"] >= p.k_min) & (tr["k"] <= p.k_max))
    assert np.abs(tr["k"][tr["on"]] - 1.0).max() < 0.5


def test_damper_dead_zone_acts_on_the_excess_only():
    # y below the dead zone: the law is the leak and the error term alone; above: the damper sees y - y_dz
    dz = 3e-3
    plain, zoned = law(damper_gain=2.0e4), law(damper_gain=2.0e4, damper_deadzone_rad2=dz)
    for y, y_seen in ((1e-3, 0.0), (5e-3, 5e-3 - dz)):
        k0 = np.array([1.4, 1.4])
        for lw in (plain, zoned):
            lw.reset()
            lw.on = True
            lw.k[:] = k0
            lw.y[:] = y
        zoned.step(np.zeros(2), np.zeros(2), np.zeros(2), True)
        expected = plain.gain_step(k0, np.zeros(2), np.full(2, y_seen))
        np.testing.assert_allclose(zoned.gains(), expected, rtol=1e-12)
    # default 0: the published law, y as it is
    assert AACParams().damper_deadzone_rad2 == 0.0
    with pytest.raises(ConfigError, match=r"aac.damper_deadzone_rad2 = -1"):
        AACParams(damper_deadzone_rad2=-1)


def test_flex_policies_follow_the_envs_vehicle(v1_rigid):
    pol = flex_pid(v1_rigid)
    assert pol.schedule.meta["vehicle"] == "smile" and FLEX_SCHEDULES["smile_v1"] == "smile_flex"
    stratos = gym.make("lvgym/StratosIII-v1", mission_time_s=2.0)
    assert flex_pid(stratos).schedule.meta["vehicle"] == "stratos3"
    assert flex_pid(gym.make("lvgym/SlenderAscent-v1", mission_time_s=2.0)).schedule.meta["vehicle"] == "slender"
    for env_id, opts in (("lvgym/SmileAscent-v0", {}), ("lvgym/SlenderAscent-v0", {}),
                         ("lvgym/SlenderAscent-v1", {"wall_thickness_m": 0.002})):   # the thesis's tube: no design
        with pytest.raises(ConfigError, match="env vehicle"):
            flex_pid(gym.make(env_id, **opts))
    aac = flex_aac(v1_rigid)
    assert aac.params.damper_deadzone_rad2 == FLEX_AAC["damper_deadzone_rad2"] and aac.name == "aac"
    assert flex_aac(v1_rigid, damper_deadzone_rad2=0.0).params.damper_deadzone_rad2 == 0.0


def test_aac_sweep_variants_and_the_scaled_base():
    """The tuning command's variants are AACParams keywords (a typo is a ConfigError naming it), 'none' is
    the base alone, and a scaled base scales both its action and the ``last_gimbal`` the law reads."""
    from experiments.aac_tuning.aac_sweep import ScaledBase, parse_variant
    from lvgym.errors import ConfigError

    assert parse_variant("none") is None
    assert parse_variant("damper_gain=1e3, damper_deadzone_rad2=0") == {"damper_gain": 1000.0,
                                                                         "damper_deadzone_rad2": 0}
    with pytest.raises(ConfigError, match="damper_gian"):
        parse_variant("damper_gian=1")
    with pytest.raises(ConfigError, match="key=value"):
        parse_variant("damper_gain")

    class Base:
        name, dt, limit = "base", 0.02, 0.1

        def reset(self):
            self.last_gimbal = np.zeros(2)

        def act(self, observation, info):
            self.last_gimbal = np.array([0.02, -0.05])
            return (self.last_gimbal / self.limit).astype(np.float32)

    b = ScaledBase(Base(), 2.0)
    b.reset()
    np.testing.assert_allclose(b.act(np.zeros(3), {}), [0.4, -1.0], rtol=1e-6)
    np.testing.assert_allclose(b.last_gimbal, [0.04, -0.1])
    assert (b.dt, b.limit, b.name) == (0.02, 0.1, "base*2")
