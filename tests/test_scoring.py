"""Protocol v1's episode metrics (lvgym.benchmark.scoring) against hand-made logs and a real flight."""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.benchmark import play_episode
from lvgym.benchmark.policy import ZeroPolicy
from lvgym.benchmark.scoring import PHASES, FlightColumns, FlightFacts, flight_metrics

FACTS = FlightFacts(dt_s=0.5, mission_time_s=10.0, failure_penalty_rad_per_s=0.1, qalpha_limit_pa_deg=100.0,
                    gimbal_rate_limit_radps=1.0)


def _metrics(n: int, e: float, fail_at: int | None = None) -> dict:
    """flight_metrics of a hand-made flight of ``n`` steps of 0.5 s, pitch and yaw rate errors ``e``."""
    events = {6: [(3.0, "stage 'a' burnout")], 10: [(5.0, "stage 'b' ignition")]}
    k = np.arange(1, n + 1)
    q = np.array([[0.0, 50.0, 90.0, 100.0, 85.0, 40.0, 10.0][min(j - 1, 6)] for j in k])
    columns = FlightColumns(
        time_s=0.5 * k, rate_error_radps=np.tile([9.0, e, e], (n, 1)), qbar_pa=q,
        qalpha_pa_deg=np.where(k == 3, 85.0, 10.0), gimbal_rate_radps=np.array([[1.0 if j == 2 else 0.2, 0.0] for j in k]),
        gyro_minus_body_radps=None, eta=np.tile([[0.0, -0.02], [0.01, 0.0]], (n, 1, 1)),
        slosh_angles_rad=np.tile([[np.radians(3.0), np.nan]], (n, 1, 1)),
        events=[x for j in k for x in events.get(int(j), [])],
        termination="q-alpha beyond the structural limit" if fail_at in k else "")
    return flight_metrics(FACTS, columns)


def test_score_charges_a_failure_for_the_mission_left():
    ok = _metrics(20, 0.1)
    assert ok["rate_error_rad"] == pytest.approx(20 * 0.2 * 0.5)
    assert ok["score"] == ok["rate_error_rad"] and not ok["failed"]
    early = _metrics(4, 0.1, fail_at=4)                          # fails at 2 s of 10
    assert early["failed"] and early["rate_error_rad"] == pytest.approx(4 * 0.2 * 0.5)
    assert early["score"] == pytest.approx(early["rate_error_rad"] + 0.1 * 8.0)


def test_phases_partition_the_flight():
    m = _metrics(20, 0.1)
    assert sum(m[f"rate_error_{p}_rad"] for p in PHASES) == pytest.approx(m["rate_error_rad"])
    # qbar >= 80 of the peak 100 at steps 3-5 (1.5-2.5 s); burnout at 3 s, ignition at 5 s
    assert m["rate_error_max_q_rad"] == pytest.approx(3 * 0.1)
    assert m["rate_error_boost_rad"] == pytest.approx(3 * 0.1)    # 0.5, 1.0 and 3.0 s
    assert m["rate_error_coast_rad"] == pytest.approx(4 * 0.1)    # 3.5 .. 5.0 s
    assert m["rate_error_upper_rad"] == pytest.approx(10 * 0.1)


def test_flex_and_constraint_metrics():
    m = _metrics(20, 0.1)
    assert m["peak_eta"] == pytest.approx(0.02) and m["peak_slosh_deg"] == pytest.approx(3.0)
    assert m["gimbal_rate_limit_s"] == pytest.approx(0.5) and m["qalpha_cost_s"] == pytest.approx(0.5)


def test_a_real_flight_holds_together():
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="turbulence", randomize=["wind"])
    m = play_episode(ZeroPolicy(), env, 10_000)
    info = {"cumulative_rate_error": np.asarray(env.unwrapped.state.task.cum_error[0])}
    assert m["score"] >= m["rate_error_rad"] > 0
    assert sum(m[f"rate_error_{p}_rad"] for p in PHASES) == pytest.approx(m["rate_error_rad"], rel=1e-12)
    if not m["failed"]:
        assert all(m[f"rate_error_{p}_rad"] > 0 for p in PHASES)
        np.testing.assert_allclose(m["rate_error_rad"], info["cumulative_rate_error"][1:].sum(), rtol=1e-12)
    assert m["peak_slosh_deg"] > 0 and m["peak_eta"] > 0
