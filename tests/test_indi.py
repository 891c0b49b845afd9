"""indi (lvgym.baselines.indi): the law against hand numbers, its increment through a loss of control effectiveness on
a linear plant, its linear loop and margins at a design row, that it reads only the observation, and its
time-domain margins on a validation seed."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import signal

import gymnasium as gym

import lvgym  # noqa: F401  (registers the envs)
import lvgym.baselines  # noqa: F401  (registers indi)
from lvgym.baselines.indi import INDILaw, INDIRowParams, INDISchedule, smile_indi
from lvgym.baselines.indikernel import INDIFilter, SyncSections
from lvgym.benchmark.registry import POLICIES
from lvgym.envs.layouts import OBS_FLIGHT
from lvgym.errors import ConfigError

DT = 0.02
LIMIT = math.radians(5.0)
MISSION = 70.0


def fake_env():
    """What the law reads of an env: the control period, the mission time, the gimbal limit, the flight layout."""
    task = SimpleNamespace(control_dt_s=DT, mission_time_s=MISSION, observation="flight")
    return SimpleNamespace(unwrapped=SimpleNamespace(task=task, gimbal_limit=LIMIT, observation_layout=OBS_FLIGHT))


def schedule(power=15.0, k_rate=3.0, k_att=2.0, filt=None, sync=SyncSections(), k_accel=0.0):
    filt = filt or INDIFilter(lowpass_radps=20.0)
    return INDISchedule((INDIRowParams(10.0, k_rate, k_att, k_accel, filt),), np.array([[0.0, power], [70.0, power]]),
                        sync, DT, "test")


def obs(t, e=(0.0, 0.0), att=(0.0, 0.0), pos=(0.0, 0.0), ref=0.0, on=1.0, acc=(0.0, 0.0)):
    o = OBS_FLIGHT.zeros()
    v = lambda name: OBS_FLIGHT.index(name)  # noqa: E731
    o[v("pitch_rate_error")], o[v("yaw_rate_error")] = e
    o[v("pitch_attitude_error")], o[v("yaw_attitude_error")] = att
    o[v("gimbal_pitch")], o[v("gimbal_yaw")] = pos[0] / LIMIT, pos[1] / LIMIT
    o[v("accel_z")], o[v("accel_y")] = acc
    o[v("time_fraction")], o[v("controller_on")], o[v("pitch_rate_reference")] = t / MISSION, on, ref
    return o


def test_law_against_hand_numbers():
    """Five steps of the law against the module docstring's equations evaluated here with scipy's lfilter on the
    filter's sections (the filters start in the steady state of the first sample)."""
    filt, sync = INDIFilter(lowpass_radps=20.0, bending_radps=60.0), SyncSections(antialias_radps=125.0)
    law = INDILaw(env=fake_env(), schedule=schedule(power=12.0, k_rate=3.0, k_att=2.0, filt=filt, sync=sync))
    law.reset(np.array([0]))
    rng = np.random.default_rng(1)
    e, att = rng.normal(0, 0.02, 5), rng.normal(0, 0.05, 5)
    pos, ref = rng.normal(0, 0.01, 5), np.linspace(-0.01, -0.012, 5)
    got = [law.act(np.array([0]), obs(10.0 + k * DT, (e[k], 0.0), (att[k], 0.0), (pos[k], 0.0), ref[k])[None], {})[0, 0]
           for k in range(5)]

    def run(sections, x):
        y = np.asarray(x, float)
        for b, a in sections:
            zi = signal.lfiltic(b, a, [y[0] * b.sum() / a.sum()] * 2, [y[0]] * 2)
            y, _ = signal.lfilter(b, a, y, zi=zi)
        return y
    h, hs = filt.discrete(DT), filt.discrete(DT) + sync.discrete(DT)
    rate_f, ref_f, pos_f = run(h, e + ref), run(h, ref), run(hs, pos)
    acc = np.r_[0.0, np.diff(rate_f) / DT]
    ref_dot = np.r_[0.0, np.diff(ref_f) / DT]
    u = pos_f + (3.0 * (-2.0 * att - e) + ref_dot - acc) / 12.0
    want = np.clip(u, -LIMIT, LIMIT) / LIMIT
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6)      # float32 actions
    # the first step by hand: every filter at rest, no acceleration: u = pos + k_q (-k_theta att - e) / G
    assert got[0] == pytest.approx((pos[0] + 3.0 * (-2.0 * att[0] - e[0]) / 12.0) / LIMIT, rel=1e-6)


def test_off_outputs_zero_and_restarts():
    law = INDILaw(env=fake_env(), schedule=schedule())
    law.reset(np.array([0]))
    assert law.act(np.array([0]), obs(1.0, (0.3, 0.2), on=0.0)[None], {}).tolist() == [[0.0, 0.0]]
    a = law.act(np.array([0]), obs(2.0, (0.01, 0.0), pos=(0.002, 0.0))[None], {})[0, 0]
    assert a == pytest.approx((0.002 - 3.0 * 0.01 / 15.0) / LIMIT, rel=1e-6)     # no acceleration at engagement


def test_load_relief_by_hand():
    """The first step with load relief: every filter at rest, ``u = k_q (k_a s g0 f) / G`` with the signs of
    gs-pid-flex (pitch +accel_z, yaw -accel_y: the nose turned into the relative wind)."""
    law = INDILaw(env=fake_env(), schedule=schedule(power=15.0, k_rate=3.0, k_att=2.0, k_accel=0.03))
    law.reset(np.array([0]))
    a = law.act(np.array([0]), obs(20.0, acc=(0.1, 0.1))[None], {})[0]
    g0 = 9.80665
    np.testing.assert_allclose(a, np.array([1.0, -1.0]) * 3.0 * 0.03 * g0 * 0.1 / 15.0 / LIMIT, rtol=1e-6)


def loss_flight(loss_at=4.0, loss=0.5, d=0.4, m_alpha=1.0, steps=600, sub=10):
    """A rigid double integrator with an aerodynamic moment, ``theta_ddot = M_a theta + G_true(t) delta + d``, the
    actuator a first-order servo (40 rad/s), flown by the law with G = 15 1/s^2 from its tables while the true
    effectiveness drops by ``loss`` at ``loss_at`` s. Returns (t, omega, theta, delta) per control step."""
    G = 15.0
    law = INDILaw(env=fake_env(), schedule=schedule(power=G, k_rate=4.0, k_att=2.0,
                                                    filt=INDIFilter(lowpass_radps=30.0), sync=SyncSections()))
    law.reset(np.array([0]))
    th = om = delta = 0.0
    cmd = 0.0
    h = DT / sub
    out = []
    for k in range(steps):
        t = k * DT
        cmd = law.act(np.array([0]), obs(10.0, (om, 0.0), (th, 0.0), (delta, 0.0))[None], {})[0, 0] * LIMIT
        g = G * (1.0 - loss) if t >= loss_at else G
        for _ in range(sub):
            delta += h * 40.0 * (cmd - delta)
            om += h * (m_alpha * th + g * delta + d)
            th += h * om
        out.append((t, om, th, delta))
    return np.array(out)


def test_increment_holds_a_step_loss_of_effectiveness():
    """INDI needs no knowledge of the loss: the increment starts from the measured position, so the trim goes to
    ``-d / G_true`` (twice the nominal's for a 50 % loss) and the attitude back to zero.

    The bound by hand: at the loss the trim ``delta = -d / G`` meets half the effectiveness, a moment
    imbalance ``d / 2`` = 0.2 rad/s^2, which the increment removes within the loop's lag; with a lag of at most
    0.25 s (the filter, the servo and the hold: 1/30 + 1/40 + 0.02 s = 0.08 s, three times that), the rate moves
    by at most 0.2 x 0.25 = 0.05 rad/s."""
    d, G = 0.4, 15.0
    r = loss_flight(d=d)
    t, om, th, delta = r.T
    before = (t > 3.5) & (t < 4.0)
    assert np.allclose(delta[before], -d / G, rtol=1e-3)                 # the nominal trim, before the loss
    after = t >= 4.0
    assert np.abs(om[after]).max() < 0.05                                 # the hand bound above (0.022 measured)
    end = t > 10.0
    assert np.allclose(delta[end], -d / (0.5 * G), rtol=0.01)             # re-converged to the new trim
    assert np.abs(th[end]).max() < 1e-3 and np.abs(om[end]).max() < 1e-3
    nominal = loss_flight(d=d, loss=0.0)
    assert np.abs(nominal[nominal[:, 0] >= 4.0, 1]).max() < 1e-3           # without the loss nothing moves


def test_schedule_checks_and_vehicle():
    with pytest.raises(ConfigError, match="rows"):
        INDISchedule((), np.array([[0.0, 1.0], [1.0, 1.0]]), SyncSections(), DT)
    with pytest.raises(ConfigError, match="control_power"):
        schedule(power=-1.0)
    with pytest.raises(ValueError, match="lowpass_radps"):
        INDIFilter(lowpass_radps=-3.0)
    env = gym.make("lvgym/StratosIII-v1")
    with pytest.raises(ConfigError, match="env vehicle"):
        smile_indi(env)


class Refusing(Mapping):
    """An info mapping that raises on any access."""

    def __getitem__(self, key):
        raise AssertionError(f"indi read info[{key!r}]")

    def __iter__(self):
        raise AssertionError("indi iterated the info")

    def __len__(self):
        raise AssertionError("indi asked the info's length")


def test_reads_only_the_observation():
    """The same actions with the env's info and with an info that refuses every access, on SMILE v2's non-rigid
    vehicle through the controller's switch-on."""
    from lvgym.benchmark.suites import get_suite
    cond = next(c for c in get_suite("smile-v2").with_options(mission_time_s=4.0).conditions if c.model == "nonrigid")
    env = cond.make_env()
    p, q = smile_indi(env), smile_indi(env)
    obs_, info = env.reset(seed=3)
    p.reset()
    q.reset()
    moved = 0
    for _ in range(190):
        a = p.act(obs_, info)
        assert np.array_equal(a, q.act(obs_, Refusing()))
        moved += bool(np.any(a != 0))
        obs_, _, term, trunc, info = env.step(a)
        if term or trunc:
            break
    assert moved > 50


@pytest.fixture(scope="module")
def row_ops():
    from lvgym.baselines.design.linearize import operating_point, reused_flights
    from lvgym.baselines.design.target import privileged_flyer
    fly = privileged_flyer()
    with warnings.catch_warnings(), reused_flights():
        warnings.simplefilter("ignore")
        return {m: operating_point("smile", 28.8, m, "v1", policy=fly) for m in ("rigid", "nonrigid")}


def test_linear_loop_at_a_design_row(row_ops):
    """The shipped row at 28.8 s on the linearised plants: the loop is the one of indiloop's docstring (checked
    against the equivalent controller), and the margins are the ones the schedule recorded."""
    from lvgym.baselines.design import indiloop as IL
    from lvgym.baselines.design.flightloop import mode_frequencies
    s = INDISchedule.load("smile_indi")
    r = next(x for x in s.rows if x.time_s == 28.8)
    G = float(np.interp(28.8, s.power[:, 0], s.power[:, 1]))
    row = IL.INDIRow(G, r.k_rate, r.k_attitude, r.filt, sync=s.sync)
    P_y, P_a = IL.loop_plants(row_ops["nonrigid"])
    L = IL.open_loop(row, P_y, P_a)
    C_eq = IL.equivalent_controller(row, P_a)
    w = np.array([0.5, 3.0, 8.0, 30.0])
    from lvgym.baselines.design.response import frequency_response as fr
    lhs = 1.0 + fr(L, w)                                      # 1 + L = (1 - H S P_a)(1 + C_eq P_y)
    _, HS = IL._parts(row, DT)
    rhs = (1.0 - fr(HS, w) * fr(P_a, w)) * (1.0 + fr(C_eq, w) * fr(P_y, w))
    np.testing.assert_allclose(lhs, rhs, rtol=1e-8)
    import yaml
    with open(s.source) as fh:
        doc = yaml.safe_load(fh)
    rec = next(x for x in doc["rows"] if x["time_s"] == 28.8)["margins"]
    modes = mode_frequencies(row_ops["nonrigid"])
    for model in ("rigid", "nonrigid"):
        m = IL.row_margins(row, row_ops[model], modes=modes if model == "nonrigid" else None, noise=False)
        assert m["closed_loop_stable"] == rec[model]["closed_loop_stable"]
        assert m["gain_margin_db"] == pytest.approx(rec[model]["gain_margin_db"], abs=0.05)
        assert m["phase_margin_deg"] == pytest.approx(rec[model]["phase_margin_deg"], abs=0.1)
    assert m["bending_db"][0] < -6.0                                  # the first bending mode gain-stabilised


def test_time_domain_margins_on_a_validation_seed():
    from lvgym.benchmark.margins import MarginOptions, time_domain_margins
    from lvgym.benchmark.suites import get_suite
    cond = next(c for c in get_suite("smile-v2").with_options(mission_time_s=6.0).conditions if c.model == "rigid")
    r = time_domain_margins(POLICIES["indi"], cond, [0], options=MarginOptions(gain_tol_db=1.0, delay_max_s=0.2),
                            experiments=["gain_up", "delay"], executor="serial")
    c = r["conditions"][cond.name]
    assert not c["nominal"][0]["failed"]
    up, delay = c["gain_up_dB"], c["delay_ms"]
    assert up["margin"] is not None and 0.0 < up["margin"] <= 20.0 and math.isfinite(up["margin"])
    assert delay["margin"] is not None and 0.0 < delay["margin"] <= 200.0
