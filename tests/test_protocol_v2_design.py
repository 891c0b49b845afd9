"""The study behind protocol v2 (experiments/protocol_v2_design): its metrics against hand numbers, without
flying an env (the commands' ``--help`` is tests/test_experiments.py's)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from experiments.protocol_v2_design.design_wind import budget
from experiments.protocol_v2_design.flyability import command_metrics
from experiments.protocol_v2_design.privileged import stationary


def _flight(cmd: np.ndarray, rate: np.ndarray | None = None, dt: float = 0.02) -> dict:
    n = cmd.shape[0]
    return {"t": dt * np.arange(1, n + 1), "cmd": cmd, "on": np.ones(n, bool),
            "rate": np.zeros_like(cmd) if rate is None else rate, "dt": dt, "rate_limit": math.radians(30.0)}


def test_an_alternating_command_asks_twice_its_amplitude_per_period_and_reverses_every_sample():
    a, dt, n = math.radians(0.1), 0.02, 500
    cmd = np.tile(a * (-1.0) ** np.arange(n), (2, 1)).T            # both axes alternate every sample
    m = command_metrics(_flight(cmd, dt=dt), hf_hz=5.0)
    want = 2 * a / dt / math.radians(30.0)                         # 10 deg/s of 30
    assert m["cmd_rate"] == pytest.approx(want) and m["cmd_rate_peak"] == pytest.approx(want)
    assert m["cmd_over"] == 0.0 and m["reversal_hz"] == pytest.approx(1 / dt, rel=0.01)
    assert m["cmd_hf"] == pytest.approx(1.0, abs=1e-3)             # all of it at 25 Hz
    quiet = _flight(np.zeros_like(cmd), dt=dt)
    assert command_metrics(_flight(cmd, dt=dt), 5.0, quiet)["cmd_rate_noise"] == pytest.approx(want)


def test_a_slow_ramp_is_low_frequency_and_the_gimbal_travel_is_its_rate_integral():
    dt, n = 0.02, 1000
    cmd = np.tile(np.radians(0.5) * np.sin(2 * math.pi * 0.5 * dt * np.arange(n)), (2, 1)).T
    rate = np.full_like(cmd, math.radians(2.0))
    m = command_metrics(_flight(cmd, rate, dt), hf_hz=5.0)
    assert m["cmd_hf"] < 1e-3 and m["cmd_over"] == 0.0
    assert m["gimbal_rate"] == pytest.approx(2.0) and m["travel_deg"] == pytest.approx(2 * 2.0 * n * dt)
    assert m["at_limit"] == 0.0 and m["gimbal_acc"] == pytest.approx(0.0)


def test_stationary_figures_of_a_first_order_process():
    a, q, dt = 0.9, 0.19, 0.02                                     # var x = q / (1 - a^2) = 1
    y, u, du = stationary(np.array([[a]]), np.array([[q]]), np.array([[1.0]]), np.array([[2.0]]), dt)
    assert y == pytest.approx(1.0) and u == pytest.approx(2.0)
    assert du == pytest.approx(2.0 * math.sqrt(2.0 * (1 - a)) / dt)
    assert stationary(np.array([[1.1]]), np.array([[q]]), np.array([[1.0]]), np.array([[1.0]]), dt)[0] == math.inf


def test_the_wind_at_the_qalpha_limit():
    traj = {"qbar": np.array([500.0, 125e3]), "airspeed": np.array([50.0, 800.0])}
    lim = budget(traj, 250e3)
    assert lim[0] == math.inf and lim[1] == pytest.approx(800.0 * math.tan(math.radians(2.0)))


def test_fault_suites_add_one_kind_each_and_keep_v1_otherwise():
    from experiments.protocol_v2_design.fault_suite import fault_suites
    from lvgym.benchmark.suites import get_suite

    base = get_suite("smile-v1")
    suites = fault_suites(["none", "stuck"], (10.0, 20.0), models=["nonrigid"])
    assert [s.name for s in suites] == ["smile-v1+none", "smile-v1+stuck"] and {s.version for s in suites} == {"v2-draft"}
    none, stuck = suites[0].conditions[0], suites[1].conditions[0]
    v1 = [c for c in base.conditions if c.model == "nonrigid"][0]
    assert none.env_kwargs() == v1.env_kwargs()
    kw = stuck.env_kwargs()
    assert set(kw["randomize"]) == set(v1.randomize) | {"fault"}
    assert kw["fault_kinds"] == ("stuck",) and kw["fault_onset_s"] == (10.0, 20.0)


def test_normalise_puts_zero_at_0_and_the_reference_at_1():
    from lvgym.benchmark.metrics import normalise

    scores = {"zero": [5.0, 4.0, 6.0], "lqg": [1.0, 1.0, 1.0], "mine": [3.0, 2.5, 3.5]}
    records = [{"suite": "s", "condition": "s/rigid", "policy": p, "seed": i, "score_v2": v}
               for p, vs in scores.items() for i, v in enumerate(vs)]
    summary = [{"suite": "s", "condition": "s/rigid", "policy": p} for p in scores]
    normalise(summary, records, {"s": "lqg"})
    got = {r["policy"]: r["score_v2_norm"] for r in summary}
    assert got["zero"] == 0.0 and got["lqg"] == 1.0 and got["mine"] == pytest.approx(0.5)
    assert all(r["score_v2_norm_ci_low"] <= r["score_v2_norm"] <= r["score_v2_norm_ci_high"] for r in summary)
    untouched = [{"suite": "t", "condition": "t/rigid", "policy": "mine"}]
    assert "score_v2_norm" not in normalise(untouched, records, {"s": "lqg"})[0]


def test_the_privileged_sweep_names_its_variants_by_their_gains_and_relief():
    from experiments.protocol_v2_design.privileged_sweep import OFF, _variants

    specs = _variants([1.0, 1.5], ["off", "0.5,0.9"], [0])
    assert [s.name for s in specs] == ["priv-w1-roff-p0", "priv-w1-r0.5-0.9-p0", "priv-w1.5-roff-p0",
                                       "priv-w1.5-r0.5-0.9-p0"]
    assert dict(specs[1].kwargs) == {"bandwidth_radps": 1.0, "damping": 1.0, "relief": (0.5, 0.9),
                                     "preview_periods": 0}
    assert dict(specs[2].kwargs)["relief"] == OFF and OFF[0] > 1.0       # onset beyond the limit: no relief
    assert [dict(s.kwargs)["preview_periods"] for s in _variants([1.0], ["off"], [0, 5])] == [0, 5]
    from lvgym.errors import ConfigError
    with pytest.raises(ConfigError, match=r"reliefs = '0.5': off, or ONSET,FULL"):
        _variants([1.0], ["0.5"], [0])
