"""Intervals and paired comparisons of benchmark results (numpy and scipy).

A benchmark number without its uncertainty says little: these functions give the interval of a summary
over seeds, the paired comparison of two policies flown on the same seeds (the suites pair them: the same
seed is the same wind, dispersions and sensor noise for every policy), and the aggregate estimates of
Agarwal et al., "Deep RL at the edge of the statistical precipice", NeurIPS 2021 (interquartile mean,
probability of improvement) for results over several training seeds.

- :func:`bootstrap_ci`: a percentile-BCa bootstrap interval of a statistic over episodes
  (``scipy.stats.bootstrap``).
- :func:`paired`: two policies on the same seeds: the mean difference with its bootstrap interval, the
  wins, the Wilcoxon signed-rank test and the paired t-test (``scipy.stats``).
- :func:`normalised`: a policy's score on a scale where the zero policy is 0 and a named reference 1, with
  a paired bootstrap interval over the seeds (all three flown on the same seeds).
- :func:`room`: the share of the best causal score that a privileged reference does without, with a
  paired bootstrap interval over the seeds.
- :func:`ratio`: the ratio of two means of paired values (non-rigid over rigid), with a paired bootstrap
  interval over the seeds.
- :func:`relative_gain`: the relative gain ``1 - mean(a) / mean(b)`` of one policy over another on the same
  seeds, with the percentile interval of a paired bootstrap (the seeds resampled jointly).
- :func:`clopper_pearson`: a rate of ``k`` events in ``n`` flights with its exact (Clopper-Pearson) interval
  (``scipy.stats.binomtest``): the interval of the failed and unflyable rates, which a bootstrap makes
  degenerate at 0 of n.
- :func:`iqm` and :func:`probability_of_improvement`: the interquartile mean (``scipy.stats.trim_mean``)
  and the probability of improvement (the Mann-Whitney U statistic over ``m n``, ``scipy.stats.mannwhitneyu``)
  over ``(runs, episodes)`` score matrices, with stratified-bootstrap percentile intervals that resample
  the runs within each episode, as the rliable library of that paper defines them (lvgym used rliable
  1.2.0 until its repository was archived; tests/test_stats.py checks these against its recorded numbers).
  Lower scores are better here (rate errors), so the probability of improvement of ``a`` over ``b`` is
  ``P(a < b)``.

Every random draw has a seed (``seed``), so an interval is reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import stats

__all__ = ["PairedResult", "bootstrap_ci", "clopper_pearson", "iqm", "normalised", "paired",
           "probability_of_improvement", "ratio", "relative_gain", "room"]

LEVEL = 0.95
REPS = 2000


def bootstrap_ci(values: Sequence[float], statistic: Callable[[np.ndarray], float] = np.mean, level: float = LEVEL,
                 reps: int = REPS, seed: int = 0) -> tuple[float, float]:
    """``(low, high)`` of a bootstrap interval (BCa, percentile for degenerate samples) of ``statistic``
    over ``values`` at confidence ``level``; ``(value, value)`` for one value or identical values, NaNs
    for none."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan
    if x.size == 1 or np.all(x == x[0]):
        v = float(statistic(x))
        return v, v
    fn = statistic if statistic in (np.mean, np.median) else (
        lambda s, axis=-1: np.apply_along_axis(statistic, axis, s))
    lo = hi = math.nan
    for method in ("BCa", "percentile"):               # BCa is undefined for some tiny samples
        with np.errstate(all="ignore"):
            res = stats.bootstrap((x,), fn, n_resamples=reps, confidence_level=level, method=method,
                                  random_state=np.random.default_rng(seed))
        lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
        if np.isfinite(lo) and np.isfinite(hi):
            break
    return lo, hi


@dataclass(frozen=True)
class PairedResult:
    """``a`` against ``b`` on ``n`` common seeds (lower is better): ``mean_diff`` = mean(a - b) with its
    bootstrap interval ``ci_low``, ``ci_high``; ``wins`` the seeds where a < b, ``ties`` where equal;
    ``p_wilcoxon`` (two-sided signed-rank) and ``p_ttest`` (two-sided paired t)."""

    n: int
    mean_a: float
    mean_b: float
    mean_diff: float
    ci_low: float
    ci_high: float
    wins: int
    ties: int
    p_wilcoxon: float
    p_ttest: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def paired(a: Sequence[float], b: Sequence[float], level: float = LEVEL, reps: int = REPS, seed: int = 0) -> PairedResult:
    """Compare two policies flown on the same seeds (``a[i]`` and ``b[i]`` are seed i's values)."""
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"paired values of shapes {x.shape} and {y.shape}: one value per common seed each")
    d = x - y
    lo, hi = bootstrap_ci(d, np.mean, level, reps, seed)
    nonzero = d[d != 0.0]
    p_w = float(stats.wilcoxon(nonzero).pvalue) if nonzero.size >= 1 else 1.0
    p_t = float(stats.ttest_rel(x, y).pvalue) if d.size > 1 and np.std(d) > 0 else (1.0 if np.all(d == 0) else 0.0)
    return PairedResult(int(d.size), float(x.mean()), float(y.mean()), float(d.mean()), lo, hi,
                        int(np.sum(d < 0)), int(np.sum(d == 0)), p_w, p_t)


def normalised(policy: Sequence[float], zero: Sequence[float], reference: Sequence[float], level: float = LEVEL,
               reps: int = REPS, seed: int = 0) -> tuple[float, float, float]:
    """``(value, low, high)``: the normalised score ``(mean(zero) - mean(policy)) / (mean(zero) -
    mean(reference))`` of per-seed scores (lower is better) flown on the same seeds, so that the zero policy
    scores 0, the reference 1 and a policy better than the reference more than 1; its interval is the
    percentile interval of the same ratio over ``reps`` resamplings of the seeds (the three policies' values
    of a seed kept together, so the interval holds the uncertainty of all three means). NaNs when the
    reference does not beat the zero policy (no scale)."""
    x, z, r = (np.asarray(v, dtype=float) for v in (policy, zero, reference))
    if not x.shape == z.shape == r.shape or x.ndim != 1 or x.size == 0:
        raise ValueError(f"per-seed scores of shapes {x.shape}, {z.shape}, {r.shape}: one value per common seed each")
    scale = z.mean() - r.mean()
    if not scale > 0.0:
        return math.nan, math.nan, math.nan
    value = float((z.mean() - x.mean()) / scale)
    idx = np.random.default_rng(seed).integers(0, x.size, (reps, x.size))
    zs, rs, xs = z[idx].mean(axis=1), r[idx].mean(axis=1), x[idx].mean(axis=1)
    with np.errstate(all="ignore"):
        ratio = (zs - xs) / (zs - rs)
    ratio = ratio[np.isfinite(ratio) & (zs - rs > 0.0)]
    lo, hi = _percentile_interval(ratio, level) if ratio.size else (math.nan, math.nan)
    return value, lo, hi


def room(best: Sequence[float], reference: Sequence[float], level: float = LEVEL, reps: int = REPS,
         seed: int = 0) -> tuple[float, float, float]:
    """``(value, low, high)``: the room ``(mean(best) - mean(reference)) / mean(best)`` of per-seed scores
    (lower is better) flown on the same seeds: the share of the best causal score that a privileged
    ``reference`` does without (0: none; negative: the reference is worse). Its interval is the percentile
    interval of the same ratio over ``reps`` resamplings of the seeds (both values of a seed kept together).
    NaNs when ``mean(best)`` is not positive."""
    b, r = (np.asarray(v, dtype=float) for v in (best, reference))
    if not b.shape == r.shape or b.ndim != 1 or b.size == 0:
        raise ValueError(f"per-seed scores of shapes {b.shape}, {r.shape}: one value per common seed each")
    if not b.mean() > 0.0:
        return math.nan, math.nan, math.nan
    value = float((b.mean() - r.mean()) / b.mean())
    idx = np.random.default_rng(seed).integers(0, b.size, (reps, b.size))
    bs, rs = b[idx].mean(axis=1), r[idx].mean(axis=1)
    ok = bs > 0.0
    lo, hi = _percentile_interval((bs[ok] - rs[ok]) / bs[ok], level) if ok.any() else (math.nan, math.nan)
    return value, lo, hi


def ratio(a: Sequence[float], b: Sequence[float], level: float = LEVEL, reps: int = REPS,
          seed: int = 0) -> tuple[float, float, float]:
    """``(value, low, high)``: ``mean(a) / mean(b)`` of values flown on the same seeds (``a[i]`` and ``b[i]``
    seed i's), with the percentile interval of the same ratio over ``reps`` resamplings of the seeds (both
    values of a seed kept together). NaNs when ``mean(b)`` is not positive."""
    x, y = (np.asarray(v, dtype=float) for v in (a, b))
    if not x.shape == y.shape or x.ndim != 1 or x.size == 0:
        raise ValueError(f"paired values of shapes {x.shape} and {y.shape}: one value per common seed each")
    if not y.mean() > 0.0:
        return math.nan, math.nan, math.nan
    idx = np.random.default_rng(seed).integers(0, x.size, (reps, x.size))
    xs, ys = x[idx].mean(axis=1), y[idx].mean(axis=1)
    ok = ys > 0.0
    lo, hi = _percentile_interval(xs[ok] / ys[ok], level) if ok.any() else (math.nan, math.nan)
    return float(x.mean() / y.mean()), lo, hi


def relative_gain(a: Sequence[float], b: Sequence[float], level: float = LEVEL, reps: int = REPS,
                  seed: int = 0) -> tuple[float, float, float]:
    """``(value, low, high)``: the relative gain ``1 - mean(a) / mean(b)`` of policy ``a`` over policy ``b``
    (per-seed scores, lower is better, ``a[i]`` and ``b[i]`` flown on seed i: 0.3 is a 30 % lower mean score)
    with the percentile interval at ``level`` of the same gain over ``reps`` resamplings of the seed indices,
    both policies' values of a seed drawn together (``numpy.random.default_rng(seed).integers(0, n, (reps,
    n))``; a resample whose mean of ``b`` is not positive is dropped). NaNs when ``mean(b)`` is not positive:
    :func:`ratio`'s value and interval, mirrored (the percentile interval of ``1 - r`` is ``1 -`` that of ``r``)."""
    value, low, high = ratio(a, b, level, reps, seed)
    return 1.0 - value, 1.0 - high, 1.0 - low


def clopper_pearson(k: int, n: int, level: float = LEVEL) -> tuple[float, float, float]:
    """``(k / n, low, high)``: a rate of ``k`` events in ``n`` flights with its exact two-sided interval at
    ``level`` (Clopper-Pearson: ``scipy.stats.binomtest(k, n).proportion_ci(level, "exact")``); NaNs for
    ``n = 0``."""
    if int(n) == 0:
        return math.nan, math.nan, math.nan
    if not 0 <= int(k) <= int(n):
        raise ValueError(f"k = {k!r} events of n = {n!r} flights: 0 <= k <= n")
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="exact")
    return int(k) / int(n), float(ci.low), float(ci.high)


def _matrix(scores: Any) -> np.ndarray:
    m = np.asarray(scores, dtype=float)
    if m.ndim == 1:
        m = m[None, :]
    if m.ndim != 2:
        raise ValueError(f"scores of shape {m.shape}: (runs, episodes), e.g. (training seeds, test seeds)")
    return m


def _percentile_interval(replicates: np.ndarray, level: float) -> tuple[float, float]:
    """The percentile interval at confidence ``level`` of bootstrap ``replicates`` (numpy's linear
    interpolation between order statistics, as rliable's ``method="percentile"`` took it from ``arch``)."""
    alpha = (1.0 - level) / 2
    low, high = np.percentile(replicates, [100 * alpha, 100 * (1.0 - alpha)])
    return float(low), float(high)


def _stratified(scores: np.ndarray, reps: int, rng: np.random.RandomState) -> np.ndarray:
    """``reps`` stratified resamples ``(reps, runs, tasks)`` of a ``(runs, tasks)`` matrix: within each task
    (column) the runs are drawn with replacement, independently of the other tasks (rliable's
    ``StratifiedBootstrap``: the tasks are fixed, the runs are the sample)."""
    runs, tasks = scores.shape
    rows = rng.randint(0, runs, size=(reps, runs, tasks))
    return scores[rows, np.arange(tasks)]


def _iqm(scores: np.ndarray) -> np.ndarray:
    """Interquartile mean of each ``(..., runs, tasks)`` matrix: the mean of the middle half of its pooled
    scores (``scipy.stats.trim_mean``, 25 % cut from either end)."""
    return stats.trim_mean(scores.reshape(scores.shape[:-2] + (-1,)), 0.25, axis=-1)


def _improvement(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Probability that a run of ``x`` scores lower than a run of ``y`` (ties count one half) on a task,
    averaged over the tasks, of each pair of ``(..., runs, tasks)`` matrices: the Mann-Whitney U statistic
    of ``y`` against ``x`` over ``m n`` per task."""
    m, n = x.shape[-2], y.shape[-2]
    u = stats.mannwhitneyu(y, x, axis=-2, method="asymptotic").statistic   # pairs y > x, ties one half
    return np.mean(u / (m * n), axis=-1)


def iqm(scores: dict[str, Any], level: float = LEVEL, reps: int = REPS, seed: int = 0) -> dict[str, tuple[float, float, float]]:
    """Interquartile mean of each policy's ``(runs, episodes)`` scores with its stratified-bootstrap
    percentile interval: ``{name: (iqm, low, high)}``.

    The resampling indices come from one Mersenne-Twister stream seeded with ``seed``
    (``numpy.random.RandomState``), drawn for the policies in the order of ``scores``: the draws rliable
    made from numpy's global generator after ``np.random.seed(seed)``, so the intervals are the ones it gave
    (tests/test_stats.py checks them against recorded rliable numbers)."""
    rng = np.random.RandomState(seed)
    out = {}
    for name, value in scores.items():
        m = _matrix(value)
        out[name] = (float(_iqm(m)), *_percentile_interval(_iqm(_stratified(m, reps, rng)), level))
    return out


def probability_of_improvement(a: Any, b: Any, level: float = LEVEL, reps: int = REPS,
                               seed: int = 0) -> tuple[float, float, float]:
    """Probability that a run of ``a`` scores lower (better) than a run of ``b`` on an episode (task),
    averaged over the episodes, with its bootstrap percentile interval: ``(p, low, high)``; ``a`` and ``b``
    are ``(runs, episodes)`` matrices of the same episodes, their runs resampled independently within each
    episode (rliable's ``StratifiedIndependentBootstrap``; the stream as in :func:`iqm`, ``a``'s draws then
    ``b``'s in every replicate)."""
    x, y = _matrix(a), _matrix(b)
    if x.shape[1] != y.shape[1]:
        raise ValueError(f"{x.shape[1]} and {y.shape[1]} episodes: the same episodes (tasks) for both")
    rng = np.random.RandomState(seed)
    rows_x = np.empty((reps,) + x.shape, dtype=np.int64)
    rows_y = np.empty((reps,) + y.shape, dtype=np.int64)
    for r in range(reps):                              # interleaved, as rliable drew them
        rows_x[r] = rng.randint(0, x.shape[0], size=x.shape)
        rows_y[r] = rng.randint(0, y.shape[0], size=y.shape)
    tasks = np.arange(x.shape[1])
    replicates = _improvement(x[rows_x, tasks], y[rows_y, tasks])
    return (float(_improvement(x, y)), *_percentile_interval(replicates, level))
