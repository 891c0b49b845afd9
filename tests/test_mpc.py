"""The constrained MPC (lvgym.baselines.mpc, mpcqp) and lqg's anti-windup (lqg-aw): the QP against hand numbers
and the finite-horizon Riccati recursion, lqg-aw against lqg, and both registered policies in flight."""

import math

import numpy as np
import pytest

import lvgym
import lvgym.baselines  # noqa: F401  (registers the policies)
from lvgym.baselines.lqg import LQGPlane, LQGSchedule, smile_lqg
from lvgym.baselines.lqgkernel import AntiWindup
from lvgym.baselines.mpc import row_qp, smile_mpc
from lvgym.baselines.mpcqp import CondensedQP, QPOptions, condense
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy, play_episode
from lvgym.errors import ConfigError

pytest.importorskip("osqp")

LIMIT = math.radians(5.0)                     # the gimbal limit [rad]
RATE_STEP = math.radians(30.0) * 0.02         # 30 deg/s over a 20 ms period [rad]


def _hold_qp(N: int = 8) -> CondensedQP:
    """A hand case: the state is (the last command, a reference r) and the cost is sum (u_k - r)^2 (plus
    1e-9 u_k^2): the unconstrained plan holds r from the first period; under the limits the best plan is the
    ramp from the last command at the rate limit, cut at r or at the angle limit."""
    Aa = np.array([[0.0, 0.0], [0.0, 1.0]])
    Ba = np.array([[1.0], [0.0]])
    Q = np.array([[1.0, -1.0], [-1.0, 1.0]])
    H, F, _, _ = condense(Aa, Ba, Q, np.array([[1e-9]]), Q, N)
    return CondensedQP(H, F, LIMIT, RATE_STEP, QPOptions(horizon=N, rate="command", eps=1e-9))


def test_a_step_beyond_the_rate_limit_is_spread_over_periods():
    qp = _hold_qp()
    r = math.radians(2.8)                     # 4.67 periods of the 0.6 deg rate step
    U = qp.solve(np.array([0.0, r]), 0.0)
    ramp = np.minimum(RATE_STEP * np.arange(1, 9), r)  # 0.6, 1.2, 1.8, 2.4, 2.8, 2.8 ... deg
    np.testing.assert_allclose(np.degrees(U), np.degrees(ramp), atol=1e-5)
    assert qp.solves == 1 and qp.fallbacks == 0
    assert abs(U[0]) <= RATE_STEP and np.all(np.abs(np.diff(U)) <= RATE_STEP * (1 + 1e-9))
    # beyond the angle limit: the ramp stops at 5 deg; from a last command of 4.9 deg, one step to 5 deg
    U = qp.solve(np.array([0.0, math.radians(8.0)]), 0.0)
    np.testing.assert_allclose(np.degrees(U), np.minimum(0.6 * np.arange(1, 9), 5.0), atol=1e-5)
    U = qp.solve(np.array([0.0, math.radians(8.0)]), math.radians(4.9))
    np.testing.assert_allclose(np.degrees(U), np.full(8, 5.0), atol=1e-5)


def test_within_the_limits_the_qp_is_the_unconstrained_plan_without_osqp():
    qp = _hold_qp()
    r = math.radians(0.5)                     # less than one rate step from the last command (0)
    U = qp.solve(np.array([0.0, r]), 0.0)
    np.testing.assert_allclose(U, np.full(8, r / (1 + 1e-9)), rtol=1e-12)
    assert qp.solves == 0


def _riccati_first_gain(Aa, Ba, Q, R, P, N):
    """The finite-horizon LQ gain of the first period: the Riccati recursion backwards from P_N = P."""
    for _ in range(N - 1):
        K = np.linalg.solve(R + Ba.T @ P @ Ba, Ba.T @ P @ Aa)
        P = Q + Aa.T @ P @ (Aa - Ba @ K)
    return np.linalg.solve(R + Ba.T @ P @ Ba, Ba.T @ P @ Aa)


@pytest.mark.parametrize("terminal", ["riccati", "stage"])
def test_first_move_is_the_finite_horizon_lq_solution_on_a_shipped_row(terminal):
    """On lqg's max-q row (28.8 s, pitch): the condensed QP's unconstrained first move is the finite-horizon
    LQ gain of the backward Riccati recursion, with the stage weight Q as terminal weight and with the
    infinite-horizon P; with P it is the row's own LQR gain (K_x, K_i), i.e. lqg's command."""
    from lvgym.baselines.design.lqg_row import LQGWeights, regulator_problem
    from lvgym.baselines.mpcqp import terminal_weight

    sched = LQGSchedule.load("smile_lqg")
    row = sched.rows["pitch"][sched.index(28.8)]
    Aa, Ba, Q, R, _ = regulator_problem(row.A, row.B, row.C, LQGWeights(*row.weights), row.dt, row.labels)
    P = terminal_weight(Aa, Ba, Q, R)[0] if terminal == "riccati" else Q
    N = 15
    H, F, _, _ = condense(Aa, Ba, Q, R, P, N)
    gain = -np.linalg.solve(H, F)[0]
    ref = -_riccati_first_gain(Aa, Ba, Q, R, P, N)[0]
    np.testing.assert_allclose(gain, ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max())
    if terminal == "riccati":
        lqr = -np.append(row.Kx[0], row.Ki)
        np.testing.assert_allclose(gain, lqr, rtol=1e-5, atol=1e-7 * np.abs(lqr).max())
        qp = row_qp(row, LIMIT, RATE_STEP, QPOptions(horizon=N, rate="command"))
        z0 = 1e-4 * np.random.default_rng(0).standard_normal(Aa.shape[0])     # small: no limit active
        U = qp.solve(z0, float(lqr @ z0))
        assert U[0] == pytest.approx(float(lqr @ z0), rel=1e-5) and qp.solves == 0


def test_servo_rate_form_holds_the_predicted_servo_rate():
    """The default form on the max-q row: from a state that asks for a fast move (a large rate error in the
    filter's estimate), the plan's predicted servo rate stays within 30 deg/s at every period while the
    unconstrained plan's exceeds it, and the commands within 5 deg."""
    sched = LQGSchedule.load("smile_lqg")
    row = sched.rows["pitch"][sched.index(28.8)]
    qp = row_qp(row, LIMIT, RATE_STEP, QPOptions(horizon=15, eps=1e-8))
    z0 = np.zeros(row.A.shape[0] + 1)
    z0[row.labels.index("omega_y")] = math.radians(15.0)          # 15 deg/s body rate
    free = qp.Pr @ z0 + qp.Gr @ (qp.gain @ z0)
    assert np.max(np.abs(free)) > math.radians(30.0)
    U = qp.solve(z0, 0.0)
    rate = qp.Pr @ z0 + qp.Gr @ U
    assert qp.solves == 1 and qp.fallbacks == 0
    assert np.max(np.abs(rate)) <= math.radians(30.0) * (1 + 1e-4) and np.max(np.abs(U)) <= LIMIT * (1 + 1e-9)
    assert np.max(np.abs(rate)) >= math.radians(30.0) * (1 - 1e-3)                    # the limit binds


def test_bad_options_name_the_key():
    with pytest.raises(ConfigError, match="mpc.horizon"):
        QPOptions(horizon=0)
    with pytest.raises(ConfigError, match="mpc.rate.*'servo', 'command'"):
        QPOptions(rate="gimbal")


def test_lqg_aw_rate_limit_and_back_calculation_by_hand():
    """One period of lqg-aw's law from rest with a large gyro sample: the command is held to one rate step, and
    the integral is back-calculated, xi_1 = -dt y + g (v - u) / K_i (v the unclipped command)."""
    sched = LQGSchedule.load("smile_lqg")
    rows = sched.rows["pitch"]
    row = rows[sched.index(28.8)]
    g = 0.1
    law = LQGPlane(rows, sched, LIMIT, aw=AntiWindup(True, RATE_STEP, g))
    y = 0.05                                  # rad/s
    u = law.update([y], [28.8], [True])[0]
    v = float(-row.Kx[0] @ (row.M[:, 0] * y))
    assert abs(v) > RATE_STEP and u == pytest.approx(math.copysign(RATE_STEP, v), rel=1e-12)
    assert law.state.xi[0] == pytest.approx(-row.dt * y + g * (v - u) / row.Ki, rel=1e-12)
    u2 = law.update([y], [28.82], [True])[0]
    assert abs(u2 - u) <= RATE_STEP * (1 + 1e-12)


def _fly(policy, env, seed=0):
    obs, info = env.reset(seed=seed)
    policy.reset()
    acts = []
    while True:
        a = policy.act(obs, info)
        acts.append(a)
        obs, _, term, trunc, info = env.step(a)
        if term or trunc:
            return np.array(acts)


#: lqg's first command at the engagement (2 s) is 0.76 deg on seed 0, more than the 0.6 deg a 30 deg/s servo
#: moves in a period: where nothing is to saturate, the flights below give the servo 100 deg/s (2 deg a period)
FAST_SERVO = {"gimbal_rate_limit_degps": 100.0}


def test_lqg_aw_is_lqg_bit_for_bit_when_nothing_saturates():
    env = lvgym.make_env("smile-v1", "nonrigid", mission_time_s=6.0, **FAST_SERVO)
    a, b = _fly(smile_lqg(env), env), _fly(smile_lqg(env, name="lqg-aw", back_gain=0.1), env)
    step = math.radians(100.0) * 0.02 / env.unwrapped.gimbal_limit
    assert np.max(np.abs(np.diff(a, axis=0))) < step and np.max(np.abs(a)) < 1.0   # nothing binds
    assert np.max(np.abs(a)) > 0.05                             # the controller did command something
    assert np.array_equal(a, b)


def test_lqg_aw_holds_lqg_s_engagement_jump_to_the_rate_limit():
    """At the 30 deg/s of smile-v1, lqg's first command (0.76 deg) is more than a period's rate step: lqg-aw
    sends one rate step (0.6 deg) and differs from lqg from there on."""
    env = lvgym.make_env("smile-v1", "nonrigid", mission_time_s=2.2)
    a, b = _fly(smile_lqg(env), env), _fly(smile_lqg(env, name="lqg-aw", back_gain=0.1), env)
    k = int(np.argmax(np.any(a != 0.0, axis=1)))               # the engagement
    deg = math.degrees(env.unwrapped.gimbal_limit)
    assert np.max(np.abs(a[k])) * deg == pytest.approx(0.761, abs=1e-3)
    assert np.max(np.abs(b[k])) * deg == pytest.approx(0.6, rel=1e-6)
    np.testing.assert_array_equal(a[:k], b[:k])


def test_mpc_flies_lqg_while_no_limit_is_active():
    env = lvgym.make_env("smile-v1", "nonrigid", mission_time_s=4.0, **FAST_SERVO)
    mpc = smile_mpc(env)
    a, b = _fly(smile_lqg(env), env), _fly(mpc, env)
    assert mpc.qp_counts["solves"] == 0
    np.testing.assert_allclose(b, a, atol=1e-5)
    assert np.max(np.abs(a)) > 0.05                             # the controller did command something


@pytest.mark.parametrize("name", ["mpc", "lqg-aw"])
def test_registered_policies_fly_a_short_mission(name):
    env = lvgym.make_env("smile-v1-maxq-gust", "nonrigid", mission_time_s=3.0)
    policy = build_policy(POLICIES[name], env)
    rec = play_episode(policy, env, 0)
    assert policy.name == name and not rec["failed"] and math.isfinite(rec["score"]) and rec["score"] > 0.0
