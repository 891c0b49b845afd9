"""Intervals and paired comparisons of benchmark results (scipy and rliable).

A benchmark number without its uncertainty says little: these functions give the interval of a summary
over seeds, the paired comparison of two policies flown on the same seeds (the suites pair them: the same
seed is the same wind, dispersions and sensor noise for every policy), and rliable's aggregate estimates
(interquartile mean, probability of improvement) for results over several training seeds.

- :func:`bootstrap_ci`: a percentile-BCa bootstrap interval of a statistic over episodes
  (``scipy.stats.bootstrap``).
- :func:`paired`: two policies on the same seeds: the mean difference with its bootstrap interval, the
  wins, the Wilcoxon signed-rank test and the paired t-test (``scipy.stats``).
- :func:`iqm` and :func:`probability_of_improvement`: rliable's stratified-bootstrap estimates over
  ``(runs, episodes)`` score matrices (Agarwal et al., "Deep RL at the edge of the statistical precipice",
  NeurIPS 2021), lower scores being better here (rate errors), so the probability of improvement of ``a``
  over ``b`` is ``P(a < b)``.

Every random draw has a seed (``seed``), so an interval is reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import stats

__all__ = ["PairedResult", "bootstrap_ci", "iqm", "paired", "probability_of_improvement"]

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


def _matrix(scores: Any) -> np.ndarray:
    m = np.asarray(scores, dtype=float)
    if m.ndim == 1:
        m = m[None, :]
    if m.ndim != 2:
        raise ValueError(f"scores of shape {m.shape}: (runs, episodes), e.g. (training seeds, test seeds)")
    return m


def iqm(scores: dict[str, Any], level: float = LEVEL, reps: int = REPS, seed: int = 0) -> dict[str, tuple[float, float, float]]:
    """Interquartile mean of each policy's ``(runs, episodes)`` scores with rliable's stratified bootstrap
    interval: ``{name: (iqm, low, high)}``."""
    from rliable import library as rly
    from rliable import metrics

    np.random.seed(seed)                              # rliable draws from numpy's global generator
    data = {k: _matrix(v) for k, v in scores.items()}
    point, ci = rly.get_interval_estimates(data, lambda s: np.array([metrics.aggregate_iqm(s)]), reps=reps,
                                           confidence_interval_size=level)
    return {k: (float(point[k][0]), float(ci[k][0, 0]), float(ci[k][1, 0])) for k in data}


def probability_of_improvement(a: Any, b: Any, level: float = LEVEL, reps: int = REPS,
                               seed: int = 0) -> tuple[float, float, float]:
    """rliable's probability that a run of ``a`` scores lower (better) than one of ``b``, with its
    interval: ``(p, low, high)``; ``a`` and ``b`` are ``(runs, episodes)`` matrices of the same episodes."""
    from rliable import library as rly
    from rliable import metrics

    np.random.seed(seed)
    x, y = _matrix(a), _matrix(b)
    if x.shape[1] != y.shape[1]:
        raise ValueError(f"{x.shape[1]} and {y.shape[1]} episodes: the same episodes (tasks) for both")
    # rliable's probability of improvement counts x > y as an improvement: negate (lower is better here)
    point, ci = rly.get_interval_estimates({"p": (-x, -y)}, metrics.probability_of_improvement, reps=reps,
                                           confidence_interval_size=level)
    return float(point["p"]), float(np.ravel(ci["p"])[0]), float(np.ravel(ci["p"])[1])
