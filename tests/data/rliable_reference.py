"""How tests/data/rliable_reference.json was made: rliable's own estimates on fixed score matrices.

lvgym computed its interquartile means and probabilities of improvement with rliable until rliable left the
extras (its repository was archived in October 2025, and its dependency ``arch`` held pandas below 3);
:mod:`lvgym.benchmark.stats` now computes them on numpy and scipy, and tests/test_stats.py checks them
against the numbers this script recorded. It needs rliable, which lvgym no longer installs::

    pip install rliable==1.2.0 && python tests/data/rliable_reference.py

The matrices are drawn here from fixed seeds and stored in the JSON with rliable's point estimates and
percentile intervals, called the way lvgym called rliable before: ``np.random.seed(seed)`` (rliable's
stratified bootstraps draw their resampling indices with ``np.random.choice``) and ``get_interval_estimates``
with ``metrics.aggregate_iqm``, or with ``metrics.probability_of_improvement`` on the negated scores (rliable
counts a higher score as the better one; lower is better in lvgym).
"""

from __future__ import annotations

import json
import sys
from importlib.metadata import version
from pathlib import Path

import numpy as np
from rliable import library as rly
from rliable import metrics

OUT = Path(__file__).with_suffix(".json")


def matrices() -> dict[str, np.ndarray]:
    """Score matrices ``(runs, tasks)``: continuous, tied, one task (lvgym's episodes as the runs of one task),
    one run, skewed."""
    rng = np.random.default_rng(20251001)
    return {
        "normal_3x40": rng.normal(1.0, 0.1, (3, 40)),
        "normal_3x40_worse": rng.normal(1.05, 0.1, (3, 40)),
        "ties_5x10": np.round(rng.normal(2.0, 1.0, (5, 10))),
        "ties_4x10": np.round(rng.normal(2.5, 1.0, (4, 10))),
        "episodes_50x1": rng.normal(0.6, 0.05, (50, 1)),
        "episodes_50x1_other": rng.normal(0.62, 0.05, (50, 1)),
        "one_run_1x20": rng.normal(0.0, 1.0, (1, 20)),
        "lognormal_10x3": rng.lognormal(0.0, 1.0, (10, 3)),
    }


IQM_CASES = [  # (policies, seed, reps, level): one call of lvgym's iqm with these policies in this order
    (["normal_3x40"], 0, 2000, 0.95),
    (["ties_5x10"], 0, 2000, 0.95),
    (["episodes_50x1"], 0, 2000, 0.95),
    (["one_run_1x20"], 0, 2000, 0.95),
    (["lognormal_10x3"], 3, 500, 0.9),
    (["normal_3x40", "normal_3x40_worse", "episodes_50x1"], 0, 2000, 0.95),   # one stream for all policies
]
POI_CASES = [  # (a, b, seed, reps, level): lvgym's probability_of_improvement(a, b)
    ("normal_3x40", "normal_3x40_worse", 0, 2000, 0.95),
    ("ties_5x10", "ties_4x10", 0, 2000, 0.95),
    ("episodes_50x1", "episodes_50x1_other", 0, 2000, 0.95),
    ("episodes_50x1", "episodes_50x1", 0, 500, 0.95),
    ("ties_4x10", "ties_5x10", 5, 1000, 0.9),
]


def rliable_iqm(data: dict[str, np.ndarray], seed: int, reps: int, level: float) -> dict[str, list[float]]:
    np.random.seed(seed)
    point, ci = rly.get_interval_estimates(data, lambda s: np.array([metrics.aggregate_iqm(s)]), reps=reps,
                                           confidence_interval_size=level)
    return {k: [float(point[k][0]), float(ci[k][0, 0]), float(ci[k][1, 0])] for k in data}


def rliable_poi(x: np.ndarray, y: np.ndarray, seed: int, reps: int, level: float) -> list[float]:
    np.random.seed(seed)
    point, ci = rly.get_interval_estimates({"p": (-x, -y)}, metrics.probability_of_improvement, reps=reps,
                                           confidence_interval_size=level)
    return [float(point["p"]), float(np.ravel(ci["p"])[0]), float(np.ravel(ci["p"])[1])]


def main() -> None:
    mats = matrices()
    out = {
        "made_by": "tests/data/rliable_reference.py",
        "versions": {p: version(p) for p in ("rliable", "arch", "numpy", "scipy")} | {"python": sys.version.split()[0]},
        "matrices": {k: v.tolist() for k, v in mats.items()},
        "iqm": [{"policies": pols, "seed": seed, "reps": reps, "level": level,
                 "rliable": rliable_iqm({p: mats[p] for p in pols}, seed, reps, level)}
                for pols, seed, reps, level in IQM_CASES],
        "probability_of_improvement": [{"a": a, "b": b, "seed": seed, "reps": reps, "level": level,
                                        "rliable": rliable_poi(mats[a], mats[b], seed, reps, level)}
                                       for a, b, seed, reps, level in POI_CASES],
    }
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
