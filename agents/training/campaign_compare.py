"""A campaign's evaluation files and its comparison over the runs (:mod:`lvgym.agents.training.campaign`).

Each run and each baseline has its evaluation file ``<campaign>/evaluation/<label>.json``: the episode
records of the test seeds and the settings they were flown with (suites, episodes, seed set, mission time,
protocol). A file whose settings are the campaign's is not flown again; the missing ones are flown
together, by the benchmark's own batched evaluation (:func:`lvgym.benchmark.evaluate`).

The comparison (``comparison.md`` and ``comparison.json``), per suite, condition and configuration (and
per suite over all its conditions, ``all``; a family suite per flight model over its vehicles, then ``all``:
:func:`condition_groups`): the interquartile mean of the metric over the ``(training
seeds, test seeds)`` matrix with its stratified-bootstrap interval, the mean and the failure rate (on a
protocol v2 suite: failed or unflyable, as ``score_v2`` charges both), and
the probability of improvement over the best classical baseline of that row (the baseline of the lowest
mean metric; lower is better), with its interval (:mod:`lvgym.benchmark.stats`, Agarwal et al. 2021).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["comparison_rows", "comparison_table", "condition_groups", "evaluation_settings", "metric_of",
           "read_evaluation", "write_evaluation"]


def metric_of(metric: str, version: str) -> str:
    """The metric a suite of protocol ``version`` is compared by (``auto``: score_v2 from v2 on, else score)."""
    if metric != "auto":
        return metric
    from lvgym.benchmark.flyability import applies

    return "score_v2" if applies(version) else "score"


def evaluation_settings(evaluation: Any) -> dict[str, Any]:
    """What an evaluation file's records depend on, besides the policy (:class:`~.campaign_schema.Evaluation`)."""
    from lvgym.benchmark.suites import PROTOCOL_VERSION, SUITES

    return {"suites": {s: SUITES[s].version for s in evaluation.suites}, "episodes": evaluation.episodes,
            "seed_set": evaluation.seed_set, "mission_time_s": evaluation.mission_time_s,
            "protocol": PROTOCOL_VERSION}


def read_evaluation(path: Path, settings: Mapping[str, Any], stamp: Any = None) -> list[dict[str, Any]] | None:
    """The records of an evaluation file flown with ``settings`` (and the policy ``stamp``), else None."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if data.get("settings") != json.loads(json.dumps(settings)) or data.get("stamp") != stamp:
        return None
    return data["records"]


def write_evaluation(path: Path, label: str, settings: Mapping[str, Any], records: Sequence[Mapping[str, Any]],
                     stamp: Any = None) -> None:
    from lvgym.benchmark.results import atomic_write_text, json_text

    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json_text({"policy": label, "settings": dict(settings), "stamp": stamp,
                                       "records": list(records)}))


def _values(records: Sequence[Mapping[str, Any]], metric: str) -> dict[tuple[str, str, str], dict[int, tuple[float, bool]]]:
    """``{(suite, condition, policy): {seed: (metric, failed)}}``; with ``score_v2`` (protocol v2) an
    unflyable flight counts as failed, as the metric charges it."""
    out: dict[tuple[str, str, str], dict[int, tuple[float, bool]]] = {}
    for r in records:
        failed = bool(r.get("failed", False)) or (metric == "score_v2" and r.get("flyable") is False)
        out.setdefault((r["suite"], r["condition"], r["policy"]), {})[int(r["seed"])] = (
            float(r[metric]) if r.get(metric) is not None else math.nan, failed)
    return out


def _matrix(values: Mapping[tuple[str, str, str], Mapping[int, tuple[float, bool]]], suite: str,
            cells: Sequence[str], labels: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """The ``(policies, episodes)`` matrices of the metric and of the failures of ``labels`` on the seeds they
    share, the conditions ``cells`` side by side."""
    cols = [(c, s) for c in cells for s in sorted(set.intersection(*(set(values.get((suite, c, p), {}))
                                                                     for p in labels)))]
    v = np.array([[values[(suite, c, p)][s][0] for c, s in cols] for p in labels], dtype=float)
    f = np.array([[values[(suite, c, p)][s][1] for c, s in cols] for p in labels], dtype=float)
    return v, f


def condition_groups(suite: str, conditions: Sequence[str]) -> list[tuple[str, list[str]]]:
    """The comparison's cells of a suite: each condition, then ``all``. A family suite's conditions are its
    vehicles in each flight model (``family-v2/20000/rigid``): its cells are the models over every vehicle
    (``rigid, 20 vehicles``), then ``all``."""
    from lvgym.benchmark.suites import SUITES_FAMILY

    if suite not in SUITES_FAMILY:
        return [*((c, [c]) for c in conditions), ("all", list(conditions))]
    model = {c.name: c.model for c in SUITES_FAMILY[suite].conditions}
    by_model: dict[str, list[str]] = {}
    for c in conditions:
        by_model.setdefault(model[c], []).append(c)
    return [*((f"{m}, {len(cells)} vehicles", cells) for m, cells in by_model.items()), ("all", list(conditions))]


def comparison_rows(records: Sequence[Mapping[str, Any]], runs: Mapping[str, Sequence[str]],
                    baselines: Sequence[str], metric: str = "auto", reps: int = 2000) -> list[dict[str, Any]]:
    """The comparison's rows (module docstring): ``runs`` maps each configuration to its runs' labels."""
    from lvgym.benchmark.stats import iqm, probability_of_improvement
    from lvgym.benchmark.suites import SUITES

    rows: list[dict[str, Any]] = []
    suites = list(dict.fromkeys(r["suite"] for r in records))
    for suite in suites:
        m = metric_of(metric, SUITES[suite].version)
        values = _values([r for r in records if r["suite"] == suite], m)
        conditions = list(dict.fromkeys(c for (_, c, _) in values))
        for cond, cells in condition_groups(suite, conditions):
            base = {b: _matrix(values, suite, cells, [b]) for b in baselines if all((suite, c, b) in values for c in cells)}
            best = min(base, key=lambda b: float(np.nanmean(base[b][0]))) if base else None
            for config, labels in runs.items():
                labels = [p for p in labels if all((suite, c, p) in values for c in cells)]
                if not labels:
                    continue
                v, f = _matrix(values, suite, cells, labels)
                point, low, high = iqm({config: v}, reps=reps)[config]
                row = {"suite": suite, "condition": cond, "configuration": config, "metric": m, "runs": len(labels),
                       "episodes": int(v.shape[1]), "iqm": point, "iqm_ci_low": low, "iqm_ci_high": high,
                       "mean": float(np.nanmean(v)), "failure_rate": float(f.mean()), "baseline": best}
                row.update({k: math.nan for k in ("baseline_iqm", "baseline_mean", "p_improvement",
                                                  "p_improvement_ci_low", "p_improvement_ci_high")})
                if best is not None:
                    both = _matrix(values, suite, cells, [best, *labels])[0]               # on the seeds the baseline and runs share
                    bv, v2 = both[:1], both[1:]
                    row["baseline_iqm"] = iqm({best: bv}, reps=reps)[best][0]
                    row["baseline_mean"] = float(np.nanmean(bv))
                    p = probability_of_improvement(v2, bv, reps=reps)
                    row.update(p_improvement=p[0], p_improvement_ci_low=p[1], p_improvement_ci_high=p[2])
                rows.append(row)
    return rows


def _num(x: Any, digits: int = 4) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{digits}g}"


def comparison_table(rows: Sequence[Mapping[str, Any]], title: str) -> str:
    """The comparison as Markdown: one table per suite."""
    lines = [f"# {title}", "",
             "Per configuration: the interquartile mean (IQM) of the metric over training seeds x test seeds with its "
             "95 % stratified-bootstrap interval, the mean and the failure rate (`score_v2`: failed or unflyable); "
             "P(improvement): the probability that "
             "an episode of the configuration scores lower (better) than the best classical baseline's on the same "
             "seed set, with its interval (0.5: neither is better). Lower is better. `all`: every condition of the "
             "suite together.", ""]
    for suite in dict.fromkeys(r["suite"] for r in rows):
        part = [r for r in rows if r["suite"] == suite]
        lines += [f"## {suite} ({part[0]['metric']})", "",
                  "| condition | configuration | runs x episodes | IQM [95 % CI] | mean | failed | best baseline "
                  "(IQM) | P(improvement) [95 % CI] |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in part:
            base = f"{r['baseline']} ({_num(r['baseline_iqm'])})" if r["baseline"] else "-"
            poi = (f"{_num(r['p_improvement'], 3)} [{_num(r['p_improvement_ci_low'], 3)}, "
                   f"{_num(r['p_improvement_ci_high'], 3)}]") if r["baseline"] else "-"
            lines.append(f"| {r['condition']} | {r['configuration']} | {r['runs']} x {r['episodes']} | "
                         f"{_num(r['iqm'])} [{_num(r['iqm_ci_low'])}, {_num(r['iqm_ci_high'])}] | {_num(r['mean'])} | "
                         f"{100 * r['failure_rate']:.0f} % | {base} | {poi} |")
        lines.append("")
    return "\n".join(lines)
