"""lqi: lqg-aw's law with the pure integral of the attitude error (lvgym.baselines.lqgkernel's ``source``,
lvgym.baselines.design.lqg_row's ``integral="attitude"``, baselines/schedules/smile_lqi.npz). Against hand numbers
on a two-state plant (the final-value theorem), against the linear compensator on the shipped rows, its batch,
what it reads, and its margins."""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest
import scipy.linalg as sla

import lvgym
import lvgym.baselines  # noqa: F401  (registers lqi)
from lvgym.baselines.design import lqg_row as R
from lvgym.baselines.lqg import LQGLaw, LQGPlane, LQGRow, LQGSchedule
from lvgym.baselines.lqgkernel import AntiWindup
from lvgym.benchmark.margins import MarginOptions, time_domain_margins
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.suites import get_suite
from lvgym.errors import ConfigError

DT = 0.02
#: the two-state plant: attitude theta [rad] and rate q [rad/s], theta'' = M_A theta + M_D u + d
M_A, M_D, D_MOMENT = 1.5, 8.0, 0.12            # 1/s^2, 1/s^2 per rad of gimbal, rad/s^2
LABELS = ("theta_y", "omega_y")


def toy_plant():
    """The plant above held over DT (zero-order hold): A, B (gimbal), Bd (the disturbance), C (the rate)."""
    Ac = np.array([[0.0, 1.0], [M_A, 0.0]])
    Bc = np.array([[0.0, 0.0], [M_D, 1.0]])
    M = sla.expm(np.block([[Ac, Bc], [np.zeros((2, 4))]]) * DT)
    A, Bu = M[:2, :2], M[:2, 2:]
    return A, Bu[:, :1], Bu[:, 1:], np.array([[0.0, 1.0]])


def toy_row(integral, leak_s=1.0):
    """The LQG row of the two-state plant with the integral of ``integral`` (the rate's leaks over ``leak_s``: its
    closed loop's slowest pole is then 18 s, the attitude's 17 s)."""
    A, B, _, C = toy_plant()
    w = R.LQGWeights(q_rate=1.0, q_int=10.0, r_gimbal=1.0, w_gimbal=1e-6, integrator_leak_s=leak_s,
                     q_attitude=10.0 if integral == "attitude" else 0.0)
    Kx, Ki, a = R.regulator(A, B, C, w, DT, LABELS, integral)
    M = R.kalman_gain(A, C, B, w, DT, LABELS)
    return LQGRow(0.0, (0.0, 1e9), A, B, C, Kx, Ki, M, a, DT, LABELS, (), integral)


def fly_toy(row, seconds=300.0):
    """The law of ``row`` (lqg-aw's anti-windup, limits far away) on the plant under the constant disturbance:
    the attitude [rad] and the command [rad] at the end."""
    A, B, Bd, C = toy_plant()
    one = LQGSchedule({p: (row,) for p in ("pitch", "yaw")}, "toy")
    law = LQGPlane(one.rows["pitch"], one, u_limit=10.0, aw=AntiWindup(True, 10.0, 0.1))
    x = np.zeros(2)
    for k in range(int(seconds / DT)):
        u = law.update(C @ x, k * DT, True, e=x[0])[0]
        x = A @ x + B[:, 0] * u + Bd[:, 0] * D_MOMENT
    return x[0], u


def test_hand_offsets_under_a_constant_disturbance_moment():
    """At rest the rate is zero, so the leaky integral and the estimate are zero and the command is zero: the
    aerodynamic moment alone holds the disturbance, theta = -d / M_A = -0.08 rad (the final-value theorem on
    the closed loop gives the same). The pure integral of the attitude is constant only at zero attitude error:
    theta = 0 and the gimbal holds the disturbance, u = -d / M_D = -0.015 rad."""
    leaky, u_leaky = fly_toy(toy_row("rate"))
    pure, u_pure = fly_toy(toy_row("attitude"))
    assert -D_MOMENT / M_A == pytest.approx(-0.08)
    assert leaky == pytest.approx(-0.08, rel=1e-3) and abs(u_leaky) < 1e-5
    assert abs(pure) < 1e-6 and u_pure == pytest.approx(-0.015, rel=1e-4)
    # the final-value theorem on the linear closed loop: theta(inf) = C_theta (I - A_cl)^-1 B_d d
    A, B, Bd, C = toy_plant()
    for row, want in ((toy_row("rate"), -0.08), (toy_row("attitude"), 0.0)):
        d = R.RowDesign(0.0, "pitch", row.A, row.B, row.C, row.Kx, row.Ki, row.M, row.a, DT, R.LQGWeights(),
                        LABELS, row.integral)
        Cl = C if row.integral == "rate" else np.vstack([C, R.attitude_output(LABELS)])
        Acl, _ = R.closed_loop(A, B, Cl, d.compensator())
        assert np.abs(np.linalg.eigvals(Acl)).max() < 1.0
        x_inf = np.linalg.solve(np.eye(Acl.shape[0]) - Acl, np.concatenate([Bd[:, 0], np.zeros(Acl.shape[0] - 2)]))
        assert x_inf[0] * D_MOMENT == pytest.approx(want, abs=1e-9)


def test_the_pure_integral_is_controllable_on_the_attitude_not_on_the_rate():
    """Hautus at z = 1: the system matrix [[A - I, B], [C_i, 0]] is singular for the rate (its zero at z = 1) and
    regular for the attitude, so dlqr has its stabilising solution only with the attitude."""
    A, B, _, C = toy_plant()
    def system(Ci):
        return np.linalg.det(np.block([[A - np.eye(2), B], [Ci, np.zeros((1, 1))]]))
    assert abs(system(C)) < 1e-15
    assert abs(system(R.attitude_output(LABELS))) == pytest.approx(M_D * DT ** 2, rel=1e-3)
    Aa, *_ = R.regulator_problem(A, B, C, R.LQGWeights(q_attitude=1.0), DT, LABELS, "attitude")
    assert Aa[2, 2] == 1.0 and Aa[2, 0] == -DT and Aa[2, 1] == 0.0


def test_errors_name_the_integral():
    with pytest.raises(ConfigError, match="integral"):
        R.check_integral("angle")
    r = toy_row("attitude")
    with pytest.raises(ConfigError, match="integral"):
        LQGRow(0.0, (0.0, 1.0), r.A, r.B, r.C, r.Kx, r.Ki, r.M, r.a, DT, LABELS, (), "angle")


@pytest.fixture(scope="module")
def shipped():
    return LQGSchedule.load("smile_lqi")


def test_shipped_rows_integrate_the_attitude_with_lqg_filters(shipped):
    """Every row integrates the attitude without a leak, on lqg's row's plant (the same states; its matrices to
    1e-3 of their largest entry: the operating points flown again, the upper stage's behind gs-pid's flight) and
    with lqg's row's estimator and mode weights (only the regulator's were searched again)."""
    lqg = LQGSchedule.load("smile_lqg")
    for plane in ("pitch", "yaw"):
        for r, g in zip(shipped.rows[plane], lqg.rows[plane]):
            assert r.integral == "attitude" and r.a == 1.0 and r.Ki != 0.0 and g.integral == "rate" and g.a < 1.0
            assert r.time_s == pytest.approx(g.time_s, abs=1e-9) and r.labels == g.labels
            np.testing.assert_allclose(r.A, g.A, rtol=0, atol=1e-3 * np.abs(g.A).max())
            ours, theirs = R.LQGWeights(*r.weights), R.LQGWeights(*g.weights)
            assert (ours.w_gimbal, ours.q_modes, ours.w_modes) == (theirs.w_gimbal, theirs.q_modes, theirs.w_modes)
            assert ours.q_attitude in (10.0, 100.0) and ours.q_int in (1.0, 10.0, 100.0)


def test_law_equals_the_two_input_compensator(shipped):
    """The law, unclipped, on known gyro and attitude sequences gives the commands of lqg_row.compensator's
    two-input system (python-control), on two rows."""
    rng = np.random.default_rng(5)
    for i in (2, 7):
        r = shipped.rows["pitch"][i]
        one = LQGSchedule({p: (r,) for p in ("pitch", "yaw")}, "one row")
        law = LQGPlane(one.rows["pitch"], one, u_limit=1e6)
        y, e = 1e-3 * rng.standard_normal(200), 1e-2 * rng.standard_normal(200)
        u_law = np.array([law.update(a, r.time_s, True, e=b)[0] for a, b in zip(y, e)])
        d = R.RowDesign(r.time_s, "pitch", r.A, r.B, r.C, r.Kx, r.Ki, r.M, r.a, r.dt, R.LQGWeights(), r.labels,
                        r.integral)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            u_lin = np.ravel(control.forced_response(d.compensator(), U=np.vstack([y, e])).outputs)
        np.testing.assert_allclose(u_law, u_lin, rtol=1e-9, atol=1e-12 * np.abs(u_lin).max())


def test_hold_integrates_the_attitude_from_the_engagement(shipped):
    """lqi-hold (``attitude_from="engagement"``) on attitude samples e_k flies as lqi on e_k - e_0, e_0 the sample
    at the engagement, to the bit, through an engagement, a switch-off and a re-engagement (a new e_0); and on
    the toy plant under a constant moment, started 0.05 rad off, it ends at that attitude where lqi ends at 0."""
    rng = np.random.default_rng(7)
    r = shipped.rows["pitch"][3]
    one = LQGSchedule({p: (r,) for p in ("pitch", "yaw")}, "one row")
    hold = LQGPlane(one.rows["pitch"], one, u_limit=0.2, aw=AntiWindup(True, 0.005, 0.1), attitude_from="engagement")
    plain = LQGPlane(one.rows["pitch"], one, u_limit=0.2, aw=AntiWindup(True, 0.005, 0.1))
    y, e = 1e-3 * rng.standard_normal(300), 0.03 + 1e-2 * rng.standard_normal(300)
    on = np.ones(300, bool)
    on[150:160] = False
    e0 = np.where(np.arange(300) < 150, e[0], e[160])
    u_hold = np.array([hold.update(a, r.time_s, o, e=b)[0] for a, b, o in zip(y, e, on)])
    u_plain = np.array([plain.update(a, r.time_s, o, e=b - c)[0] for a, b, c, o in zip(y, e, e0, on)])
    np.testing.assert_array_equal(u_hold, u_plain)
    assert np.abs(u_hold).max() > 1e-3 and not u_hold[150:160].any()
    with pytest.raises(ConfigError, match="attitude_from"):
        LQGLaw(env=lvgym.make_env("smile-v2", "rigid"), schedule="smile_lqi", attitude_from="start")
    A, B, Bd, C = toy_plant()
    row = toy_row("attitude")
    toy = LQGSchedule({p: (row,) for p in ("pitch", "yaw")}, "toy")
    ends = {}
    for start in ("zero", "engagement"):
        law = LQGPlane(toy.rows["pitch"], toy, u_limit=10.0, aw=AntiWindup(True, 10.0, 0.1), attitude_from=start)
        x = np.array([0.05, 0.0])
        for k in range(int(300.0 / DT)):
            u = law.update(C @ x, k * DT, True, e=x[0])[0]
            x = A @ x + B[:, 0] * u + Bd[:, 0] * D_MOMENT
        ends[start] = x[0]
    assert abs(ends["zero"]) < 1e-6 and abs(ends["engagement"] - 0.05) < 1e-6


class NoInfo(dict):
    def __getitem__(self, key):
        raise AssertionError(f"lqi read info[{key!r}]")

    def __contains__(self, key):
        raise AssertionError(f"lqi asked for info[{key!r}]")

    def get(self, key, default=None):
        raise AssertionError(f"lqi read info[{key!r}]")


def test_reads_only_the_observation_and_its_attitude_is_the_integral_of_its_rate():
    """A flight through the switch-on: lqi acts the same with an info that raises on any access as with the
    env's; and the observation's attitude error moves by dt times the mean of the last two rate errors (the
    strapdown's step), the sign the design's attitude output assumes (theta' = the gyro's rate)."""
    env = lvgym.make_vec_env("smile-v2-faults", model="nonrigid", num_envs=2, mission_time_s=4.0)
    lay = env.unwrapped.observation_layout
    a, b = (LQGLaw(env=env, schedule="smile_lqi", name="lqi", back_gain=0.1, clock="observation", n=2)
            for _ in range(2))
    obs, info = env.reset(seed=[1, 2])
    rows = np.arange(2)
    a.reset(rows)
    b.reset(rows)
    rate, att, on = [], [], []
    for _ in range(190):
        ua, ub = a.act(rows, obs, info), b.act(rows, obs, NoInfo())
        np.testing.assert_array_equal(ua, ub)
        obs, _, _, _, info = env.step(ua)
        rate.append(obs[:, [lay.index("pitch_rate_error"), lay.index("yaw_rate_error")]].astype(float))
        att.append(obs[:, [lay.index("pitch_attitude_error"), lay.index("yaw_attitude_error")]].astype(float))
        on.append(obs[0, lay.index("controller_on")])
    assert np.abs(a.gimbal).max() > 0.0                    # it flew (the controller came on)
    rate, att = np.array(rate)[100:], np.array(att)[100:]
    step = np.diff(att, axis=0) / DT
    mean = 0.5 * (rate[1:] + rate[:-1])
    np.testing.assert_allclose(step, mean, atol=2e-3 * np.abs(mean).max() + 1e-6)


def test_margins_are_computed_and_the_nominal_flies():
    """A short time-domain margin search (validation seed 0, 8 s of flight): finite margins, the nominal
    flight not lost."""
    cond = next(c for c in get_suite("smile-v2").with_options(mission_time_s=8.0).conditions if c.model == "nonrigid")
    opts = MarginOptions(gain_tol_db=2.0, gain_max_db=12.0, gain_min_db=-12.0, delay_max_s=0.16)
    r = time_domain_margins(POLICIES["lqi"], cond, get_suite("smile-v2").seeds("validation", 1), options=opts,
                            executor="serial")
    c = r["conditions"][cond.name]
    assert not c["nominal"][0]["failed"]
    for key in ("gain_up_dB", "gain_down_dB", "delay_ms"):
        m = c[key]["margin"]
        assert m is not None and math.isfinite(m) and m != 0.0, (key, c[key])
