"""Tests of adaptive augmenting control (baselines/aac.py, docs/adaptive-control.md): one step of the law
by hand, the three behaviours (tracking error raises k_T, high-frequency content lowers it, leakage brings it
back to 1), bounds, the controller-on flag, determinism, parameter checks and a short v1 flight."""

import math
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.aac import FLEX_AAC, AACLaw, AACParams, AdaptiveAugmentingPolicy, consts, flex_aac, smile_aac
from lvgym.baselines.aackernel import AAC_ROW, first_order, gain_step_k
from lvgym.baselines.pid import FLEX_SCHEDULES, flex_pid
from lvgym.benchmark.batch import BatchLaw
from lvgym.benchmark.policy import Policy
from lvgym.envs.layouts import OBS_FLIGHT
from lvgym.errors import ConfigError

DT, LIMIT = 0.02, math.radians(5.0)


class _Commands(BatchLaw):
    """A base law whose rows' commands [rad] are set from outside (``next``), for the adaptive law alone."""

    name, dt, limit = "stub", DT, LIMIT

    def __init__(self, n: int = 1) -> None:
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.gimbal, self.next = np.zeros((n, 2)), np.zeros((n, 2))

    def reset(self, rows) -> None:
        self.gimbal[rows] = 0.0

    def act(self, rows, observations, info):
        self.gimbal[rows] = self.next[rows]
        return (self.gimbal[rows] / LIMIT).astype(np.float32)


def _fake_env():
    return SimpleNamespace(unwrapped=SimpleNamespace(observation_layout=OBS_FLIGHT, gimbal_limit=LIMIT,
                                                     task=SimpleNamespace(control_dt_s=DT)))


def law(**changes):
    """The adaptive law for one row on a base whose commands the test sets."""
    return AACLaw(_Commands(), env=_fake_env(), params=AACParams().replace(**changes))


def step(lw, u, err, on=True, ref=(0.0, 0.0)):
    """One step of the law's row 0: base commands ``u`` (2,) [rad], rate errors ``err`` (2,) [rad/s], the pitch
    rate reference ``ref[0]``; the command sent (2,) [rad]."""
    lw.base.next[0] = u
    obs = OBS_FLIGHT.pack({"pitch_rate_error": err[0], "yaw_rate_error": err[1], "pitch_rate_reference": ref[0],
                           "controller_on": 1.0 if on else 0.0})[None].astype(np.float32)
    lw.act([0], obs, {})
    return lw.gimbal[0].copy()


def run(lw, u, err, on=True, ref=(0.0, 0.0)):
    """Steps of the law over rows of ``u`` and ``err`` (n, 2); returns the gains (n, 2)."""
    ks = []
    for ui, ei in zip(u, err):
        step(lw, ui, ei, on, ref)
        ks.append(lw.gains([0])[0])
    return np.array(ks)


def test_one_step_of_the_law_by_hand():
    c = consts(AACParams(error_gain=3000.0, damper_gain=2.0e4, leak_rate=0.5, k_min=0.5, k_max=2.0), DT, LIMIT)
    # a e^2 = 3000 * 0.01^2 = 0.3, no damper: r = c = 0.5, k_inf = (0.3 + 0.5) / 0.5 = 1.6
    k = gain_step_k(c, 1.0, 1e-4, 0.0)
    assert k == pytest.approx(1.6 - 0.6 * math.exp(-0.5 * DT), rel=1e-12)       # 1.0059700...
    assert k == pytest.approx(1.0 + 0.3 * DT, rel=1e-4)                        # forward Euler, to first order
    # damper: b y = 2e4 * 1e-4 = 2, r = 2.5, k_inf = (0 + 2 * 0.5 + 0.5) / 2.5 = 0.6
    assert gain_step_k(c, 1.0, 0.0, 1e-4) == pytest.approx(0.6 + 0.4 * math.exp(-2.5 * DT), rel=1e-12)  # 0.98039...
    # no leakage, no damper: k grows by a e^2 dt exactly
    c0 = consts(AACParams(error_gain=3000.0, leak_rate=0.0), DT, LIMIT)
    assert gain_step_k(c0, 1.0, 1e-4, 0.0) == pytest.approx(1.0 + 0.3 * DT)
    # the exact step never overshoots the lower bound, however stiff the damper
    assert gain_step_k(consts(AACParams(damper_gain=1e12), DT, LIMIT), 1.0, 0.0, 1.0) >= 0.5


def test_filters_by_hand():
    w = 2 * math.pi
    kk = w / math.tan(w * DT / 2)
    pole, gain = first_order("low", 1.0, DT)
    assert (pole, gain) == (pytest.approx((kk - w) / (kk + w)), pytest.approx(w / (kk + w)))   # first sample: w/(k+w)
    assert 2.0 * gain / (1.0 - pole) == pytest.approx(1.0)                    # unit DC gain
    assert first_order("high", 1.0, DT)[1] == pytest.approx(kk / (kk + w))
    with pytest.raises(ValueError):
        first_order("band", 1.0, DT)
    # in the law: a constant command is no high-frequency content (the high-pass restarts at the engagement)
    lw = law()
    run(lw, np.full((50, 2), 0.03), np.zeros((50, 2)))
    assert np.all(lw.damper([0]) == 0.0)


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
    assert lw.errors([0])[0, 0] == pytest.approx(-0.01, rel=1e-3)   # dead-zoned, filtered; e = model - gyro = -rate error
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
    out = step(big, np.array([1.0, -1.0]), np.zeros(2))
    assert np.all(np.abs(out) <= LIMIT)                                # the command stays within the gimbal limit


def test_controller_off_freezes_and_engagement_resets():
    lw = law()
    run(lw, np.zeros((100, 2)), np.full((100, 2), 0.05))
    k_on = lw.gains([0])[0]
    assert k_on[0] > 1.0
    out = step(lw, np.array([0.05, 0.05]), np.full(2, 0.5), on=False)
    ks_off = run(lw, np.zeros((50, 2)), np.full((50, 2), 0.5), on=False)
    assert np.all(out == 0.0) and np.all(ks_off == k_on)               # frozen while off, the gimbal at 0
    step(lw, np.zeros(2), np.zeros(2))
    k = lw.gains([0])[0]
    assert np.all(k < k_on) and k[0] == pytest.approx(1.0, abs=1e-12)  # engaged again: from 1
    hold = law(reset_on_engage=False)
    run(hold, np.zeros((100, 2)), np.full((100, 2), 0.05))
    k_hold = hold.gains([0])[0]
    run(hold, np.zeros((10, 2)), np.zeros((10, 2)), on=False)
    step(hold, np.zeros(2), np.zeros(2))
    assert hold.gains([0])[0, 0] == pytest.approx(k_hold[0], rel=0.02)  # held, then one step of leakage


class _Pattern(_Commands):
    """A base law commanding a 9 Hz pitch pattern and a constant yaw [rad], each row on its own clock."""

    def _rows(self, n: int) -> None:
        super()._rows(n)
        self.k = np.zeros(n, dtype=np.int64)

    def reset(self, rows) -> None:
        super().reset(rows)
        self.k[rows] = 0

    def act(self, rows, observations, info):
        self.next[rows, 0] = 0.01 * np.sin(2 * math.pi * 9.0 * self.k[rows] * DT)
        self.next[rows, 1] = 0.002
        self.k[rows] += 1
        return super().act(rows, observations, info)


def test_policy_wrapper_is_deterministic_and_respects_controller_on():
    env = _fake_env()
    pol = AdaptiveAugmentingPolicy(_Pattern(), env=env, record=True)
    assert isinstance(pol, Policy) and pol.name == "aac(stub)"
    rng = np.random.default_rng(3)
    obs = np.zeros((300, OBS_FLIGHT.size), np.float32)
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
    # the same rows in a batch of three, each its own flight: row 1 flies the one-row policy's actions to the bit
    batch = pol.batch(3)
    batch.reset(np.arange(3))
    many = [batch.act(np.arange(3), np.stack([rng.normal(size=o.shape).astype(np.float32) * o[i_on], o, o]), {})[1]
            for o in obs]
    assert np.array_equal(np.array(many), a1)


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
        consts(AACParams(damper_hp_hz=30.0), DT, LIMIT)
    with pytest.raises(ConfigError, match=r"aac base = 'list'"):
        AdaptiveAugmentingPolicy([], env=_fake_env())
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
    plain = consts(AACParams(damper_gain=2.0e4), DT, LIMIT)
    zoned = law(damper_gain=2.0e4, damper_deadzone_rad2=dz)
    for y, y_seen in ((1e-3, 0.0), (5e-3, 5e-3 - dz)):
        zoned.reset([0])
        row = zoned.rows[0]
        row[AAC_ROW.slice("k")], row[AAC_ROW.slice("lp_y")] = 1.4, y     # engaged, k_T and y as given
        row[AAC_ROW.index("on")], row[AAC_ROW.index("fresh")] = 1.0, 0.0
        step(zoned, np.zeros(2), np.zeros(2))
        expected = gain_step_k(plain, 1.4, 0.0, y_seen)
        np.testing.assert_allclose(zoned.gains([0])[0], expected, rtol=1e-12)
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

    b = ScaledBase(_Commands(), 2.0)
    b.law.base.next[0] = [0.002, -0.005]
    b.reset()
    np.testing.assert_allclose(b.act(np.zeros(3), {}), [2 * 0.002 / LIMIT, -2 * 0.005 / LIMIT], rtol=1e-6)
    np.testing.assert_allclose(b.last_gimbal, [0.004, -0.01])
    assert (b.dt, b.limit, b.name) == (DT, LIMIT, "stub*2")


def test_around_the_pid_law_one_compiled_call_gives_the_two_calls_numbers():
    """Around a :class:`PIDLaw` the adaptive law and its base run in one compiled call
    (``aac_pid_act_k``); around any other base law (here a subclass of it) the base acts first and
    ``aac_act_k`` follows. Both give the same actions and states to the bit, three rows of a non-rigid flight
    with dispersions and turbulence, the rows reset at different steps."""
    from lvgym.baselines.pid import PIDLaw

    class _OtherBase(PIDLaw):
        pass

    venv = gym.make_vec("lvgym/SmileAscent-v1", num_envs=3, vectorization_mode="vector_entry_point",
                        model="nonrigid", wind="turbulence", randomize=True, mission_time_s=8.0)
    single = gym.make("lvgym/SmileAscent-v1", model="nonrigid", mission_time_s=8.0)
    fused = flex_aac(single).law.batch(3)
    base = fused.base
    other = AACLaw(_OtherBase(single, schedule=base.schedule, name="other"), env=single,
                   params=fused.params).batch(3)
    assert type(fused.base) is PIDLaw and type(other.base) is _OtherBase
    rows = np.arange(3)
    obs, info = venv.reset(seed=11)
    fused.reset(rows), other.reset(rows)
    for k in range(300):
        a, b = fused.act(rows, obs, info), other.act(rows, obs, info)
        np.testing.assert_array_equal(a, b)
        if k in (120, 200):
            fused.reset([k % 3]), other.reset([k % 3])
        obs, _, term, trunc, info = venv.step(a)
        assert not np.any(term | trunc)
    np.testing.assert_array_equal(fused.rows, other.rows)
    np.testing.assert_array_equal(fused.base.st.pid, other.base.st.pid)
    assert np.abs(fused.gains(rows) - 1.0).max() > 0.0              # the adaptive gain moved
