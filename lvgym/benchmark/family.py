"""The launcher family's table: a family suite's flights (:data:`~.suites.SUITES_FAMILY`: a rigid and a
non-rigid condition per test vehicle) gathered over its vehicles, per model and policy.

Per (suite, model, policy), over the vehicles x wind seeds the policy flew: the share of failed flights, the
share of failed or unflyable ones (v2's flyability rule), the mean ``score_v2``, each with a 95 % interval,
and the vehicles it held (no failed or unflyable flight). The intervals come from a crossed bootstrap that
resamples the vehicles and the wind seeds (every vehicle flies the same seeds): a family's spread between
vehicles is most of the uncertainty, and an interval over the seeds alone would hide it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from .suites import SUITES_FAMILY

__all__ = ["REPS", "crossed_interval", "family_room", "family_rows", "family_table"]

#: bootstrap replicates of the crossed intervals
REPS = 2000


def crossed_interval(values: np.ndarray | Sequence[np.ndarray], statistic: Callable[..., float] | None = None,
                     reps: int = REPS, level: float = 0.95, seed: int = 0) -> tuple[float, float]:
    """The ``level`` percentile interval of ``statistic`` (default: the mean) of ``values`` (vehicles x seeds,
    or a sequence of such matrices paired cell by cell, ``statistic`` then taking one resample of each) under
    a bootstrap that resamples the rows (vehicles) and the columns (seeds) independently."""
    mats = [np.asarray(values, float)] if isinstance(values, np.ndarray) else [np.asarray(m, float) for m in values]
    stat = statistic or (lambda m: float(m.mean()))
    rng = np.random.RandomState(seed)
    n_v, n_s = mats[0].shape
    out = np.empty(reps)
    for k in range(reps):
        cells = np.ix_(rng.randint(0, n_v, n_v), rng.randint(0, n_s, n_s))
        out[k] = stat(*(m[cells] for m in mats))
    a = (1.0 - level) / 2.0
    return float(np.quantile(out, a)), float(np.quantile(out, 1.0 - a))


#: a family suite's records by (suite, model, policy), then vehicle (the condition's group), then seed
Cells = dict[tuple[str, str, str], dict[str, dict[int, Mapping[str, Any]]]]


def _cells(records: Iterable[Mapping[str, Any]]) -> Cells:
    """The records of the family suites (:data:`Cells`), in order of appearance; others are left out."""
    cells: Cells = {}
    for r in records:
        if r.get("suite") in SUITES_FAMILY and "score_v2" in r:
            cells.setdefault((r["suite"], r["model"], r["policy"]), {}).setdefault(r["group"], {})[int(r["seed"])] = r
    return cells


def _matrix(per_vehicle: Mapping[str, Mapping[int, Mapping[str, Any]]], vehicles: Sequence[str], seeds: Sequence[int],
            key: str) -> np.ndarray:
    return np.array([[float(per_vehicle[v][s][key]) for s in seeds] for v in vehicles])


def family_room(records: Iterable[Mapping[str, Any]], kinds: Mapping[str, str]) -> list[dict[str, Any]]:
    """Per (family suite, model): the best causal policy (``kinds``: label -> kind, as
    :func:`~.headline.policy_kind`; causal: neither ``privileged`` nor ``none``, the zero policy's; the best: the
    fewest failed or unflyable flights, then the lowest mean score_v2), the privileged reference, and the room
    ``1 - score(privileged) / score(best)`` on the vehicles and seeds both flew, with its crossed interval."""
    cells = _cells(records)
    rows = family_rows(records)
    out = []
    for suite, model in dict.fromkeys((r["suite"], r["model"]) for r in rows):
        here = [r for r in rows if (r["suite"], r["model"]) == (suite, model)]
        causal = [r for r in here if kinds.get(r["policy"], "other") not in ("privileged", "none")]
        ref = [r for r in here if kinds.get(r["policy"]) == "privileged"]
        if not causal or not ref:
            continue
        best = min(causal, key=lambda r: (r["bad"], r["score_v2"]))
        per = {p: cells[(suite, model, p)] for p in (best["policy"], ref[0]["policy"])}
        vehicles = sorted(set(per[best["policy"]]) & set(per[ref[0]["policy"]]))
        seeds = sorted(set.intersection(*(set(p[v]) for p in per.values() for v in vehicles)))
        b, p = (_matrix(per[name], vehicles, seeds, "score_v2") for name in (best["policy"], ref[0]["policy"]))
        lo, hi = crossed_interval((b, p), lambda x, y: 1.0 - float(y.mean()) / float(x.mean()))
        out.append({"suite": suite, "model": model, "best": best["policy"], "reference": ref[0]["policy"],
                    "room": 1.0 - float(p.mean()) / float(b.mean()), "room_low": lo, "room_high": hi})
    return out


def family_rows(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One row per (family suite, model, policy) of ``records`` (others are left out), in order of
    appearance: ``suite``, ``model``, ``policy``, ``vehicles``, ``seeds``; ``failed``, ``bad`` (failed or
    unflyable) and ``score_v2``, each as the mean with ``_low`` and ``_high``; ``held`` (vehicles without a
    bad flight). Only the seeds every vehicle flew count (a crossed design)."""
    out = []
    for (suite, model, policy), per_vehicle in _cells(records).items():
        seeds = sorted(set.intersection(*(set(v) for v in per_vehicle.values())))
        vehicles = list(per_vehicle)
        grid = [[per_vehicle[v][s] for s in seeds] for v in vehicles]
        metrics = {"failed": np.array([[bool(r["failed"]) for r in row] for row in grid], float),
                   "bad": np.array([[bool(r["failed"]) or not bool(r.get("flyable", True)) for r in row]
                                    for row in grid], float),
                   "score_v2": np.array([[float(r["score_v2"]) for r in row] for row in grid])}
        row: dict[str, Any] = {"suite": suite, "model": model, "policy": policy, "vehicles": len(vehicles),
                               "seeds": len(seeds), "held": int((metrics["bad"].sum(axis=1) == 0).sum())}
        for name, m in metrics.items():
            lo, hi = crossed_interval(m) if m.size else (float("nan"), float("nan"))
            row.update({name: float(m.mean()) if m.size else float("nan"), f"{name}_low": lo, f"{name}_high": hi})
        out.append(row)
    return out


def family_table(rows: Sequence[Mapping[str, Any]], rooms: Sequence[Mapping[str, Any]] = ()) -> list[str]:
    """:func:`family_rows` as Markdown lines, ranked per suite and model by the bad share, then score_v2;
    then the room of each suite and model (:func:`family_room`), when given."""
    lines = ["| suite | model | policy | vehicles held | failed [95 % CI] | failed or unflyable [95 % CI] | "
             "score_v2 [rad], mean [95 % CI] |", "|---|---|---|---:|---:|---:|---:|"]
    order = sorted(rows, key=lambda r: (r["suite"], r["model"] != "rigid", r["bad"], r["score_v2"]))
    for r in order:
        pct = "{:.0f} % [{:.0f}, {:.0f}]".format
        lines.append(f"| {r['suite']} | {r['model']} | {r['policy']} | {r['held']} of {r['vehicles']} | "
                     f"{pct(100 * r['failed'], 100 * r['failed_low'], 100 * r['failed_high'])} | "
                     f"{pct(100 * r['bad'], 100 * r['bad_low'], 100 * r['bad_high'])} | "
                     f"{r['score_v2']:.3f} [{r['score_v2_low']:.3f}, {r['score_v2_high']:.3f}] |")
    if rooms:
        lines += ["", "| suite | model | best causal | room [95 % CI] against the privileged reference |",
                  "|---|---|---|---:|"]
        lines += [f"| {r['suite']} | {r['model']} | {r['best']} | {100 * r['room']:.0f} % [{100 * r['room_low']:.0f}, "
                  f"{100 * r['room_high']:.0f}] |" for r in rooms]
    return lines
