"""The load relief of the gain-scheduled PID (lvgym.baselines.pid, ``accel_gain``), the slender vehicle's
gs-pid-flex schedule and its drift requirement against the q-alpha limit, the tube's structural q-alpha
limit (experiments.aeroelastic_divergence.structural_limit) and the linear-programme bound on the q-alpha of any gimbal history
(experiments.load_relief.loadbound)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.design import flexdesign as FD
from experiments.aeroelastic_divergence.divergence import Lift, free_free_beam
from lvgym.baselines.filters import StructuralFilter
from experiments.load_relief.loadbound import min_peak_qalpha
from lvgym.baselines.pid import ACCEL_SIGNS, FLEX_SCHEDULES, GainSchedule, GainScheduledPIDPolicy, flex_pid
from experiments.load_relief.qalpha_floor import fly, summary
from experiments.aeroelastic_divergence.structural_limit import bending_moment_per_qsa, buckling_stress_pa, qalpha_limit_pa_deg
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import PolicySpec
from lvgym.benchmark.suites import get_suite
from lvgym.envs.layouts import REASONS
from lvgym.errors import ConfigError


@pytest.fixture(scope="module")
def slender_env():
    env = gym.make("lvgym/SlenderAscent-v1", model="rigid")
    yield env
    env.close()


def _one_row(accel_gain: float | None) -> GainSchedule:
    row = {"mass_kg": 300.0, "kp": 0.1, "ki": 0.0, "kd": 0.0}
    if accel_gain is not None:
        row["accel_gain"] = accel_gain
    return GainSchedule.from_dict({"variable": "mass", "rows": [row]})


def test_load_relief_law_against_hand_numbers(slender_env):
    pol = GainScheduledPIDPolicy(_one_row(0.002), env=slender_env)
    lay = slender_env.unwrapped.observation_layout
    obs = np.zeros(lay.size)
    obs[lay.index("pitch_rate_error")] = 0.01       # rad/s
    obs[lay.index("accel_z")] = 0.5                 # g0
    obs[lay.index("accel_y")] = -0.2
    obs[lay.index("controller_on")] = 1.0
    pol.reset()
    action = pol.act(obs, {"mass": 300.0, "time": 3.0})
    # pitch: e = -0.01 + 0.002 * 9.80665 * (+1) * 0.5 = -0.01 + 0.00980665 = -1.9335e-4 rad/s
    # yaw:   e = 0 + 0.002 * 9.80665 * (-1) * (-0.2) = 3.92266e-3 rad/s; gimbal = kp e (no filter, ki = kd = 0)
    assert ACCEL_SIGNS == (1.0, -1.0)
    np.testing.assert_allclose(pol.last_gimbal, [0.1 * -1.9335e-4, 0.1 * 3.92266e-3], rtol=1e-4)
    np.testing.assert_allclose(action, pol.last_gimbal / slender_env.unwrapped.gimbal_limit, rtol=1e-5)
    # without the row key: the error alone, and no accelerometer term
    plain = GainScheduledPIDPolicy(_one_row(None), env=slender_env)
    plain.reset()
    plain.act(obs, {"mass": 300.0, "time": 3.0})
    np.testing.assert_allclose(plain.last_gimbal, [0.1 * -0.01, 0.0], atol=1e-12)


def test_load_relief_needs_every_row_and_accelerometers():
    rows = [{"mass_kg": 300.0, "kp": 0.1, "ki": 0.0, "kd": 0.0, "accel_gain": 0.001},
            {"mass_kg": 200.0, "kp": 0.1, "ki": 0.0, "kd": 0.0}]
    with pytest.raises(ConfigError, match="accel_gain"):
        GainSchedule.from_dict({"variable": "mass", "rows": rows})
    env = gym.make("lvgym/SlenderAscent-v1", model="rigid", observation="state")
    with pytest.raises(ConfigError, match="accelerometers"):
        GainScheduledPIDPolicy(_one_row(0.001), env=env)
    env.close()


def test_accelerometer_signs_in_a_crosswind():
    """The frame facts behind ACCEL_SIGNS: in a steady crosswind with the gimbal at zero, the lateral
    specific force is opposite to the air's body component (pitch: +v_air_z gives -accel_z; yaw:
    +v_air_y gives -accel_y), and a positive pitch (yaw) rate raises (lowers) v_air_z (v_air_y). The
    ``gust`` tier (a 1-cosine gust): in the steady ``profile`` wind the weathercock's oscillation puts
    the IMU's lever-arm acceleration on top and the correlation is weaker (-0.24 / -0.34 when measured)."""
    env = gym.make("lvgym/SlenderAscent-v1", model="rigid", wind="gust", mission_time_s=6.0)
    lay = env.unwrapped.observation_layout
    obs, info = env.reset(seed=0)
    rows = []
    while True:
        obs, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        va = env.unwrapped.flight.conditions("v_air_b")[0]
        w = env.unwrapped.flight.state("omega_bi_b")[0]
        rows.append([info["time"], va[2] / va[0], va[1] / va[0], obs[lay.index("accel_z")], obs[lay.index("accel_y")],
                     w[1], w[2]])
        if term or trunc:
            break
    env.close()
    a = np.array(rows)
    a = a[a[:, 0] >= 2.0]
    assert np.corrcoef(a[:, 1], a[:, 3])[0, 1] < -0.8
    assert np.corrcoef(a[:, 2], a[:, 4])[0, 1] < -0.8
    dt = a[1, 0] - a[0, 0]
    rate_p, rate_y = np.gradient(a[:, 1], dt), np.gradient(a[:, 2], dt)
    assert np.corrcoef(rate_p, a[:, 5])[0, 1] > 0.5
    assert np.corrcoef(rate_y, a[:, 6])[0, 1] < -0.5


def test_gs_pid_flex_flies_the_slender_schedule(slender_env):
    key = slender_env.unwrapped.task.vehicle
    assert FLEX_SCHEDULES[key] == "slender_flex"
    pol = flex_pid(slender_env)
    assert pol.schedule.accel_gain is not None and all(k > 0 for k in pol.schedule.accel_gain)
    assert pol.schedule.meta["design"]["ki_scale"] < 1.0
    assert pol.schedule.filters is not None


def test_slender_rows_meet_every_requirement_but_the_drift():
    """The shipped load-relief schedule's record: every row, at its time and at both ends of its stretch,
    in pitch and yaw, rigid and non-rigid, meets the 6 dB / 30 deg margins and attenuates every bending
    mode by at least 6 dB, and misses the drift requirement only: its slowest divergence (0.14-0.50 1/s)
    is above 0.02 1/s and below the vehicle's own with the gimbal held (0.16-0.95 1/s). Its integral is
    ``ki_scale`` (0.05) times the plain design's it records."""
    meta = GainSchedule.load("slender_flex").meta
    assert meta["design"]["ki_scale"] == 0.05 and meta["design"]["accel_gain"] == 0.001
    assert [r["time_s"] for r in meta["rows"]] == [1.0, 3.0, 5.0, 7.0]
    for row in meta["rows"]:
        assert row["misses"] == ["drift"] and not row["meets"], (row["time_s"], row["misses"])
        assert row["ki"] == pytest.approx(0.05 * row["plain"]["ki"], rel=1e-12)
        assert row["accel_gain"] == 0.001
        for chk in [row] + row["ends"]:
            assert chk["misses"] == ["drift"], (row["time_s"], chk["time_s"], chk["misses"])
            for key, m in chk["margins"].items():
                assert m["gain_margin_db"] >= 5.95 and abs(m["phase_margin_deg"]) >= 29.5, (row["time_s"], key, m)
                assert 0.02 < m["max_pole_real_per_s"] < m["open_loop_pole_per_s"], (row["time_s"], key, m)
            assert all(x["loop_gain_db"] <= -6.0 for x in chk["modes"] if x["mode"] == "bending"), chk["modes"]


def test_slender_first_row_on_fresh_plants():
    """The 1 s row (which missed the gain margin before it was designed on the relieved loop: rigid
    5.4-5.8, non-rigid 4.3-4.7 dB) checked again on freshly built pitch plants at 1 s (flown there with the
    gimbal at zero, as the design flew them): the record's numbers side by side, rigid / non-rigid gain
    margin 6.69 / 6.93 dB, phase margin 54.0 / 54.2 deg, bending modes 6.5 dB down, slowest divergence
    0.50 1/s against the vehicle's own 0.95 1/s."""
    plants, modes, _ = FD.row_plants("slender", 1.0, None)
    row = GainSchedule.load("slender_flex").meta["rows"][0]
    chk = FD.check_loops({"pitch": plants["pitch"]}, (row["kp"], row["ki"], row["kd"]),
                         StructuralFilter.from_dict(row["filter"]), modes, FD.Requirements())
    assert chk["misses"] == ["drift"]
    for key in ("rigid_pitch", "nonrigid_pitch"):
        rec, m = row["margins"][key], chk[key]
        assert m["gain_margin_db"] == pytest.approx(rec["gain_margin_db"], abs=0.01) and m["gain_margin_db"] >= 6.0
        assert m["phase_margin_deg"] == pytest.approx(rec["phase_margin_deg"], abs=0.05)
        assert m["max_pole_real_per_s"] == pytest.approx(rec["max_pole_real_per_s"], abs=1e-4)
        assert m["open_loop_pole_per_s"] == pytest.approx(rec["open_loop_pole_per_s"], abs=1e-4)
    assert chk["rigid_pitch"]["max_pole_real_per_s"] == pytest.approx(0.502, abs=1e-3)
    assert chk["rigid_pitch"]["open_loop_pole_per_s"] == pytest.approx(0.953, abs=1e-3)
    assert [m["loop_gain_db"] for m in chk["modes"]] == [x["loop_gain_db"] for x in row["modes"]]


def test_the_drift_requirement_contradicts_the_qalpha_limit():
    """Issue 17 asks every row for a slowest divergence of 0.02 1/s; slender-v1 asks for a q-alpha below
    250 kPa deg. On this vehicle they contradict each other. The plain designs the load-relief rows
    record (integral 0.56-0.78 rad of gimbal per rad, no accelerometer) come as close to the drift
    requirement as the optimiser got (0.008-0.025 1/s; the relief rows: 0.14-0.50 1/s); flown on
    validation seeds where the load-relief schedule stays far under the limit (rigid seed 5: 163.8 kPa deg;
    non-rigid seed 3: 174.3), they break it (270.1 at 5.42 s; 271.1 at 5.18 s). And a perfect attitude hold
    in the same winds would carry 455.6 and 441.8 kPa deg (the wind's angle times q; 409-489 on all ten
    seeds of either model when measured): no loop that holds the attitude can meet 250."""
    sched = GainSchedule.load("slender_flex")
    meta = sched.meta
    plain_growth = [r["plain"]["max_pole_real_per_s"] for r in meta["rows"]]
    assert max(plain_growth) < 0.026 and min(plain_growth) < 0.02
    assert min(m["max_pole_real_per_s"] for r in meta["rows"] for m in r["margins"].values()) > 0.15
    assert all(0.5 < r["plain"]["ki"] < 0.8 for r in meta["rows"])
    suite = get_suite("slender-v1")
    seeds = suite.seeds("validation", 10)
    plain = PolicySpec("plain", "lvgym.baselines.pid:GainScheduledPIDPolicy", (("schedule", FD.plain_schedule(sched)),))
    for cond in suite.conditions:
        seed = {"rigid": seeds[5], "nonrigid": seeds[3]}[cond.model]
        held = summary(fly(plain, cond, seed))
        relieved = summary(fly(POLICIES["gs-pid-flex"], cond, seed))
        assert held["failed"] and held["reason"] == REASONS[2], (cond.model, held)
        assert held["qalpha_peak_kpa_deg"] > 260.0, (cond.model, held)
        assert not relieved["failed"] and relieved["qalpha_peak_kpa_deg"] < 180.0, (cond.model, relieved)
        assert relieved["hold_peak_kpa_deg"] > 440.0, (cond.model, relieved)


def test_plain_schedule_needs_the_record():
    with pytest.raises(ValueError, match="plain"):
        FD.plain_schedule(GainSchedule.load("smile_flex"))


def test_short_slender_v1_flight_with_load_relief():
    env = gym.make("lvgym/SlenderAscent-v1", model="nonrigid", wind="turbulence", mission_time_s=4.0)
    pol = flex_pid(env)
    obs, info = env.reset(seed=0)
    pol.reset()
    gains = []
    while True:
        gains.append(pol.schedule.accel_gain_at(float(info["mass"])))   # the load-relief gain the law flies
        obs, _, term, trunc, info = env.step(pol.act(obs, info))
        if term or trunc:
            break
    env.close()
    assert trunc and not term and info["time"] == pytest.approx(4.0)
    assert max(gains) > 0.0 and np.all(np.isfinite(pol.last_gimbal))


def test_bending_moment_of_a_uniform_free_beam_against_hand_numbers():
    """A uniform 1 m, 1 kg free beam with a unit lateral force at 0.25 m behind the nose (gimbal at zero):
    a = 1, theta_ddot = 0.25 / (1/12) = 3; M(x) = (x - 0.25)+ - int_0^x (1 + 3 (0.5 - s)) (x - s) ds,
    so M(0.25) = -(1.75 * 0.25^2 / 2 + 0.25^3) = -0.0703125 and M(0.5) = 0.25 - (0.5^2 / 2 + 0.5^3) = 0."""
    beam = free_free_beam(1.0, 1.0, lambda x: np.ones_like(x), [], n_el=400, gimbal=1.0)
    lift = Lift(np.array([0.25]), np.array([1.0]), 1.0)
    xi, m = bending_moment_per_qsa(beam, lift, "free")
    at = lambda x: float(np.interp(x, xi, m))  # noqa: E731
    assert at(0.25) == pytest.approx(-0.0703125, abs=2e-3)
    assert at(0.5) == pytest.approx(0.0, abs=2e-3)
    assert abs(m[-1]) < 1e-9 and abs(m[0]) < 1e-12                # free ends carry no moment
    # trimmed: the side force at the tail F_g = -0.25 / (0.5 - 1.0) = 0.5, a = 1.5, no rotation:
    # M(0.5) = 0.25 - 1.5 * 0.5^2 / 2 = 0.0625
    xi, m = bending_moment_per_qsa(beam, lift, "trimmed")
    assert float(np.interp(0.5, xi, m)) == pytest.approx(0.0625, abs=2e-3)


def test_qalpha_limit_against_hand_numbers():
    """D 0.2833 m, t 4.5 mm: I = pi/64 (D^4 - d^4) = 3.8306e-5 m^4, A = 3.9414e-3 m^2. A bending moment of
    5 m per unit q S alpha on S = 0.063 m^2 stresses the wall by 5 * 0.063 * 0.14165 / 3.8306e-5 = 1164.8 Pa
    per Pa rad; 40 kN of compression takes 10.149 MPa of the 224 MPa allowable, leaving 213.85 MPa:
    q alpha = 213.85e6 / 1164.8 = 1.8359e5 Pa rad = 10.519e6 Pa deg."""
    assert qalpha_limit_pa_deg(5.0, 0.063, 0.2833, 0.0045, 224e6, 40000.0) == pytest.approx(10.519e6, rel=1e-3)
    assert qalpha_limit_pa_deg(5.0, 0.063, 0.2833, 0.0045, 224e6, 1e7) == 0.0
    # SP-8007's knockdown at R/t = 31.5: phi = sqrt(31.5)/16 = 0.3508, gamma = 1 - 0.901 (1 - e^-phi) = 0.7335;
    # 0.605 * 71 GPa / 31.5 * 0.7335 = 1.0003 GPa
    assert buckling_stress_pa(71e9, 0.14165, 0.0045) == pytest.approx(1.0003e9, rel=1e-3)


def test_load_bound_on_a_frozen_model():
    """A model whose gimbal drives the angle of attack directly can null a constant wind angle (bound 0);
    with no gimbal the bound is the wind's own q-alpha."""
    t = np.arange(0.0, 1.0, 0.02)
    V = np.full(t.size, 100.0)
    q = np.full(t.size, 1e5)
    wind = np.full(t.size, 1.0)                    # 0.01 rad of wind angle
    A = np.zeros((1, 3, 3))
    models = {"t": np.array([0.0]), "A": A, "B": np.array([[0.0, 0.0, 0.0]]), "E": np.zeros((1, 3))}
    free = min_peak_qalpha(models, t, q, V, wind, 0.0, 1.0, on_after_s=0.0)
    assert free["peak_pa_deg"] == pytest.approx(1e5 * math.degrees(0.01), rel=1e-6)
    assert free["zero_peak_pa_deg"] == pytest.approx(free["peak_pa_deg"], rel=1e-9)
    models["B"] = np.array([[0.0, 1.0, 0.0]])      # theta_dot = delta: the gimbal turns the body
    held = min_peak_qalpha(models, t, q, V, wind, 0.1, 10.0, on_after_s=0.0, count_after_s=0.2)
    assert held["peak_pa_deg"] < 1e-6 * free["peak_pa_deg"] + 1e-6
