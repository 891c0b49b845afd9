"""Policies compared on the same seeds: paired tests, the IQM and the probability of improvement.

Within every (suite, condition) each policy is compared with a reference policy: a named one
(``reference``), else the best-ranked one of that condition (:func:`.metrics.rank`: failure rate, then
mean score). The seeds of a suite are common random numbers (the same wind, dispersions and noise for
every policy), so the comparison is paired (:func:`.stats.paired`); the aggregate estimates of Agarwal
et al. (2021) (:func:`.stats.iqm`, :func:`.stats.probability_of_improvement`) take each policy's episodes
as the runs of one task, so the interval comes from resampling the episodes.

Rows of :func:`compare` (lower is better for every metric compared; ``metric`` is ``score`` by default):

======================  ===========================================================================
suite, condition,       what is compared; ``reference`` is the policy it is compared with (a row of the
policy, reference       reference itself carries its IQM and no test)
n                       common seeds
mean, reference_mean    mean of ``metric`` of the policy and of the reference over the common seeds
diff, diff_ci_low,      mean of the per-seed difference policy - reference with its bootstrap interval
diff_ci_high
wins, ties, losses      seeds where the policy is better than (lower), equal to, worse than the reference
p_wilcoxon, p_ttest     two-sided Wilcoxon signed-rank and paired t-test p-values
iqm, iqm_ci_low,        interquartile mean of the policy's ``metric`` over its episodes with its
iqm_ci_high             stratified-bootstrap interval
p_improvement, _ci_low, probability of improvement: that an episode of the policy scores lower than one of the
_ci_high                reference (0.5: neither is better), with its interval
======================  ===========================================================================

:func:`run_groups` aggregates policies that are training runs of one agent (labels ``<agent>-s<seed>``,
as ``experiments.rigid_vs_nonrigid_training.robustness`` names them): the IQM over the ``(runs, episodes)`` matrix.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from .metrics import per_seed, rank
from .stats import REPS, iqm, paired, probability_of_improvement

__all__ = ["RUN_LABEL", "compare", "protocol_metric", "run_groups"]

#: a policy label that names one training run of an agent: ``<agent>-s<training seed>``
RUN_LABEL = re.compile(r"^(?P<agent>.+)-s(?P<seed>\d+)$")


def protocol_metric(records: Sequence[dict[str, Any]]) -> str:
    """The score a suite's ``records`` are compared by: ``score_v2`` when every record carries it (protocol v2,
    which charges an unflyable flight as a failure), else ``score`` (protocols v0 and v1)."""
    return "score_v2" if records and all("score_v2" in r for r in records) else "score"


def compare(records: Sequence[dict[str, Any]], summary: Sequence[dict[str, Any]], metric: str = "score",
            reference: str | None = None, reps: int = REPS) -> list[dict[str, Any]]:
    """Rows of the paired comparison (module docstring) of every policy of every (suite, condition)
    with ``reference`` (a policy label; None or a label the condition lacks: its best-ranked policy)."""
    values = per_seed(records, metric)
    out: list[dict[str, Any]] = []
    ordered = rank([dict(r) for r in summary])
    conditions = list(dict.fromkeys((r["suite"], r["condition"]) for r in ordered))
    for suite, cond in conditions:
        rows = [r for r in ordered if (r["suite"], r["condition"]) == (suite, cond)]
        names = [r["policy"] for r in rows]
        ref = reference if reference in names else names[0]
        ref_values = values[(suite, cond, ref)]
        series = {p: np.array(list(values[(suite, cond, p)].values()), dtype=float) for p in names}
        estimates = iqm({p: x[:, None] for p, x in series.items()}, reps=reps)
        for r in rows:
            pol = r["policy"]
            mine = values[(suite, cond, pol)]
            common = sorted(set(mine) & set(ref_values))
            row: dict[str, Any] = {"suite": suite, "condition": cond, "policy": pol, "rank": r["rank"],
                                   "reference": ref, "metric": metric, "n": len(common)}
            a = np.array([mine[s] for s in common], dtype=float)
            b = np.array([ref_values[s] for s in common], dtype=float)
            row["mean"] = float(a.mean()) if a.size else math.nan
            row["reference_mean"] = float(b.mean()) if b.size else math.nan
            nan = {k: math.nan for k in ("diff", "diff_ci_low", "diff_ci_high", "p_wilcoxon", "p_ttest",
                                         "p_improvement", "p_improvement_ci_low", "p_improvement_ci_high")}
            row.update(nan, wins=0, ties=0, losses=0)
            if pol != ref and common:
                p = paired(a, b)
                row.update(diff=p.mean_diff, diff_ci_low=p.ci_low, diff_ci_high=p.ci_high, wins=p.wins, ties=p.ties,
                           losses=p.n - p.wins - p.ties, p_wilcoxon=p.p_wilcoxon, p_ttest=p.p_ttest)
                poi = probability_of_improvement(a[:, None], b[:, None], reps=reps)
                row.update(p_improvement=poi[0], p_improvement_ci_low=poi[1], p_improvement_ci_high=poi[2])
            row["iqm"], row["iqm_ci_low"], row["iqm_ci_high"] = estimates[pol]
            out.append(row)
    return out


def run_groups(records: Sequence[dict[str, Any]], metric: str = "score",
               reps: int = REPS) -> list[dict[str, Any]]:
    """Per (suite, condition, agent) whose policies are at least two training runs (labels
    :data:`RUN_LABEL`) flown on the same seeds: ``runs``, ``episodes``, the mean of ``metric`` and
    the IQM over the ``(runs, episodes)`` matrix with its stratified-bootstrap interval."""
    values = per_seed(records, metric)
    agents: dict[tuple[Any, Any, str], list[str]] = {}
    for suite, cond, pol in values:
        m = RUN_LABEL.match(pol)
        if m:
            agents.setdefault((suite, cond, m.group("agent")), []).append(pol)
    out = []
    for (suite, cond, agent), pols in agents.items():
        if len(pols) < 2:
            continue
        common = sorted(set.intersection(*(set(values[(suite, cond, p)]) for p in pols)))
        if not common:
            continue
        matrix = np.array([[values[(suite, cond, p)][s] for s in common] for p in pols], dtype=float)
        point, low, high = iqm({agent: matrix}, reps=reps)[agent]
        out.append({"suite": suite, "condition": cond, "agent": agent, "metric": metric, "runs": len(pols),
                    "episodes": len(common), "mean": float(matrix.mean()), "iqm": point, "iqm_ci_low": low,
                    "iqm_ci_high": high})
    return out
