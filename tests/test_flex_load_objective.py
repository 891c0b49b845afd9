"""The flex design's load objective (lvgym.baselines.design.loadobjective, flexdesign --load-objective)."""

import math
import warnings

import control
import numpy as np
import pytest
import yaml
from scipy import integrate

from lvgym.baselines.design import flexdesign as FD
from lvgym.baselines.design import loadobjective as LO
from lvgym.baselines.design.flexproblem import RowProblem, Requirements, START, design_row, notch_frequency
from lvgym.baselines.design.flextable import margin_table
from lvgym.baselines.design.response import frequency_response
from lvgym.environment.turbulence import dryden_psd
from lvgym.errors import ConfigError

W = np.unique(np.concatenate([np.geomspace(1e-4, 1e3, 40000)]))


def test_wind_rms_first_order_by_hand():
    """A first-order lag 1 / (1 + tau s) in first-order Dryden turbulence (``u``: ``Phi = sigma^2 2 a /
    (pi (a^2 + w^2))``, ``a = V / L``): ``integral Phi b^2 / (b^2 + w^2) dw = sigma^2 b / (a + b)`` with
    ``b = 1 / tau``, so the RMS is ``sigma / sqrt(1 + tau V / L)``; unit response: the RMS is ``sigma``."""
    V, L, sigma, tau = 300.0, 533.4, 2.0, 1.5
    resp = 1.0 / (1.0 + 1j * W * tau)
    assert LO.wind_rms(resp, W, V, L, sigma, "u") == pytest.approx(sigma / math.sqrt(1.0 + tau * V / L), rel=2e-3)
    assert LO.wind_rms(np.ones_like(W), W, V, L, sigma, "w") == pytest.approx(sigma, rel=2e-3)
    # the transverse spectrum the objective uses, against the integral done by quad
    ref = integrate.quad(lambda w: dryden_psd(w / V, sigma, L, "w") / V / (1 + (w * tau) ** 2), 0, np.inf, limit=200)[0]
    assert LO.wind_rms(resp, W, V, L, sigma, "w") == pytest.approx(math.sqrt(ref), rel=2e-3)


@pytest.fixture(scope="module")
def smile_row():
    """SMILE's pitch loops at 20 s (flown centred), with the load plants."""
    return FD.row_plants("smile", 20.0, None, True)


def test_load_plant_gyro_part_and_wind_angle(smile_row):
    """The load plant's gimbal-to-gyro part is flight_plant's; the wind's direct effect on the angle of
    attack is -1 / V (a lateral wind w turns the airflow by -w / V)."""
    plants, _, info = smile_row
    for plane in ("pitch", "yaw"):
        for model in ("rigid", "nonrigid"):
            g = info["load"][plane][model]
            w = np.geomspace(0.01, 150.0, 60)
            a = frequency_response(LO._sub(g, 0, 0), w)
            b = frequency_response(plants[plane][model], w)
            assert np.max(np.abs(a - b) / np.abs(b)) < 1e-6
            assert np.asarray(g.D)[1, 1] == pytest.approx(-1.0 / info["airspeed_mps"], rel=1e-3)


def test_closed_loop_load_against_python_control(smile_row):
    """The load measure of LoadProblem (the closed loop's wind response formed on the grid) against the
    loop closed by python-control on the MIMO plant, u = -C (y_gyro - k_a s y_f), the wind left open."""
    info = smile_row[2]
    cases = FD._load_cases([(20.0, smile_row)], ("pitch",))
    values = dict(START, kp=0.11, ki=0.55, kd=0.005, lead_zero_radps=3.3, lead_ratio=24.0, accel_gain=0.003)
    for objective, out in (("qalpha", 1), ("accel", 2)):
        p = LO.LoadProblem(cases, Requirements(), objective)
        e = p.evaluate(values)
        gains, filt = FD.controller(values, p.notch_radps)
        C = control.ss(FD.controller_tf(gains, filt, p.dt))
        M = np.array([[1.0, 0.0, -values["accel_gain"]], [0.0, 0.0, 0.0]])     # pitch: s = +1
        K = control.series(control.ss([], [], [], M, p.dt), control.append(C, control.ss([], [], [], [[0.0]], p.dt)))
        ref = 0.0
        for model in ("rigid", "nonrigid"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cl = control.feedback(info["load"]["pitch"][model], K, sign=-1)
            t = frequency_response(LO._sub(control.ss(cl), out, 1), p.w)
            scale = info["qbar_pa"] * 180 / math.pi if objective == "qalpha" else 1.0
            ref += scale * LO.wind_rms(t, p.w, info["airspeed_mps"]) / 2
        assert e["load"] == pytest.approx(ref, rel=1e-4)


def test_default_unchanged(smile_row):
    """Without the objective: row_plants has no load entries and the same plants; the load problem with
    no load relief reads the plain problem's margins and J; a document without the objective keeps the
    margin table's columns."""
    plants, modes, info = FD.row_plants("smile", 20.0, None)
    assert "load" not in info and "qbar_pa" not in info
    for plane in plants:
        for model in plants[plane]:
            w = np.geomspace(0.01, 150.0, 40)
            assert np.allclose(frequency_response(plants[plane][model], w),
                               frequency_response(smile_row[0][plane][model], w), rtol=1e-12)
    req = Requirements()
    values = dict(START, kp=0.11, ki=0.55, kd=0.005)
    plain = RowProblem([(plants["pitch"], modes)], req, drift="vehicle").evaluate(values)
    lp = LO.LoadProblem(FD._load_cases([(20.0, smile_row)], ("pitch",)), req).evaluate(dict(values, accel_gain=0.0))
    assert lp["J"] == pytest.approx(plain["J"], rel=1e-6)
    for model in ("rigid", "nonrigid"):
        assert lp[model] == pytest.approx(plain[model], rel=1e-6, abs=1e-9)
    with open(FD.__file__.replace("design/flexdesign.py", "schedules/smile_flex.yaml")) as f:
        doc = yaml.safe_load(f)
    table = margin_table(doc)
    assert "load" not in table.lower().split("requirements:")[0] and "| load (plain) |" not in table
    assert table.splitlines()[4].endswith("| noise [%] | meets |")


def test_chosen_relief_lowers_the_load():
    """On SMILE's 28.8 s row (max q) the design with the q-alpha objective (weight 10) lowers the load measure below
    the plain design's and keeps the rate loop's margins (the relieved loop: effective plant)."""
    row = FD.row_plants("smile", 28.8, None, True)
    plants, modes, _ = row
    req = Requirements()
    cases = [(28.8, row)]
    plain = design_row(RowProblem([(plants["pitch"], modes)], req), None, np.random.default_rng(0), 0, 300)
    e = LO.load_row(FD._load_cases(cases, ("pitch",)), req, plain, "qalpha", 10.0, maxiter=300)
    assert e["load"] < 0.95 * e["load_plain"]
    gains, filt = FD.controller(e["values"], notch_frequency(modes, 0.02))
    chk = FD.check_loops(FD._relieved(row, e["values"]["accel_gain"])[0], gains, filt, modes, req)
    assert set(chk["misses"]) <= {"drift"}                       # the relieved loop may drift as the vehicle does
    for k, m in chk.items():
        if k.startswith(("rigid_", "nonrigid_")):
            assert m["gain_margin_db"] >= 5.9 and abs(m["phase_margin_deg"]) >= 29.5


def test_bad_options_refused():
    with pytest.raises(ConfigError, match=r"load_objective.*'qalfa'.*'qalpha', 'accel'"):
        FD.design_schedule("smile", (20.0,), load_objective="qalfa")
    with pytest.raises(ConfigError, match=r"load_weight.*-1.*\(0, 100\]"):
        FD.design_schedule("smile", (20.0,), load_objective="qalpha", load_weight=-1.0)
    with pytest.raises(ConfigError, match=r"load_objective.*relief"):
        FD.design_schedule("smile", (20.0,), load_objective="qalpha", relief=(0.1, 0.001))
    with pytest.raises(SystemExit):
        FD.main(["--load-objective", "qalpha", "--load-relief", "0.1", "0.001"])
    with pytest.raises(SystemExit):
        FD.main(["--load-objective", "qalpha", "--load-weight", "0"])


def test_margin_table_load_column():
    """A load-objective document's table gains the column 'load (plain)' on its rows (ends: '-'), and its
    log line names the objective with the plain design's value."""
    with open(FD.__file__.replace("design/flexdesign.py", "schedules/smile_flex.yaml")) as f:
        doc = yaml.safe_load(f)
    doc["design"]["load_objective"] = "qalpha"
    for r in doc["rows"]:
        r["load"] = {"objective": "qalpha", "value": 6374.0, "plain": 6710.0, "J": 243.1, "J_plain": 284.2}
        r["accel_gain"] = 0.001
    lines = margin_table(doc).splitlines()
    assert lines[4].endswith("| meets | load (plain) |") and lines[5].count("|") == lines[4].count("|")
    row = next(x for x in lines if x.startswith("| 28.8 |"))
    assert row.endswith("| 6374 (6710) |")
    end = next(x for x in lines if "(end)" in x)
    assert end.endswith("| - |")
    assert "qalpha 6374 Pa deg (plain 6710)" in FD.row_line(doc["rows"][0])


def test_load_plant_accelerometer_against_the_env():
    """The load plant's gimbal-to-accelerometer part against the v1 env's own accelerometer: SMILE (rigid)
    flown centred to 3 s, then a held gimbal command of 1 % of the limit for 15 control periods; the
    change of the observation's accel_z (times g0) against a flight with the gimbal centred, within 3 %
    of its largest value (the linear step response), the gyro's change likewise and the angle of attack's
    (the simulator's flight condition) within 5 %."""
    import gymnasium as gym

    from lvgym.baselines.design.linearize import operating_point
    from lvgym.baselines.design.target import design_env
    from lvgym.envs.layouts import G0

    t0, k, amp = 3.0, 15, 0.01
    env_id, opts = design_env("smile", "v1")

    def fly(a: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        env = gym.make(env_id, model="rigid", wind="none", **opts)
        obs, _ = env.reset(seed=0)
        u = env.unwrapped
        ia, ig = u.observation_layout.index("accel_z"), u.observation_layout.index("pitch_rate_error")
        zero = np.zeros(env.action_space.shape, np.float32)
        while float(u.state.sim.t[0]) < t0 - 0.5 * float(u.task.control_dt_s):
            obs, *_ = env.step(zero)
        act = zero.copy()
        act[0] = a
        def alpha() -> float:
            return float(np.ravel(u.sim.conditions(u.state.sim, "alpha"))[0])

        acc, gyro, al = [obs[ia] * G0], [obs[ig]], [alpha()]
        for _ in range(k):
            obs, *_ = env.step(act)
            acc.append(obs[ia] * G0)
            gyro.append(obs[ig])
            al.append(alpha())
        return np.array(acc), np.array(gyro), np.array(al), float(u.gimbal_limit)

    a1, g1, al1, limit = fly(amp)
    a0, g0, al0, _ = fly(0.0)
    g = LO.load_plant(operating_point("smile", t0, "rigid", protocol="v1"), "pitch")
    t = np.arange(k + 1) * g.dt
    cmd = np.r_[np.ones(k), 0.0] * amp * limit
    for env_change, out, tol in ((a1 - a0, 2, 0.03), (g1 - g0, 0, 0.03), (al1 - al0, 1, 0.05)):
        _, lin = control.forced_response(LO._sub(g, out, 0), T=t, U=cmd)
        assert np.max(np.abs(env_change)) > 0
        assert np.max(np.abs(lin - env_change)) < tol * np.max(np.abs(env_change))
