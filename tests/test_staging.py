"""The next stage's ignition as the flight computer sees it and the moment it measures there from the rigid
body (lvgym.agents.policies.staging), by hand, and the disturbance-observer policy flying that moment for a while
after ignition (lvgym.agents.policies.inversion.Staging): the law by hand on it, its batch against its single env to
the bit, refusals by name."""

from __future__ import annotations

import numpy as np
import pytest

import lvgym
from lvgym.agents.policies.inversion import InversionPolicy, command
from lvgym.agents.policies.staging import GIMBAL, RATES, Ignition, Measured, signal_index
from lvgym.errors import ConfigError


def test_the_steps_since_ignition_count_from_the_controllers_return_after_a_coast():
    """-1 until ``controller_on`` comes back after it fell once the controller had acted (row 0: on at step 2,
    the coast at 4-5, ignition at 6), then 0, 1, ...; a row that never coasts (row 1) stays -1, whichever
    rows a step pushes; a reset starts a row again."""
    on = np.array([[0, 0, 1, 1, 0, 0, 1, 1, 0], [0, 1, 1, 1, 1, 1, 1, 1, 1]], dtype=float)
    lit, got = Ignition(2, on=3), []
    for k in range(on.shape[1]):
        rows = np.array([0]) if k == 7 else np.array([0, 1])      # row 1 sits a step out: nothing moves it
        obs = np.zeros((len(rows), 5))
        obs[:, 3] = on[rows, k]
        got.append(dict(zip(rows.tolist(), lit.push(rows, obs).tolist())))
    assert [g[0] for g in got] == [-1, -1, -1, -1, -1, -1, 0, 1, 2]
    assert [g.get(1) for g in got] == [-1] * 7 + [None, -1]
    lit.reset(np.array([0]))
    assert lit.push(np.array([0]), np.ones((1, 5))).tolist() == [-1]           # acting again, no coast yet


def test_the_measured_moment_by_hand():
    """Gyro rates on a ramp (pitch: its error 0.01 k rad/s plus a reference of 0.002 k; yaw: -0.03 k) and a
    gimbal at 0.1 k: with ``a`` = (0.5, 2) the moment over 3 steps of 0.02 s is ``a`` times the rates' slope
    less the gimbal's mean over the 4 steps; zeros before the first step; a reset forgets."""
    rates, gimbal = [0, 1, 2], [3, 4]
    m = Measured(1, rates, gimbal, dt=0.02)
    row = np.zeros(1, dtype=np.int64)
    np.testing.assert_array_equal(m.moment(row, np.ones((1, 2))), [[0.0, 0.0]])
    for k in range(6):
        m.push(row, np.array([[0.01 * k, -0.03 * k, 0.002 * k, 0.1 * k, 0.1 * k]]))
    slope = np.array([0.012, -0.03]) / 0.02                                    # rad/s^2
    want = np.array([0.5, 2.0]) * slope - 0.1 * np.mean([2, 3, 4, 5])
    np.testing.assert_allclose(m.moment(row, np.array([[0.5, 2.0]])), [want], rtol=1e-12)
    m.reset(row)
    np.testing.assert_array_equal(m.moment(row, np.ones((1, 2))), [[0.0, 0.0]])
    with pytest.raises(ConfigError, match="measured disturbance"):
        Measured(1, rates, gimbal, dt=0.0)


def _flight(env, steps: int, rng: np.random.Generator, rows: int = 1) -> np.ndarray:
    """Observations of ``rows`` flights: noise, the controller on from step 2, a coast at steps 8-11, ignition
    at 12, the gyro rates and gimbal positions on their own."""
    on = signal_index(env, ("controller_on",))[0]
    o = rng.normal(0.0, 0.05, (steps, rows, 14)).astype(np.float32)
    o[:, :, on] = [[1.0 if 2 <= k < 8 or k >= 12 else 0.0] * rows for k in range(steps)]
    return o


@pytest.mark.parametrize("share", [1.0, 0.5])
def test_a_policy_flies_the_measured_moment_for_its_seconds_after_ignition_and_its_batch_is_its_rows(share):
    """``ignition=0.1`` (5 control steps): from the ignition's step for 5 steps the law cancels the measured
    moment (on the observer's ``a``) less the observer's misalignment in place of the observer's aerodynamic
    moment (``ignition_share`` 0.5: half of it and half the observer's), before and after it the observer's;
    the batch of two rows gives each row its single policy's actions to the bit; ``ignition`` and
    ``ignition_share`` out of range and an observation without the signals are refused by name."""
    env = lvgym.make_env("smile-v2-faults", "nonrigid", mission_time_s=3.0)
    terms = np.array([0.2, -0.1, 0.03, -0.02, 0.6, 0.7, 0.1])
    p = InversionPolicy(env, lambda window: terms.copy(), ignition=0.1, ignition_share=share)
    assert p.staging.steps == 5
    hand = Measured(1, signal_index(env, RATES), signal_index(env, GIMBAL), 0.02)
    row = np.zeros(1, dtype=np.int64)
    for k, o in enumerate(_flight(env, 20, np.random.default_rng(0))[:, 0]):
        got = p.act(o, {})
        hand.push(row, o[None])
        t = terms.copy()
        if 12 <= k < 17:
            t[0:2] = share * (hand.moment(row, terms[None, 4:6])[0] - terms[2:4]) + (1.0 - share) * terms[0:2]
        np.testing.assert_allclose(got, command(o[None], t[None], p.index, p.w, p.z)[0], rtol=1e-6, atol=1e-7)

    def observer(window):
        return np.r_[window[-3:, :2].mean(axis=0), 0.01, 0.0, 0.5 + window[-1, 2:4] ** 2, 0.1]

    single = [InversionPolicy(env, observer, ignition=0.1, ignition_share=share) for _ in range(2)]
    batch = InversionPolicy(env, observer, ignition=0.1, ignition_share=share).batch(2)
    batch.reset([0, 1])
    obs = _flight(env, 24, np.random.default_rng(1), rows=2)
    for k in range(24):
        rows = np.array([0, 1]) if k != 13 else np.array([1])               # row 0 sits out a step
        got = batch.act(rows, obs[k, rows], {})
        for j, r in enumerate(rows):
            np.testing.assert_array_equal(got[j], single[r].act(obs[k, r], {}))
    with pytest.raises(ConfigError, match="ignition"):
        InversionPolicy(env, observer, ignition=-1.0)
    for bad in (0.0, 1.5):
        with pytest.raises(ConfigError, match=r"ignition share.*more than 0 and at most 1"):
            InversionPolicy(env, observer, ignition=0.1, ignition_share=bad)
    with pytest.raises(ConfigError, match="gimbal_pitch"):
        signal_index(env, ("gimbal_pitch", "no_such_signal"))
