"""The flight computer's linear plant (lvgym.baselines.design.flightloop) against the nonlinear v1 env it models."""

import warnings

import control
import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.baselines.design import flightloop as F
from lvgym.baselines.design import linearize as L

T0 = 28.8


def _env_response(model: str, pulse: float, steps: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Pitch rate error seen by the policy after a gimbal pulse at T0, less that of the zero action
    (the same seed: the sensor noise cancels), and the gimbal limit [rad]."""
    out = []
    for amp in (0.0, pulse):
        env = gym.make("lvgym/SmileAscent-v1", model=model, wind="none")
        env.reset(seed=0)
        zero = np.zeros(2, np.float32)
        info = {"time": 0.0}
        while info["time"] < T0 - 0.01:
            _, _, _, _, info = env.step(zero)
        i = env.unwrapped.observation_layout.index("pitch_rate_error")
        seq = []
        for k in range(steps):
            a = np.array([amp if k < 5 else 0.0, 0.0], np.float32)
            obs, *_ = env.step(a)
            seq.append(float(obs[i]))
        out.append(np.array(seq))
        limit = float(env.unwrapped.gimbal_limit)
    return out[1] - out[0], np.array([pulse if k < 5 else 0.0 for k in range(steps)]), limit


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_flight_plant_predicts_the_env(model):
    """A 0.05 deg gimbal pulse of 5 control periods at max q: the discrete model (servo, vehicle, slope
    at the IMU, gyro filters, hold, one period of delay) gives the sampled gyro's response within 5 % of
    its peak over 0.6 s, and with the delay the first sample after the pulse sees nothing."""
    steps = 30
    d_env, action, limit = _env_response(model, 0.01, steps)
    op = L.operating_point("smile", T0, model, protocol="v1")
    g = F.flight_plant(op)
    assert g.dt == pytest.approx(0.02) and F.control_timing(op) == (0.02, 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        y = control.forced_response(g, U=np.r_[action * limit, 0.0]).outputs
    y = np.ravel(y)[1:]                                 # obs after step k is y[k + 1]
    peak = np.max(np.abs(d_env))
    assert peak > 1e-4                                   # rad/s: a response well above round-off
    assert abs(d_env[0]) < 1e-3 * peak and abs(y[0]) < 1e-12
    np.testing.assert_allclose(y, d_env, atol=0.05 * peak)


def test_gyro_slope_and_modes():
    """The non-rigid plant's gyro output carries the bending slope rate at the IMU (the rigid one does
    not), its modes are sorted into slosh and bending, and the delay adds one pole at the origin."""
    op = L.operating_point("smile", T0, "nonrigid", protocol="v1")
    bare = L.linearize(op=op)
    gyro = F.vehicle_with_gyro_output(op)
    names = list(gyro.state_labels)
    k = names.index("eta_dot_z0")
    assert gyro.C[0, k] == pytest.approx(-F.imu_slopes(op)[0]) and bare.C[0, k] == 0.0
    modes = F.mode_frequencies(op)
    assert len(modes["slosh"]) >= 2 and all(10.0 < w < 25.0 for w in modes["slosh"])
    assert 50.0 < modes["bending"][0] < 100.0                 # rad/s: the first bending mode at max q
    n0 = F.flight_plant(op, delay_steps=0).nstates
    assert F.flight_plant(op).nstates == n0 + 1


def test_charts_write_figures_and_margins(tmp_path):
    """The charts command writes one figure per thrusting row, skips a coast row, and its margins are
    those of linearize.margins on the flight computer's loop (the rigid row at 28.8 s of the shipped
    rigid-designed schedule: the v1 loop's delay and filters leave it under 2 dB of gain margin)."""
    import json

    import yaml

    from lvgym.baselines.design import charts

    sched = tmp_path / "two.yaml"
    sched.write_text(yaml.safe_dump({"variable": "time", "rows": [
        {"time_s": 28.8, "kp": 0.0491, "ki": 0.3526, "kd": 0.1196, "n": 500.0},
        {"time_s": 48.0, "kp": 0.0491, "ki": 0.3526, "kd": 0.1196, "n": 500.0}]}))
    assert charts.main(["--schedule", str(sched), "--out", str(tmp_path)]) == 0
    out = tmp_path / "smile_v1_two"
    assert (out / "loop_28.8s.png").stat().st_size > 10_000 and not (out / "loop_48s.png").exists()
    doc = json.loads((out / "margins.json").read_text())
    assert [r["time_s"] for r in doc["rows"]] == [28.8]
    op = L.operating_point("smile", 28.8, "rigid", protocol="v1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = L.margins(charts.open_loop(op, (0.0491, 0.3526, 0.1196, 500.0)))
    assert doc["rows"][0]["rigid"]["gain_margin_db"] == pytest.approx(m["gain_margin_db"], abs=1e-3)
    assert 0.0 < m["gain_margin_db"] < 2.0


def test_the_charts_of_a_flex_schedule_close_the_loop_through_its_filters(tmp_path):
    """A gs-pid-flex schedule's charts include each row's structural filter: they give the margins its
    design recorded (SMILE's shipped flex schedule, its first row), which the bare PID does not."""
    from lvgym.baselines.design import charts
    from lvgym.baselines.pid import GainSchedule

    sched = GainSchedule.load("smile_flex")
    row, value = sched.meta["rows"][0], sched.points[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        filtered = charts.row_loops("smile", "v1", float(row["time_s"]), sched.gains(value), None,
                                    sched.filter_at(value))
        bare = charts.row_loops("smile", "v1", float(row["time_s"]), sched.gains(value), None, None)
    for model in ("rigid", "nonrigid"):
        want = row["margins"][f"{model}_pitch"]
        got = filtered[model]["margins"]
        assert got["gain_margin_db"] == pytest.approx(want["gain_margin_db"], abs=0.01)
        assert got["phase_margin_deg"] == pytest.approx(want["phase_margin_deg"], abs=0.01)
    assert abs(bare["nonrigid"]["margins"]["gain_margin_db"] - row["margins"]["nonrigid_pitch"]["gain_margin_db"]) > 1.0
