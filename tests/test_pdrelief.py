"""gs-pd-relief: the soft attitude loop without integral (lvgym.baselines.design.pdrelief)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import lvgym
import lvgym.baselines  # noqa: F401  (registers the classical designs)
from lvgym.baselines.design.linearize import analytic_rigid, operating_point, rigid_terms
from lvgym.baselines.design.pdrelief import main, pd_rows, row_times, schedule
from lvgym.baselines.design.target import privileged_flyer
from lvgym.baselines.pid import SCHEDULES, GainSchedule
from lvgym.benchmark import get_suite
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import build_policy
from lvgym.errors import ConfigError

SMILE_V1 = Path(lvgym.__file__).resolve().parent / "vehicles" / "smile_v1.yaml"


def test_the_rows_by_hand():
    """kp = 2 zeta w / P and k_theta = w / (2 zeta): a control power of 16 /s^2 at w = 2 /s, zeta = 1 gives
    0.25 rad per rad/s and 1 /s; at zeta = 0.5, 0.125 and 2 /s."""
    rows = pd_rows((10.0, 20.0), np.array([16.0, 20.0]))
    assert rows[0] == {"time_s": 10.0, "kp": 0.25, "ki": 0.0, "kd": 0.0, "attitude_gain": 1.0,
                       "control_power_per_s2": 16.0}
    assert rows[1]["kp"] == 0.2
    assert pd_rows((1.0,), np.array([16.0]), bandwidth=2.0, damping=0.5)[0]["kp"] == 0.125
    assert pd_rows((1.0,), np.array([16.0]), bandwidth=2.0, damping=0.5)[0]["attitude_gain"] == 2.0
    assert row_times(((2.0, 4.0), (10.0, 10.5)), 1.0) == (2.5, 3.5, 10.25)
    for kwargs, key in (({"bandwidth": -1.0}, "bandwidth"), ({"damping": float("nan")}, "damping")):
        with pytest.raises(ConfigError) as exc:
            pd_rows((1.0,), np.array([16.0]), **kwargs)
        assert exc.value.key == key
    with pytest.raises(ConfigError, match="control_power"):
        pd_rows((1.0, 2.0), np.array([16.0, 0.0]))
    with pytest.raises(ConfigError, match="row_step"):
        row_times(((0.0, 1.0),), 0.0)


def test_the_control_power_is_the_rigid_models_and_the_shipped_schedule_its_design():
    """The rigid terms are those the textbook model uses (its B column: s T / m and s T l / J), and the shipped
    schedule's row at 28.5 s is what the design gives there now."""
    op = operating_point("smile", 28.5, "rigid", protocol="v1", policy=privileged_flyer())
    terms = rigid_terms(op)
    B = np.asarray(analytic_rigid(op).B).ravel()
    assert B[0] == pytest.approx(terms["vectored_thrust"] / terms["mass"], rel=1e-12)
    assert B[2] == pytest.approx(terms["vectored_thrust"] * terms["arm"] / terms["inertia"], rel=1e-12)
    assert 1e5 < terms["thrust"] < 1e6 and 0.0 < terms["arm"] < 10.0          # SMILE's boost: hundreds of kN
    doc = schedule("smile", times=(28.5,))
    shipped = yaml.safe_load((SCHEDULES / "smile_pd_relief.yaml").read_text())
    row = next(r for r in shipped["rows"] if r["time_s"] == 28.5)
    assert doc["rows"][0] == row
    assert row["kp"] == pytest.approx(4.0 / B[2], rel=1e-5)
    assert shipped["interpolation"] == "nearest" and shipped["variable"] == "time"
    assert all(r["ki"] == 0.0 and r["kd"] == 0.0 and r["attitude_gain"] == 1.0 for r in shipped["rows"])
    GainSchedule.load(SCHEDULES / "smile_pd_relief.yaml")                    # the PID family reads it


def test_the_registered_policy_flies_the_law():
    """gs-pd-relief's action is -kp (rate error + k_theta attitude error) over the gimbal limit, with kp of the
    row nearest the time, and no memory: the same observation twice gives the same action."""
    env = get_suite("smile-v2-maxq-gust").conditions[0].make_env()
    policy = build_policy(resolve_policy("gs-pd-relief"), env)
    policy.reset()
    obs, info = env.reset(seed=0)
    rows = yaml.safe_load((SCHEDULES / "smile_pd_relief.yaml").read_text())["rows"]
    for _ in range(600):                                                    # to 12 s
        obs, _, _, _, info = env.step(policy.act(obs, info))
    kp = min(rows, key=lambda r: abs(r["time_s"] - info["time"]))["kp"]
    names = list(env.unwrapped.func.observation_layout.names)
    probe = obs.copy()
    probe[names.index("pitch_rate_error")], probe[names.index("pitch_attitude_error")] = 0.002, 0.01
    probe[names.index("yaw_rate_error")], probe[names.index("yaw_attitude_error")] = -0.001, 0.0
    limit = float(env.unwrapped.func.gimbal_limit)
    want = np.array([-kp * (0.002 + 0.01), -kp * (-0.001)]) / limit
    np.testing.assert_allclose(policy.act(probe, info), want, rtol=1e-5)
    np.testing.assert_allclose(policy.act(probe, info), want, rtol=1e-5)


def test_the_command_designs_for_a_vehicle_file_and_refuses_bad_values(tmp_path):
    out = tmp_path / "mine.yaml"
    assert main(["--vehicle", str(SMILE_V1), "--times", "5", "20", "--out", str(out)]) == 0
    doc = yaml.safe_load(out.read_text())
    assert [r["time_s"] for r in doc["rows"]] == [5.0, 20.0]
    assert all(0.05 < r["kp"] < 1.0 for r in doc["rows"])
    assert out.read_text().startswith("# gs-pd-relief schedule of")
    with pytest.raises(SystemExit, match="--fly = 'rows'"):
        main(["--fly", "rows", "--out", str(tmp_path / "x.yaml")])
    with pytest.raises(SystemExit, match="--out .*--overwrite"):                # a shipped schedule
        main(["--out", str(SCHEDULES / "smile_pd_relief.yaml")])
    assert not (tmp_path / "x.yaml").exists()
