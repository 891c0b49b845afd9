"""Intervals and paired comparisons (lvgym.benchmark.stats) against hand cases and known distributions."""

import numpy as np
import pytest

from lvgym.benchmark.stats import bootstrap_ci, iqm, paired, probability_of_improvement


def test_bootstrap_interval_covers_the_mean_and_shrinks_with_n():
    rng = np.random.default_rng(1)
    small, big = rng.normal(2.0, 1.0, 20), rng.normal(2.0, 1.0, 500)
    lo, hi = bootstrap_ci(small)
    assert lo < small.mean() < hi
    blo, bhi = bootstrap_ci(big)
    assert blo < 2.0 < bhi and (bhi - blo) < 0.5 * (hi - lo)
    # the normal-theory half-width 1.96 sigma / sqrt(n), within 15 %
    assert (bhi - blo) / 2 == pytest.approx(1.96 * big.std(ddof=1) / np.sqrt(big.size), rel=0.15)
    assert bootstrap_ci(small) == (lo, hi)                      # seeded: reproducible
    assert bootstrap_ci([3.0]) == (3.0, 3.0) and bootstrap_ci([1.0, 1.0]) == (1.0, 1.0)
    assert all(np.isnan(bootstrap_ci([])))


def test_paired_comparison_by_hand():
    a = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    b = a + np.array([0.5, 0.4, 0.6, 0.5, 0.3, 0.7])             # b is worse on every seed
    r = paired(a, b)
    assert r.n == 6 and r.wins == 6 and r.ties == 0
    assert r.mean_diff == pytest.approx(-0.5)
    assert r.ci_low < -0.5 < r.ci_high < 0.0
    assert r.p_wilcoxon == pytest.approx(0.03125)              # all 6 signs alike: 2 / 2^6
    assert r.p_ttest == pytest.approx(3.39e-4, rel=0.01)                # t = 0.5 / (0.1414 / sqrt 6) = 8.66, 5 dof
    same = paired(a, a)
    assert same.ties == 6 and same.p_wilcoxon == 1.0 and same.p_ttest == 1.0
    with pytest.raises(ValueError, match="one value per common seed"):
        paired(a, b[:3])


def test_rliable_estimates():
    rng = np.random.default_rng(0)
    good, bad = rng.normal(1.0, 0.1, (3, 40)), rng.normal(1.5, 0.1, (3, 40))
    out = iqm({"good": good, "bad": bad}, reps=300)
    assert out["good"][1] < out["good"][0] < out["good"][2] < out["bad"][1]
    p, lo, hi = probability_of_improvement(good, bad, reps=300)    # lower is better: good improves on bad
    assert p == pytest.approx(1.0) and hi <= 1.0
    p_rev, *_ = probability_of_improvement(bad, good, reps=300)
    assert p_rev == pytest.approx(0.0)
    p_tie, lo, hi = probability_of_improvement(good, good + 0.0, reps=300)
    assert p_tie == pytest.approx(0.5) and lo <= 0.5 <= hi
