"""The statistics that decide (lvgym.benchmark.stats.relative_gain, clopper_pearson; lvgym.benchmark.decide)
against hand-computed cases."""

import math

import numpy as np
import pytest

from lvgym.benchmark.decide import both_survived, by_fault, fault_table, gain, rates
from lvgym.benchmark.metrics import summarize
from lvgym.benchmark.stats import clopper_pearson, relative_gain

A = [1.0, 2.0, 3.0, 2.0]            # mean 2
B = [2.0, 2.0, 4.0, 4.0]            # mean 3


def test_relative_gain_by_hand():
    value, _, _ = relative_gain(A, B)
    assert value == pytest.approx(1.0 - 2.0 / 3.0)                  # a 33 % lower mean score
    assert relative_gain(B, A)[0] == pytest.approx(1.0 - 3.0 / 2.0)  # -50 %: worse
    assert all(math.isnan(v) for v in relative_gain([1.0], [0.0]))


def test_relative_gain_fixed_resample():
    """reps=2 with seed 0: numpy's default_rng(0).integers(0, 4, (2, 4)) draws the seed indices [3, 2, 2, 1] and
    [1, 0, 0, 0]: A 2, 3, 3, 2 against B 4, 4, 4, 2 (gain 1 - 2.5/3.5 = 2/7), then A 2, 1, 1, 1 against B 2, 2, 2, 2
    (gain 1 - 1.25/2 = 3/8); the 95 % percentile interval interpolates between them at 2.5 % and 97.5 %."""
    assert np.random.default_rng(0).integers(0, 4, (2, 4)).tolist() == [[3, 2, 2, 1], [1, 0, 0, 0]]
    _, low, high = relative_gain(A, B, reps=2, seed=0)
    lo, hi = 2.0 / 7.0, 3.0 / 8.0
    assert low == pytest.approx(lo + 0.025 * (hi - lo)) and high == pytest.approx(lo + 0.975 * (hi - lo))


def test_relative_gain_interval_holds_the_value():
    rng = np.random.default_rng(3)
    b = rng.uniform(1.0, 2.0, 200)
    a = 0.7 * b + rng.normal(0.0, 0.05, 200)
    value, low, high = relative_gain(a, b)
    assert low < value < high and low < 0.3 < high and high - low < 0.05


def test_clopper_pearson_known_values():
    # 0 of 50: the upper bound 1 - 0.025^(1/50); 3 of 10 and 1 of 2: the published exact intervals
    assert clopper_pearson(0, 50) == pytest.approx((0.0, 0.0, 1.0 - 0.025 ** (1 / 50)))
    assert clopper_pearson(3, 10) == pytest.approx((0.3, 0.06674, 0.65245), abs=5e-5)
    assert clopper_pearson(1, 2) == pytest.approx((0.5, 0.01258, 0.98742), abs=5e-5)
    assert clopper_pearson(10, 10)[1] == pytest.approx(0.025 ** (1 / 10))
    with pytest.raises(ValueError, match="0 <= k <= n"):
        clopper_pearson(3, 2)


def _rec(policy, seed, score, failed=False, flyable=True, fault=None):
    r = {"suite": "s", "condition": "s/rigid", "policy": policy, "seed": seed, "score_v2": score, "failed": failed,
         "flyable": flyable, "group": "s", "model": "rigid", "wind": "none", "rate_error_rad": score, "score": score,
         "failure_reason": "q-alpha" if failed else "", "episode_return": 0.0}
    if fault is not None:
        r["fault"] = fault
    return r


def test_rates_both_survived_and_gain_by_hand():
    recs = [_rec("a", 0, 1.0), _rec("a", 1, 5.0, failed=True), _rec("a", 2, 1.0), _rec("a", 3, 2.0, flyable=False),
            _rec("b", 0, 2.0), _rec("b", 1, 2.0), _rec("b", 2, 3.0, failed=True), _rec("b", 3, 4.0)]
    r = rates(recs, "s", "s/rigid", "a")
    assert (r["n"], r["failed_count"], r["unflyable_count"], r["lost_count"]) == (4, 1, 1, 2)
    assert (r["failed"], r["failed_low"], r["failed_high"]) == pytest.approx(clopper_pearson(1, 4))
    both = both_survived(recs, "s", "s/rigid", "a", "b")           # seed 0 only: a lost 1 and 3, b lost 2
    assert (both["n"], both["of"], both["mean_a"], both["mean_b"]) == (1, 4, 1.0, 2.0)
    g = gain(recs, "s", "s/rigid", "a", "b")
    assert g["n"] == 4 and g["gain"] == pytest.approx(1.0 - 9.0 / 4 / (11.0 / 4))
    assert summarize(recs, ["score_v2"])[0]["failure_rate_ci_high"] == pytest.approx(clopper_pearson(1, 4)[2])


def test_by_fault_means_and_median_ratios():
    recs = [_rec("lqg", 0, 1.0, fault="thrust"), _rec("lqg", 1, 2.0, fault="gyro_bias pitch"),
            _rec("lqg", 2, 4.0, fault="gyro_bias yaw"),
            _rec("x", 0, 3.0, fault="thrust"), _rec("x", 1, 1.0, fault="gyro_bias pitch"),
            _rec("x", 2, 2.0, failed=True, fault="gyro_bias yaw")]
    rows = {(r["policy"], r["fault"]): r for r in by_fault(recs, {"s": "lqg"})}
    assert rows[("x", "gyro_bias")]["mean"] == pytest.approx(1.5) and rows[("x", "gyro_bias")]["lost"] == 1
    assert rows[("x", "gyro_bias")]["median_ratio"] == pytest.approx(0.5)     # 1/2 and 2/4
    assert rows[("x", "thrust")]["median_ratio"] == pytest.approx(3.0) and rows[("lqg", "thrust")]["n"] == 1
    lines = fault_table(by_fault(recs, {"s": "lqg"}))
    assert lines[0] == "| condition | policy | gyro_bias | thrust |"
    assert lines[3] == "| rigid | x | 1.500 (x0.50), 1/2 | 3.000 (x3.00), 0/1 |"
    assert by_fault([_rec("x", 0, 1.0)], {"s": "lqg"}) == []
