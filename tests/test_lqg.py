"""The LQG baseline (lvgym.baselines.design.lqg_design, lvgym.baselines.lqg): its plant, its margins, its law and its flight."""

import warnings
from dataclasses import fields

import control
import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.design import flightloop as F
from lvgym.baselines.design import linearize as L
from lvgym.baselines.design import lqg_design as D
from lvgym.baselines.design import lqg_row as R
from lvgym.baselines.lqg import LQGPlane, LQGPolicy, LQGRow, LQGSchedule, smile_lqg
from lvgym.errors import ConfigError

T0 = 28.8


@pytest.fixture(scope="module")
def ops():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {m: L.operating_point("smile", T0, m, protocol="v1") for m in ("rigid", "nonrigid")}


@pytest.fixture(scope="module")
def shipped():
    return LQGSchedule.load("smile_lqg")


def _row_weights(t: float) -> R.LQGWeights:
    """The weights the shipped schedule chose at the row of flight time ``t`` [s]."""
    with np.load(D.SCHEDULES / "smile_lqg.npz") as z:
        i = int(np.argmin(np.abs(z["time_s"] - t)))
        vals = z[f"pitch_{i}_weights"]
    return R.LQGWeights(**{f.name: float(v) for f, v in zip(fields(R.LQGWeights), vals)})


def test_delayed_plant_is_the_flight_plant(ops):
    """The delay written as a state leaves the plant as flight_plant builds it, and the state names
    count the servo, the vehicle, the gyro filters and the delay."""
    op = ops["nonrigid"]
    A, B, C, Gw = R.delayed_plant(op)
    w = np.logspace(-1, np.log10(150.0), 200)
    ours = F.frequency_response(control.ss(A, B, C, 0.0, 0.02), w)
    ref = F.frequency_response(F.flight_plant(op), w)
    # the same plant written two ways: agreement to rounding (1.2e-9 relative near 0.2 rad/s on one machine's
    # LAPACK, 2026-12-07; a wrong block would be off by orders more)
    np.testing.assert_allclose(ours, ref, rtol=1e-8, atol=1e-12)
    labels = R.plant_labels(op)
    assert len(labels) == A.shape[0] and labels[0] == "servo_position" and labels[-1] == "command_delay_0"
    assert "omega_y" in labels and "eta_dot_z0" in labels
    assert np.all(Gw[-1] == 0.0) and B[-1, 0] == 1.0              # the disturbance enters after the delay


def test_grid_margins_agree_with_linearize_margins_on_a_pid_loop(ops):
    """loop_margins (frequency grid, closed-loop eigenvalues) against linearize.margins on the shipped
    rigid PID's 10-state loop: the same phase margin and crossover, the gain margin within 0.1 dB
    (the polynomial method's root finding is the less accurate: |L| at its phase crossover is 0.920,
    0.73 dB), the same closed-loop verdict."""
    from lvgym.baselines.design import charts

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        Lp = charts.open_loop(ops["rigid"], (0.0491, 0.3526, 0.1196, 500.0))
        ref, ours = L.margins(Lp), R.loop_margins(Lp)
    assert ours["phase_margin_deg"] == pytest.approx(ref["phase_margin_deg"], abs=0.05)
    assert ours["gain_crossover_radps"] == pytest.approx(ref["gain_crossover_radps"], rel=1e-3)
    assert ours["gain_margin_db"] == pytest.approx(ref["gain_margin_db"], abs=0.1)
    assert ours["closed_loop_stable"] == ref["closed_loop_stable"]


def test_design_at_max_q_meets_its_margins(ops, shipped):
    """The max-q row, designed with the shipped weights on the non-rigid plant, is the shipped row, and its
    rigid and non-rigid loops broken at the plant input are stable with >= 6 dB and >= 30 deg, the second
    bending mode (aliased) below -6 dB, and linearize.margins agrees that both closed loops are stable."""
    d = R.design_row(ops["nonrigid"], "pitch", _row_weights(T0))
    row = shipped.rows["pitch"][shipped.index(T0)]
    np.testing.assert_allclose(d.Kx, row.Kx, rtol=1e-6, atol=1e-9 * np.abs(row.Kx).max())
    np.testing.assert_allclose(d.M, row.M, rtol=1e-6, atol=1e-9 * np.abs(row.M).max())
    modes = F.mode_frequencies(ops["nonrigid"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plants = {m: F.flight_plant(ops[m]) for m in ops}
        a = D.assess(d, plants, modes)
        for m in ops:
            assert a[m]["closed_loop_stable"], m
            assert a[m]["gain_margin_db"] >= 6.0 and abs(a[m]["phase_margin_deg"]) >= 30.0, (m, a[m])
            assert L.margins(R.open_loop(d.compensator(), plants[m]))["closed_loop_stable"], m
    assert max(a["bending_db"][1:]) <= -6.0


def test_law_equals_the_linear_compensator(shipped):
    """The policy's law, unclipped, on a known gyro sequence gives the command sequence of
    lqg_design.compensator (python-control), row by row."""
    rng = np.random.default_rng(3)
    for i in (3, 6):
        r = shipped.rows["pitch"][i]
        one = LQGSchedule({p: (r,) for p in ("pitch", "yaw")}, "one row")
        law = LQGPlane(one.rows["pitch"], one, u_limit=1e6)
        y = 1e-3 * rng.standard_normal(200)
        u_law = np.array([law.update(v, r.time_s, True)[0] for v in y])
        d = R.RowDesign(r.time_s, "pitch", r.A, r.B, r.C, r.Kx, r.Ki, r.M, r.a, r.dt, R.LQGWeights(), r.labels)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            u_lin = np.ravel(control.forced_response(d.compensator(), U=y).outputs)
        np.testing.assert_allclose(u_law, u_lin, rtol=1e-9, atol=1e-12 * np.abs(u_lin).max())


def test_yaw_plane_sign_matches_the_env():
    """A yaw gimbal pulse at max q: the env's yaw rate error follows flight_plant(op, "yaw") (the sign the
    yaw law assumes) within 5 % of its peak."""
    out = []
    for amp in (0.0, 0.01):
        env = gym.make("lvgym/SmileAscent-v1", model="rigid", wind="none")
        env.reset(seed=0)
        info = {"time": 0.0}
        while info["time"] < T0 - 0.01:
            _, _, _, _, info = env.step(np.zeros(2, np.float32))
        i = env.unwrapped.observation_layout.index("yaw_rate_error")
        seq = []
        for k in range(30):
            obs, *_ = env.step(np.array([0.0, amp if k < 5 else 0.0], np.float32))
            seq.append(float(obs[i]))
        out.append(np.array(seq))
        limit = float(env.unwrapped.gimbal_limit)
    d_env = out[1] - out[0]
    op = L.operating_point("smile", T0, "rigid", protocol="v1")
    u = np.r_[[0.01 * limit if k < 5 else 0.0 for k in range(30)], 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        y = np.ravel(control.forced_response(F.flight_plant(op, "yaw"), U=u).outputs)[1:]
    peak = np.abs(d_env).max()
    assert peak > 1e-4
    np.testing.assert_allclose(y, d_env, atol=0.05 * peak)


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_lqg_flies_smile_v1(model):
    """The first validation seed of the smile-v1 suite (turbulence, gust, every dispersion), 70 s: no
    failure and a pitch + yaw rate error under 1.0 rad (the shipped schedule flies 0.70 rigid and 0.84
    non-rigid; gs-pid 0.76 and 3.67 on this seed)."""
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy, play_episode
    from lvgym.benchmark.suites import SUITES

    cond = next(c for c in SUITES["smile-v1"].conditions if c.model == model)
    env = cond.make_env()
    policy = build_policy(resolve_policy("lqg"), env)
    assert isinstance(policy, LQGPolicy)
    rec = play_episode(policy, env, SUITES["smile-v1"].seeds("validation", 1)[0])
    assert not rec["failed"], rec["failure_reason"]
    assert rec["rate_error_rad"] < 1.0


def test_bad_inputs_raise_clear_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        LQGSchedule.load(tmp_path / "missing.npz")
    with pytest.raises(ConfigError, match="smile_v1"):
        smile_lqg(gym.make("lvgym/StratosIII-v1"))
    with pytest.raises(ConfigError, match="vehicle"):
        D.design_schedule("stratos3")
    with pytest.raises(ConfigError, match="lqg.r_gimbal"):
        R.LQGWeights(r_gimbal=0.0)
    with pytest.raises(SystemExit):
        D.main(["--vehicle", "slender"])
    with pytest.raises(ConfigError, match="rows"):
        D.row_intervals((48.0,), D.SMILE_PHASES_S)
    r = LQGSchedule.load("smile_lqg").rows["pitch"][0]
    with pytest.raises(ConfigError, match="Kx"):
        LQGRow(r.time_s, r.interval_s, r.A, r.B, r.C, r.Kx[:, :-1], r.Ki, r.M, r.a, r.dt, r.labels)


def test_a_batch_of_rows_is_the_policy_of_each_row():
    """LQGLaw steps n rows together (what a residual's baselines in training use); each row's actions
    equal an LQGPolicy's flying the same inputs to the bit, with the rows at different flight times
    (other schedule rows, the boost and the upper stage at once), switched off through a coast, reset at
    different steps and stepped in changing subsets."""
    env = gym.make("lvgym/SmileAscent-v1", model="nonrigid")
    obs0, _ = env.reset(seed=0)
    lay = env.unwrapped.observation_layout
    n = 6
    single = [smile_lqg(env) for _ in range(n)]
    batch = smile_lqg(env).batch(n)
    rng = np.random.default_rng(5)
    t = np.array([2.0, 9.0, 20.0, 41.9, 50.0, 54.0])          # the last two: coast, then ignition
    batch.reset(np.arange(n))
    for p in single:
        p.reset()
    for step in range(400):
        rows = np.flatnonzero(rng.random(n) < 0.8)              # the rows stepped this time
        obs = np.tile(obs0, (n, 1)).astype(float)
        obs[:, lay.index("pitch_rate_error")] = 2e-3 * rng.standard_normal(n)
        obs[:, lay.index("yaw_rate_error")] = 2e-3 * rng.standard_normal(n)
        obs[:, lay.index("controller_on")] = ((t < 43.0) | (t > 54.5)).astype(float)
        got = batch.act(rows, obs[rows], {"time": t.copy()})
        want = np.array([single[b].act(obs[b], {"time": float(t[b])}) for b in rows]).reshape(-1, 2)
        np.testing.assert_array_equal(got, want)
        t[rows] += 0.02
        if step == 200:                                         # a row starts a new episode
            batch.reset([3])
            single[3].reset()
            t[3] = 2.0
