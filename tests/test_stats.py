"""Intervals and paired comparisons (lvgym.benchmark.stats) against hand cases and known distributions."""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from lvgym.benchmark.stats import bootstrap_ci, iqm, normalised, paired, probability_of_improvement


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


def test_iqm_and_probability_of_improvement_order_policies():
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


def test_iqm_and_probability_of_improvement_by_hand():
    # 1..8 pooled over 2 runs x 4 episodes: the middle half 3, 4, 5, 6
    point, lo, hi = iqm({"c": [[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]]})["c"]
    assert point == 4.5 and 1.0 <= lo < 4.5 < hi <= 8.0
    # one run: the runs within an episode are the sample, so one run has no spread
    assert iqm({"one": [0.0, 1.0, 2.0, 3.0]})["one"] == (1.5, 1.5, 1.5)
    # per episode, runs of a score 1 and 3, runs of b 2 and 4: a is lower in 3 of the 4 pairs
    a, b = np.array([[1.0] * 4, [3.0] * 4]), np.array([[2.0] * 4, [4.0] * 4])
    assert probability_of_improvement(a, b)[0] == 0.75
    # a tie counts one half: a's 1, 3 against c's 1|5, 2|6, 3|7, 4|8: 2.5, 3, 3.5, 4 of 4 pairs
    c = np.array([[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]])
    assert probability_of_improvement(a, c)[0] == pytest.approx(np.mean([0.625, 0.75, 0.875, 1.0]), abs=1e-15)
    # the Mann-Whitney U statistic over m n, runs of different counts (3 against 2 on one episode)
    x, y = np.array([[0.1], [0.5], [0.9]]), np.array([[0.4], [0.6]])
    assert probability_of_improvement(x, y)[0] == pytest.approx(stats.mannwhitneyu(y[:, 0], x[:, 0]).statistic / 6)
    assert probability_of_improvement(x, y)[0] == pytest.approx(3 / 6)     # 0.1 < both, 0.5 < 0.6, 0.9 < none
    with pytest.raises(ValueError, match="the same episodes"):
        probability_of_improvement(a, c[:, :3])


def test_iqm_and_probability_of_improvement_are_seeded_and_leave_numpy_alone():
    rng = np.random.default_rng(2)
    x, y = rng.normal(0, 1, (4, 6)), rng.normal(0.3, 1, (5, 6))
    state = np.random.get_state()[1].copy()
    first = iqm({"x": x, "y": y}, seed=4), probability_of_improvement(x, y, seed=4)
    assert (iqm({"x": x, "y": y}, seed=4), probability_of_improvement(x, y, seed=4)) == first
    assert iqm({"x": x}, seed=5)["x"] != first[0]["x"]                 # another seed, other draws
    np.testing.assert_array_equal(np.random.get_state()[1], state)    # numpy's global generator untouched


# Numbers of rliable 1.2.0 (arch 7.2.0, numpy 2.4.6) on fixed matrices, recorded by
# tests/data/rliable_reference.py before rliable left the extras.
RLIABLE = json.loads((Path(__file__).parent / "data" / "rliable_reference.json").read_text(encoding="utf-8"))
MATRICES = {k: np.array(v) for k, v in RLIABLE["matrices"].items()}


def _cases() -> list:
    return ([pytest.param(c, id="iqm-" + "+".join(c["policies"])) for c in RLIABLE["iqm"]]
            + [pytest.param(c, id=f"poi-{c['a']}-{c['b']}") for c in RLIABLE["probability_of_improvement"]])


def _ours(case: dict, seed: int) -> dict[str, tuple[float, float, float]]:
    if "policies" in case:
        return iqm({p: MATRICES[p] for p in case["policies"]}, case["level"], case["reps"], seed)
    return {"p": probability_of_improvement(MATRICES[case["a"]], MATRICES[case["b"]], case["level"],
                                            case["reps"], seed)}


def _theirs(case: dict) -> dict[str, list[float]]:
    return case["rliable"] if "policies" in case else {"p": case["rliable"]}


@pytest.mark.parametrize("case", _cases())
def test_same_draws_as_rliable_same_numbers(case):
    # with rliable's seed, the same Mersenne-Twister draws: the same resamples, so the point estimates and
    # the interval ends agree to rounding (1e-12; they agree bit for bit with numpy 2.4 and scipy 1.17)
    ours, theirs = _ours(case, case["seed"]), _theirs(case)
    assert set(ours) == set(theirs)
    for name, want in theirs.items():
        np.testing.assert_allclose(ours[name], want, rtol=0, atol=1e-12, err_msg=name)


@pytest.mark.parametrize("case", _cases())
def test_other_draws_than_rliable_within_the_monte_carlo_error(case):
    # with another seed the resamples differ; the point estimates do not (1e-12), and each interval end
    # moves by the Monte-Carlo error of a bootstrap percentile. For B replicates, an end at tail
    # probability q = (1 - level) / 2 has a standard error of sqrt(q (1 - q) / B) / f, f the density of the
    # bootstrap distribution there; for a near-normal one that is sqrt(q (1 - q) / B) / (2 z phi(z)) of the
    # interval's width (z the normal quantile of 1 - q): 1.5 % of the width at B = 2000 and 95 %. Two
    # independent runs differ by sqrt(2) of that; the tolerance is 5 such standard errors (11 to 22 % of
    # the width here; over the seeds 1 to 40 the largest move was 0.70 of it).
    ours, theirs = _ours(case, case["seed"] + 1), _theirs(case)
    q = (1.0 - case["level"]) / 2
    z = stats.norm.ppf(1.0 - q)
    rel = np.sqrt(q * (1 - q) / case["reps"]) / (2 * z * stats.norm.pdf(z))
    for name, (point, lo, hi) in theirs.items():
        assert ours[name][0] == pytest.approx(point, rel=0, abs=1e-12)
        tol = 5 * np.sqrt(2) * rel * (hi - lo) + 1e-12
        assert abs(ours[name][1] - lo) <= tol and abs(ours[name][2] - hi) <= tol, (name, ours[name], (lo, hi), tol)


def test_normalised_score_by_hand():
    zero, ref = np.array([4.0, 6.0, 5.0]), np.array([1.0, 1.2, 0.8])          # means 5 and 1
    pol = np.array([2.0, 3.5, 3.5])                                             # mean 3: half way
    v, lo, hi = normalised(pol, zero, ref)
    assert v == pytest.approx(0.5) and lo <= 0.5 <= hi
    assert normalised(zero, zero, ref)[0] == 0.0 and normalised(ref, zero, ref)[0] == pytest.approx(1.0)
    assert normalised(ref - 0.5, zero, ref)[0] == pytest.approx(1.125)          # better than the reference
    assert np.isnan(normalised(pol, ref, zero)[0])                               # the reference no better than zero
    with pytest.raises(ValueError, match="one value per common seed"):
        normalised(pol, zero[:2], ref)


def test_normalised_interval_shrinks_with_seeds_and_is_seeded():
    rng = np.random.default_rng(0)
    widths = []
    for n in (10, 160):
        zero = 5.0 + rng.normal(0.0, 1.0, n)
        ref = 1.0 + 0.1 * (zero - 5.0) + rng.normal(0.0, 0.1, n)
        pol = 2.0 + 0.1 * (zero - 5.0) + rng.normal(0.0, 0.1, n)
        v, lo, hi = normalised(pol, zero, ref)
        assert lo < v < hi and v == pytest.approx(0.75, abs=0.1)
        widths.append(hi - lo)
        assert normalised(pol, zero, ref) == (v, lo, hi)
    assert widths[1] < 0.5 * widths[0]
