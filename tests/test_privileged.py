"""The privileged reference (lvgym/baselines/privileged.py) and the env's privileged_info: the law against
hand numbers, the info against the simulator's state, and the runner flying it with the option set."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import lvgym
from lvgym.baselines.privileged import GAINS, PREVIEW, RELIEF, PrivilegedPolicy, privileged
from lvgym.envs.privileged import PREVIEW_PERIODS
from lvgym.errors import ConfigError


def test_the_info_holds_the_true_state_only_when_asked():
    env = gym.make("lvgym/SmileAscent-v1", mission_time_s=3.0, privileged_info=True)
    env.reset(seed=0)
    info = env.step(np.array([0.1, -0.1], np.float32))[4]
    u = env.unwrapped
    np.testing.assert_array_equal(info["omega_bi_b"], u.flight.state("omega_bi_b")[0])
    np.testing.assert_array_equal(info["m_aero_b"], u.flight.conditions("m_aero_b")[0])
    assert info["thrust"] == u.flight.conditions("thrust")[0] > 0.0 and 0.0 < info["gimbal_arm"] < 16.5
    assert info["J_b_diag"].shape == (3,) and info["J_b_diag"][1] > info["J_b_diag"][0] > 0.0
    plain = gym.make("lvgym/SmileAscent-v1", mission_time_s=3.0)
    plain.reset(seed=0)
    other = plain.step(np.array([0.1, -0.1], np.float32))[4]
    assert "m_aero_b" not in other and other["time"] == info["time"]
    np.testing.assert_array_equal(other["gimbal"], info["gimbal"])          # the same flight


def test_the_law_cancels_the_aerodynamic_moment_and_closes_the_attitude_loop():
    env = gym.make("lvgym/SmileAscent-v1", privileged_info=True, model="rigid")
    pol = PrivilegedPolicy(env, bandwidth_radps=2.0, damping=0.5, preview_periods=0)
    limit = env.unwrapped.func.gimbal_limit
    obs = np.zeros(env.observation_space.shape, np.float32)
    info = {"omega_bi_b": np.array([0.0, 0.01, -0.02]), "attitude_error": np.array([0.03, 0.0]),
            "m_aero_b": np.array([0.0, 500.0, -300.0]), "thrust": 4e5, "gimbal_arm": 5.0,
            "J_b_diag": np.array([700.0, 1e5, 1e5])}
    a = pol.act(obs, info)
    want_p = (1e5 * (-2 * 0.5 * 2.0 * 0.01 - 4.0 * 0.03) - 500.0) / 2e6
    want_y = (1e5 * (-2 * 0.5 * 2.0 * -0.02) + 300.0) / 2e6
    np.testing.assert_allclose(a, np.array([want_p, want_y]) / limit, rtol=1e-6)
    assert not pol.act(obs, {**info, "thrust": 0.0}).any()                  # no thrust, no command
    assert not pol.act(obs, {"time": 0.0}).any()                            # the reset's info
    # load relief: from onset to full of the q-alpha limit the attitude term and the cancellation fade out
    relief = PrivilegedPolicy(env, bandwidth_radps=2.0, damping=0.5, relief=(0.4, 0.8), preview_periods=0)
    np.testing.assert_allclose(relief.act(obs, {**info, "qalpha_pa_deg": 0.3 * 250e3}), a, rtol=1e-6)
    half = relief.act(obs, {**info, "qalpha_pa_deg": 0.6 * 250e3})
    want_half = [(1e5 * (-2 * 0.5 * 2.0 * 0.01 - 0.5 * 4.0 * 0.03) - 0.5 * 500.0) / 2e6,
                 (1e5 * (-2 * 0.5 * 2.0 * -0.02) + 0.5 * 300.0) / 2e6]
    np.testing.assert_allclose(half, np.array(want_half) / limit, rtol=1e-6)
    damping_only = relief.act(obs, {**info, "qalpha_pa_deg": 0.9 * 250e3})
    want_damp = [1e5 * (-2 * 0.5 * 2.0 * 0.01) / 2e6, 1e5 * (-2 * 0.5 * 2.0 * -0.02) / 2e6]
    np.testing.assert_allclose(damping_only, np.array(want_damp) / limit, rtol=1e-6)


def test_the_preview_is_the_wind_the_vehicle_then_meets():
    """The info's wind ahead, k control periods on, against the wind the flight then meets: the turbulence is a
    frozen field in altitude, so they differ only by the path's curvature over k periods."""
    env = lvgym.make_env("smile-v2", model="rigid", privileged_info=True)
    env.reset(seed=5)
    for _ in range(1000):                                              # to 20 s: in the turbulence
        info = env.step(np.zeros(2, np.float32))[4]
    u = env.unwrapped
    ahead, m_ahead = info["wind_ahead_n"], info["m_aero_ahead_b"]
    assert ahead.shape == m_ahead.shape == (PREVIEW_PERIODS, 3)
    np.testing.assert_array_equal(info["actuator_effectiveness"], [1.0, 1.0])
    np.testing.assert_array_equal(info["misalignment"], u.func.sim.misalignment(u.core.state.sim)[0])
    assert 0.0 < np.abs(info["misalignment"]).max() < np.radians(0.16)      # the dispersion's draw
    sim, data = u.func.sim, u.core.state.sim
    np.testing.assert_array_equal(sim.conditions_ahead(data, [0.0])[0], data.conditions)     # horizon 0: now
    now, met = u.flight.conditions("wind_n")[0].copy(), []
    for _ in range(PREVIEW_PERIODS):
        env.step(np.zeros(2, np.float32))
        met.append(u.flight.conditions("wind_n")[0].copy())
    change, miss = np.abs(np.array(met) - now).max(), np.abs(ahead - np.array(met)).max()
    assert change > 0.1 and miss < 0.03 * change, (change, miss)      # it moves; the preview follows it


@pytest.mark.parametrize("suite", ["smile-v2", "slender-v2"])
def test_the_privileged_info_changes_nothing_of_the_flight(suite):
    """The preview evaluates the models in the rows' context (their scratch): the flight is the same to the bit."""
    records = []
    for privileged_info in (False, True):
        env = lvgym.make_env(suite, model="nonrigid", privileged_info=privileged_info, mission_time_s=12.0)
        env.reset(seed=7)
        rng = np.random.default_rng(0)
        rows = []
        for _ in range(600):
            obs, _, term, trunc, info = env.step(rng.uniform(-0.3, 0.3, 2).astype(np.float32))
            u = env.unwrapped
            rows.append(np.concatenate([u.core.state.sim.x[0], u.core.state.sim.conditions[0], obs]))
            if term or trunc:
                break
        records.append(np.array(rows))
    np.testing.assert_array_equal(records[0], records[1])


def test_the_law_reads_the_moment_at_its_preview():
    env = gym.make("lvgym/SmileAscent-v1", privileged_info=True, model="rigid")
    obs = np.zeros(env.observation_space.shape, np.float32)
    m_ahead = np.zeros((PREVIEW_PERIODS, 3))
    m_ahead[1] = [0.0, 800.0, -100.0]
    info = {"omega_bi_b": np.zeros(3), "attitude_error": np.zeros(2), "m_aero_b": np.array([0.0, 500.0, -300.0]),
            "m_aero_ahead_b": m_ahead, "thrust": 4e5, "gimbal_arm": 5.0, "J_b_diag": np.array([700.0, 1e5, 1e5])}
    limit = env.unwrapped.func.gimbal_limit
    np.testing.assert_allclose(PrivilegedPolicy(env, preview_periods=0).act(obs, info),
                               np.array([-500.0, 300.0]) / 2e6 / limit, rtol=1e-6)
    np.testing.assert_allclose(PrivilegedPolicy(env, preview_periods=2).act(obs, info),
                               np.array([-800.0, 100.0]) / 2e6 / limit, rtol=1e-6)
    with pytest.raises(ConfigError, match=f"privileged.preview_periods = {PREVIEW_PERIODS + 1}: an integer from 0"):
        PrivilegedPolicy(env, preview_periods=PREVIEW_PERIODS + 1)
    # it knows the true thrust direction and what the actuator still reaches: it takes the misalignment off and
    # divides by the effectiveness (plant=False: it does not)
    faulty = {**info, "misalignment": np.array([0.001, -0.002]), "actuator_effectiveness": np.array([1.0, 0.5])}
    want = (np.array([-500.0, 300.0]) / 2e6 - [0.001, -0.002]) / [1.0, 0.5]
    np.testing.assert_allclose(PrivilegedPolicy(env, preview_periods=0).act(obs, faulty), want / limit, rtol=1e-6)
    np.testing.assert_allclose(PrivilegedPolicy(env, preview_periods=0, plant=False).act(obs, faulty),
                               np.array([-500.0, 300.0]) / 2e6 / limit, rtol=1e-6)


def test_it_refuses_an_env_without_the_true_state_and_bad_gains():
    with pytest.raises(ConfigError, match="privileged_info"):
        privileged(gym.make("lvgym/SmileAscent-v1"))
    with pytest.raises(ConfigError, match="bandwidth_radps"):
        privileged(gym.make("lvgym/SmileAscent-v1", privileged_info=True), bandwidth_radps=-1.0)
    with pytest.raises(ConfigError, match=r"privileged.relief = \(0.8, 0.4\): two shares"):
        privileged(gym.make("lvgym/SmileAscent-v1", privileged_info=True), relief=(0.8, 0.4))
    pol = privileged(gym.make("lvgym/SmileAscent-v1", privileged_info=True, model="rigid"))
    assert (pol.w, pol.z) == GAINS["rigid"] and pol.relief == RELIEF and pol.preview == PREVIEW


def test_the_runner_flies_it_with_the_true_state_batched_as_single():
    from dataclasses import replace

    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import evaluate, make_tasks, run_episode
    from lvgym.benchmark.suites import get_suite

    import lvgym.cli.policies  # noqa: F401

    s = get_suite("smile-v1").with_options(mission_time_s=8.0)
    s = replace(s, conditions=s.conditions[:1])
    spec, lqg = resolve_policy("privileged"), resolve_policy("lqg")
    tasks = make_tasks([spec, lqg], [s], 2, "validation")
    assert [dict(t.condition.options).get("privileged_info", False) for t in tasks] == [True, True, False, False]
    recs = evaluate([spec], [s], 2, "validation", executor="serial", progress=False)
    for r, t in zip(recs, tasks):
        single = run_episode(spec, t.condition, t.seed)
        assert {k: single[k] for k in ("score", "failed", "rate_error_rad")} == {k: r[k] for k in ("score", "failed",
                                                                                                    "rate_error_rad")}
        assert not r["failed"]
