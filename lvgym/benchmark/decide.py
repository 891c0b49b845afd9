"""The statistics that decide between two policies of protocol v2, from episode records (``score_v2``,
``failed``, ``flyable``; lower scores are better):

- :func:`rates`: the failed and the unflyable rate of a policy with their exact (Clopper-Pearson) 95 %
  intervals (:func:`~.stats.clopper_pearson`);
- :func:`gain`: the relative gain ``1 - mean(a) / mean(b)`` of policy ``a`` over ``b`` on the seeds both flew,
  with its paired bootstrap interval (:func:`~.stats.relative_gain`: the seed indices resampled jointly);
- :func:`both_survived`: both policies' mean ``score_v2`` on the flights that neither lost (neither failed nor
  unflyable), with their count: the comparison of the flying, apart from the comparison of the losses;
- :func:`by_fault`: per kind of in-flight fault (smile-v2-faults; a record's ``fault`` is the kind and the axis,
  e.g. ``effectiveness pitch``), each policy's mean ``score_v2``, its flights lost and the median over the seeds
  of its per-seed score ratio to the suite's reference (``score_v2`` of the policy over the reference's on the
  same seed), and :func:`fault_table`, its Markdown lines.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from .stats import clopper_pearson, relative_gain

__all__ = ["both_survived", "by_fault", "fault_kind", "fault_table", "gain", "lost", "rates"]

Row = Mapping[str, Any]


def lost(record: Row) -> bool:
    """A flight lost under protocol v2: failed or unflyable."""
    return bool(record["failed"]) or not bool(record.get("flyable", True))


def _of(records: Iterable[Row], suite: str, condition: str, policy: str) -> dict[int, Row]:
    return {int(r["seed"]): r for r in records
            if r["suite"] == suite and r["condition"] == condition and r["policy"] == policy}


def rates(records: Iterable[Row], suite: str, condition: str, policy: str) -> dict[str, Any]:
    """``n``; ``failed``, ``failed_low``, ``failed_high`` and ``unflyable``, ``unflyable_low``,
    ``unflyable_high`` (rates with their Clopper-Pearson 95 % intervals); ``lost`` (failed or unflyable) with
    its interval too, of ``policy``'s flights of ``condition`` of ``suite``."""
    mine = list(_of(records, suite, condition, policy).values())
    out: dict[str, Any] = {"n": len(mine)}
    counts = {"failed": sum(bool(r["failed"]) for r in mine),
              "unflyable": sum(not bool(r.get("flyable", True)) for r in mine), "lost": sum(lost(r) for r in mine)}
    for name, k in counts.items():
        out[name], out[f"{name}_low"], out[f"{name}_high"] = clopper_pearson(k, len(mine))
        out[f"{name}_count"] = k
    return out


def _common(records: Sequence[Row], suite: str, condition: str, a: str, b: str) -> tuple[list[Row], list[Row]]:
    x, y = _of(records, suite, condition, a), _of(records, suite, condition, b)
    seeds = sorted(set(x) & set(y))
    return [x[s] for s in seeds], [y[s] for s in seeds]


def gain(records: Sequence[Row], suite: str, condition: str, a: str, b: str, metric: str = "score_v2",
         seed: int = 0) -> dict[str, Any]:
    """``n`` (common seeds), ``mean_a``, ``mean_b`` and ``gain``, ``gain_low``, ``gain_high``: the relative
    gain of ``a`` over ``b`` on ``metric`` with its paired bootstrap 95 % interval (NaNs without common seeds)."""
    x, y = _common(records, suite, condition, a, b)
    if not x:
        return {"n": 0, "mean_a": math.nan, "mean_b": math.nan, "gain": math.nan, "gain_low": math.nan,
                "gain_high": math.nan}
    va, vb = [float(r[metric]) for r in x], [float(r[metric]) for r in y]
    g, lo, hi = relative_gain(va, vb, seed=seed)
    return {"n": len(x), "mean_a": float(np.mean(va)), "mean_b": float(np.mean(vb)), "gain": g, "gain_low": lo,
            "gain_high": hi}


def both_survived(records: Sequence[Row], suite: str, condition: str, a: str, b: str,
                  metric: str = "score_v2") -> dict[str, Any]:
    """``n`` (the common seeds neither policy lost: neither failed nor unflyable), ``of`` (the common seeds),
    ``mean_a`` and ``mean_b`` (their mean ``metric`` on those seeds; NaN without any)."""
    x, y = _common(records, suite, condition, a, b)
    kept = [(p, q) for p, q in zip(x, y) if not lost(p) and not lost(q)]
    mean = (lambda v: float(np.mean(v)) if v else math.nan)                     # noqa: E731
    return {"n": len(kept), "of": len(x), "mean_a": mean([float(p[metric]) for p, _ in kept]),
            "mean_b": mean([float(q[metric]) for _, q in kept])}


def fault_kind(record: Row) -> str:
    """The kind of a record's in-flight fault (``effectiveness pitch`` -> ``effectiveness``; ``none``)."""
    return str(record.get("fault") or "none").split()[0]


def by_fault(records: Sequence[Row], references: Mapping[str, str], metric: str = "score_v2") -> list[dict[str, Any]]:
    """Per (suite, condition, policy, fault kind) of the records that carry ``fault`` (in order of
    appearance; kinds sorted): ``n``, ``mean`` of ``metric``, ``lost`` (flights failed or unflyable),
    ``reference`` (``references[suite]``, the suite's reference) and ``median_ratio`` (the median over the
    kind's seeds of the policy's ``metric`` over the reference's on the same seed; NaN without the reference,
    seeds whose reference score is not positive left out)."""
    faulted = [r for r in records if "fault" in r]
    out = []
    keys = list(dict.fromkeys((r["suite"], r["condition"], r["policy"]) for r in faulted))
    for suite, cond, pol in keys:
        mine = _of(faulted, suite, cond, pol)
        ref_name = references.get(suite, "")
        ref = _of(faulted, suite, cond, ref_name) if ref_name else {}
        for kind in sorted({fault_kind(r) for r in mine.values()}):
            seeds = [s for s, r in mine.items() if fault_kind(r) == kind]
            ratios = [float(mine[s][metric]) / float(ref[s][metric]) for s in seeds
                      if s in ref and float(ref[s][metric]) > 0.0]
            out.append({"suite": suite, "condition": cond, "policy": pol, "fault": kind, "n": len(seeds),
                        "mean": float(np.mean([float(mine[s][metric]) for s in seeds])),
                        "lost": sum(lost(mine[s]) for s in seeds), "reference": ref_name,
                        "median_ratio": statistics.median(ratios) if ratios else math.nan})
    return out


def fault_table(rows: Sequence[Row]) -> list[str]:
    """Lines of the table of :func:`by_fault`'s rows: per condition and policy, a cell per fault kind with
    the mean ``score_v2``, the median ratio to the reference and the flights lost; none without rows."""
    if not rows:
        return []
    kinds = sorted({r["fault"] for r in rows})
    out = ["| condition | policy | " + " | ".join(kinds) + " |", "|---|---|" + "---:|" * len(kinds)]
    cells: dict[tuple[str, str], dict[str, Row]] = {}
    for r in rows:
        cells.setdefault((r["condition"], r["policy"]), {})[r["fault"]] = r
    for (cond, pol), mine in cells.items():
        text = []
        for k in kinds:
            c = mine.get(k)
            if c is None:
                text.append("-")
                continue
            ratio = f"x{c['median_ratio']:.2f}" if math.isfinite(c["median_ratio"]) else "-"
            text.append(f"{c['mean']:.3f} ({ratio}), {c['lost']}/{c['n']}")
        out.append(f"| {cond.rsplit('/', 1)[-1]} | {pol} | " + " | ".join(text) + " |")
    return out
