"""``eso`` (baselines/eso.py, esokernel.py, design/esodesign.py): the observer's convergence against the triple
pole's closed form, the law against hand numbers at a frozen state, the compiled law against the linear
compensator of the design, that it reads the observation only, and a short flight."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pytest

import lvgym
import lvgym.baselines  # noqa: F401  (registers eso)
from lvgym.baselines.eso import observer_gain, row_gains, servo_model, smile_eso
from lvgym.baselines.esokernel import ESOCols, ESOTables, eso_act_k, new_state

DT = 0.02


def test_observer_poles_and_the_design_tools_gain():
    from lvgym.baselines.design import esodesign as ed

    for wo in (2.0, 6.0, 20.0):
        L = observer_gain(wo, DT)
        phi, _ = ed.eso_model(DT)
        ev = np.linalg.eigvals((np.eye(3) - np.outer(L, [1, 0, 0])) @ phi)
        assert np.allclose(ev, math.exp(-wo * DT), atol=2e-4)          # a triple root: the eigenvalues to ~eps^(1/3)
        assert np.allclose(L, ed.observer_gain(wo, DT), rtol=1e-12)


def test_constant_disturbance_estimate_converges_at_the_triple_pole():
    """The plant is the observer's own (theta_ddot = f + b0 delta, f a constant 0.5 rad/s^2 from t = 0, the plant
    and the observer at rest). Fine sampling (dt = 1 ms) approaches the continuous observer, whose disturbance
    error is f (1 + wo t + (wo t)^2 / 2) exp(-wo t): at wo = 10 rad/s, t = 0.5 s, 0.5 * 18.5 * exp(-5) = 0.06233."""
    dt, wo, f, b0 = 1e-3, 10.0, 0.5, 15.0
    L = observer_gain(wo, dt)
    phi = np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    gam = np.array([0.5 * dt * dt, dt, 0.0])
    x, xh = np.zeros(3), np.zeros(3)               # plant (theta, omega, f_state) and the estimate
    rng = np.random.default_rng(0)
    for k in range(500):
        delta = 0.01 * rng.standard_normal()       # a known input changes nothing in the error
        x = phi @ x + gam * (f + b0 * delta)
        xb = phi @ xh + gam * b0 * delta
        xh = xb + L * (x[0] - xb[0])
    err = f - xh[2]
    hand = 0.5 * (1 + 5 + 12.5) * math.exp(-5.0)
    assert hand == pytest.approx(0.06233, abs=1e-5)
    assert err == pytest.approx(hand, rel=0.02)
    # twice the bandwidth: the error at the same time falls to 0.5 * (1 + 10 + 50) exp(-10) = 1.38e-3
    L2 = observer_gain(2 * wo, dt)
    x, xh = np.zeros(3), np.zeros(3)
    for k in range(500):
        x = phi @ x + gam * f
        xb = phi @ xh
        xh = xb + L2 * (x[0] - xb[0])
    assert f - xh[2] == pytest.approx(0.5 * 61 * math.exp(-10.0), rel=0.03)


def _tables(wc=1.2, wo=6.0, b0=16.0, limit=0.1, **row):
    As, Bs = servo_model(15.0, 0.7, DT)
    kp, kd, F, H, G, fb, fa = row_gains([{"controller_bandwidth_radps": wc, "observer_bandwidth_radps": wo, **row}], DT)
    return ESOTables(np.array([10.0]), kp, kd, F, H, G, fb, fa, np.array([0.0, 100.0]), np.array([b0, b0]), As, Bs, DT,
                     100.0, limit)


COLS = ESOCols(np.array([0, 1]), np.array([2, 3]), np.array([4, 5]), 6, 7)


def test_law_at_a_frozen_state_against_hand_numbers():
    """Engaged a step before with the estimate (0.02 rad, -0.01 rad/s, 0.3 rad/s^2) and the servo model at rest at
    zero; the new sample equals the prediction (no correction), so the estimate is the prediction:
    theta = 0.02 - 0.01 dt + 0.3 dt^2/2 = 0.01986, omega = -0.01 + 0.3 dt = -0.004, f = 0.3, and with
    wc = 1.2, b0 = 16: u = -(0.0285984 - 0.0096 + 0.3) / 16 = -0.0199374 rad."""
    tb = _tables()
    st = new_state(1)
    st.x[0, :] = (0.02, -0.01, 0.3)
    st.was_on[0] = True
    obs = np.zeros((1, 8))
    obs[0, :2] = 0.02 - 0.01 * DT + 0.3 * DT * DT / 2
    obs[0, 6], obs[0, 7] = 0.1, 1.0                  # t = 10 s, on
    out = np.empty((1, 2), np.float32)
    eso_act_k(tb, COLS, st, np.zeros(1, np.int64), obs, out)
    assert st.x[0, 0] == pytest.approx([0.01986, -0.004, 0.3], abs=1e-12)
    assert st.gimbal[0, 0] == pytest.approx(-(1.44 * 0.01986 - 2.4 * 0.004 + 0.3) / 16, rel=1e-12)
    assert st.gimbal[0, 0] == pytest.approx(-0.0199374, rel=1e-9)
    assert out[0, 0] == np.float32(st.gimbal[0, 0] / 0.1)


ROWS = [{},                                                                    # Gao's plain ESO
        {"observer": "attitude", "controller_damping": 0.3, "stiffness_per_s2": 27.04, "damping_per_s": 1.03},
        {"observer": "rate", "controller_damping": 1.4, "stiffness_per_s2": -2.69, "damping_per_s": 0.02,
         "notch": {"frequency_radps": 9.0, "damping": 0.3, "depth": 0.3}}]


@pytest.mark.parametrize("row", ROWS, ids=["plain", "model-assisted", "rate-fed-notch"])
def test_compiled_law_equals_the_design_compensator(row):
    """A random gyro sequence, its trapezoidal attitude fed to the kernel, the commands against
    :func:`esodesign.compensator` (the servo model in the observer's input, the row's notch on the gyro) on the
    same sequence, unclipped: the plain ESO, the model-assisted one (max q's rigid pair) and the rate-fed one
    with the slosh notch (the upper stage's)."""
    import control

    from lvgym.baselines.design import esodesign as ed

    wc, wo, b0 = 1.2, 6.0, 16.0
    filt = ed.RowFilter(row["notch"], DT) if "notch" in row else None
    comp = ed.compensator(b0, wc, wo, DT, filt, ed.input_model(DT, 1, (15.0, 0.7)), **ed.row_design(row))
    rng = np.random.default_rng(1)
    y = np.concatenate([[0.0], 0.01 * rng.standard_normal(199)])
    theta = np.concatenate([[0.0], np.cumsum(0.5 * DT * (y[1:] + y[:-1]))])
    ref = control.forced_response(comp, np.arange(y.size) * DT, y).outputs.ravel()
    tb, st = _tables(wc, wo, b0, limit=10.0, **row), new_state(1)
    got = []
    for k in range(y.size):
        obs = np.zeros((1, 8))
        obs[0, 0] = obs[0, 1] = theta[k]
        obs[0, 2] = obs[0, 3] = y[k] if k else 0.0
        obs[0, 6], obs[0, 7] = 0.1, 1.0
        out = np.empty((1, 2), np.float32)
        eso_act_k(tb, COLS, st, np.zeros(1, np.int64), obs, out)
        got.append(st.gimbal[0, 0])
    assert np.max(np.abs(ref)) > 1e-3
    np.testing.assert_allclose(got, ref, rtol=1e-7, atol=1e-12)


def test_observer_matrices_hand_numbers():
    """The rate-fed observer passes the attitude through (x[0] = theta_k, H[0] = (1, 0), F[0] = 0); its (rate,
    disturbance) error map has the double pole exp(-wo dt); the model-assisted attitude ESO's error map the triple
    one; with no stiffness the model is Gao's: Phi = [[1, dt, dt^2/2], [0, 1, dt], [0, 0, 1]], Gam = [dt^2/2, dt, 0]."""
    from lvgym.baselines.eso import eso_model, observer_matrices

    phi, gam = eso_model(DT)
    assert np.allclose(phi, [[1, DT, DT * DT / 2], [0, 1, DT], [0, 0, 1]], atol=1e-15)
    assert np.allclose(gam, [DT * DT / 2, DT, 0.0], atol=1e-15)
    F, H, G = observer_matrices("rate", 20.0, DT, -2.69, 0.02)
    assert np.allclose(F[0], 0.0) and np.allclose(H[0], [1.0, 0.0]) and G[0] == 0.0
    assert np.allclose(np.linalg.eigvals(F[1:, 1:]), math.exp(-20.0 * DT), atol=1e-6)
    F, H, G = observer_matrices("attitude", 5.0, DT, 27.04, 1.03)
    assert np.allclose(np.linalg.eigvals(F), math.exp(-5.0 * DT), atol=2e-4)
    with pytest.raises(lvgym.errors.ConfigError, match="observer"):
        observer_matrices("accelerometer", 5.0, DT)


class _NoInfo(Mapping):
    def __getitem__(self, key):
        raise AssertionError(f"eso read info[{key!r}]")

    def __iter__(self):
        raise AssertionError("eso iterated info")

    def __len__(self):
        raise AssertionError("eso read info")


def test_reads_the_observation_only_and_flies():
    env = lvgym.make_vec_env("smile-v2", model="nonrigid", num_envs=1, mission_time_s=8.0)
    law = smile_eso(env).law
    other = smile_eso(env).law
    obs, info = env.reset(seed=[0])
    law.reset(np.zeros(1, np.int64))
    other.reset(np.zeros(1, np.int64))
    rows = np.zeros(1, np.int64)
    acted = 0
    for _ in range(int(8.0 / DT)):
        a = law.act(rows, obs, info)
        b = other.act(rows, obs, _NoInfo())
        assert np.array_equal(a, b)
        acted += bool(np.any(a != 0.0))
        obs, _, term, trunc, info = env.step(a)
        assert np.all(np.isfinite(obs)) and not term[0]
        if trunc[0]:
            break
    assert acted > 100


def test_refuses_another_vehicle_or_observation():
    env = lvgym.make_vec_env("stratos-tvc-v2", model="rigid", num_envs=1)
    with pytest.raises(lvgym.errors.ConfigError, match="smile_v1"):
        smile_eso(env)
