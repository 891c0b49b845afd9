"""Metrics of the benchmark: per episode from a trajectory, per suite from the episode records.

Per episode (:func:`episode_metrics`; ``e`` is the absolute body-rate error ``|omega - omega_ref|`` at
the end of each control step, ``dt`` the control period; integrals are sums ``sum_k x_k dt``):

=========================  ========  ===========================================================
rate_error_rad             rad       cumulative pitch + yaw rate error ``int (e_pitch + e_yaw) dt``
                                     (the thesis's criterion; the headline metric)
rate_error_{roll,pitch,    rad       the same per axis
yaw}_rad
max_rate_radps             rad/s     largest pitch or yaw rate error of the episode
max_rate_{pitch,yaw}_radps rad/s     per axis
effort_rad_s               rad s     control effort ``int (|gimbal_pitch| + |gimbal_yaw|) dt``
                                     (actuator positions, not commands)
max_alpha_rad              rad       largest total angle of attack while the dynamic pressure is at
                                     least ``ALPHA_MIN_QBAR_PA`` = 5 kPa (at lift-off a slow vehicle
                                     in wind sees tens of degrees that no controller can change)
max_qalpha_pa_deg          Pa deg    largest dynamic pressure times total angle of attack
episode_return             -         sum of the env's rewards
duration_s                 s         flight time when the episode ended
failed, failure_reason     -         terminated before the mission end, and the env's reason
=========================  ========  ===========================================================

A failed episode's integrals stop at the failure: read them with its failure rate (the env's reward
charges the remaining time instead). NaN samples (a non-finite state) are ignored by the maxima (0.0
without any sample).

Every record also carries protocol v1's metrics (:mod:`.scoring`: the failure-charged ``score``, the
per-phase rate errors, what flexibility does, the q-alpha constraint cost); these definitions are v0's
and stay as they are.

Per suite, for each (suite, condition, policy) (:func:`summarize`): ``mean``, ``ci_low`` and ``ci_high``
(the 95 % BCa bootstrap interval of the mean over the seeds, :func:`.stats.bootstrap_ci`), ``std``
(sample standard deviation, ``ddof = 1``; 0 for one episode), ``cvar10`` (conditional value at risk at
10 %: the mean of the worst ``ceil(0.1 n)`` episodes, at least one; worst is the largest value, the
smallest for ``episode_return``), ``failure_rate`` (failed episodes over episodes, with its exact interval),
``n`` and ``rank``: the place of the policy within its (suite, condition), by failure rate, then by mean
``score`` (lower is better for both; :func:`rank_key`). Protocol v2's records (:mod:`.flyability`) add
``unflyable_rate`` and ``failure_rate_v2`` (failed or unflyable) and rank by that, then by ``score_v2``.

Degradation (:func:`degradation`), per policy, for each condition against the ``rigid`` condition of its
group (same env, wind, randomisation and seeds; only the flight model differs):
``ratio = mean_model / mean_rigid`` and ``diff = mean_model - mean_rigid`` of ``rate_error_rad``
(ratio 1.0 and diff 0 mean the policy does not notice slosh and bending), also for ``cvar10``, the
failure rates of both conditions and ``failure_rate_diff``; with the episode records, the paired test of
the per-seed differences (:func:`.stats.paired`). Of the ``score`` (``metric="score"``) the degradation
counts failures by itself: a failed episode is charged by its score for the mission it did not fly.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .flyability import V2_METRICS
from .scoring import PHASES
from .stats import bootstrap_ci, clopper_pearson, paired, ratio

#: metrics summarised per suite (all "lower is better" except those in :data:`HIGHER_IS_BETTER`)
SUMMARY_METRICS = ("rate_error_rad", "rate_error_pitch_rad", "rate_error_yaw_rad", "max_rate_radps", "effort_rad_s",
                   "max_alpha_rad", "max_qalpha_pa_deg", "episode_return")
#: protocol v1's metrics (:mod:`.scoring`), summarised beside v0's when the records carry them
V1_METRICS = ("score", *(f"rate_error_{p}_rad" for p in PHASES), "peak_eta", "peak_slosh_deg",
              "gyro_minus_body_rate_rad", "gimbal_rate_limit_s", "qalpha_cost_s")
HIGHER_IS_BETTER = frozenset({"episode_return"})
CVAR_LEVEL = 0.10
#: dynamic pressure [Pa] from which the angle of attack counts in ``max_alpha_rad``
ALPHA_MIN_QBAR_PA = 5e3
#: keys that identify a summary row
GROUP_KEYS = ("suite", "condition", "policy")


@dataclass
class Trajectory:
    """What one episode leaves, per control step ``k = 1 .. N`` (after the step).

    dt_s: control period [s]; rate_error_radps (N, 3): ``|omega - omega_ref|`` roll, pitch, yaw [rad/s];
    gimbal_rad (N, 2): actuator pitch, yaw [rad]; alpha_total_rad (N,) [rad]; qalpha_pa_deg (N,) [Pa deg];
    reward (N,); time_s (N,) [s]; qbar_pa (N,) [Pa]; termination: the env's reason ("" if none)."""

    dt_s: float
    rate_error_radps: np.ndarray
    gimbal_rad: np.ndarray
    alpha_total_rad: np.ndarray
    qalpha_pa_deg: np.ndarray
    reward: np.ndarray
    time_s: np.ndarray
    qbar_pa: np.ndarray
    termination: str = ""


def _nanmax(x: np.ndarray) -> float:
    """Largest value ignoring NaN; 0.0 when there is none (an episode that never reached the samples)."""
    x = np.asarray(x, dtype=float)
    return float(np.nanmax(x)) if x.size and not np.all(np.isnan(x)) else 0.0


def episode_metrics(traj: Trajectory) -> dict[str, Any]:
    """The per-episode metrics of ``traj`` (see the module docstring; SI units, radians)."""
    dt = float(traj.dt_s)
    e = np.abs(np.nan_to_num(np.asarray(traj.rate_error_radps, dtype=float), nan=0.0))
    g = np.abs(np.nan_to_num(np.asarray(traj.gimbal_rad, dtype=float), nan=0.0))
    integral = e.sum(axis=0) * dt if len(e) else np.zeros(3)
    peak = e.max(axis=0) if len(e) else np.zeros(3)
    return {
        "rate_error_rad": float(integral[1] + integral[2]),
        "rate_error_roll_rad": float(integral[0]),
        "rate_error_pitch_rad": float(integral[1]),
        "rate_error_yaw_rad": float(integral[2]),
        "max_rate_radps": float(max(peak[1], peak[2])),
        "max_rate_pitch_radps": float(peak[1]),
        "max_rate_yaw_radps": float(peak[2]),
        "effort_rad_s": float(g.sum() * dt),
        "max_alpha_rad": _nanmax(np.where(np.asarray(traj.qbar_pa) >= ALPHA_MIN_QBAR_PA, traj.alpha_total_rad, np.nan)),
        "max_qalpha_pa_deg": _nanmax(traj.qalpha_pa_deg),
        "episode_return": float(np.sum(traj.reward)),
        "duration_s": float(traj.time_s[-1]) if len(traj.time_s) else 0.0,
        "failed": bool(traj.termination),
        "failure_reason": str(traj.termination),
    }


def combined_record(v0: dict[str, Any], v1: dict[str, Any]) -> dict[str, Any]:
    """An episode's record: protocol v0's :func:`episode_metrics` and, beside them, v1's
    :func:`~.scoring.flight_metrics` (``score``, the per-phase rate errors, ...). ``rate_error_rad`` and the
    failure fields are defined once (v0's): v1's must agree bit for bit (``AssertionError`` otherwise)."""
    v1 = dict(v1)
    for key in ("rate_error_rad", "failed", "failure_reason"):
        value = v1.pop(key)
        if value != v0[key]:
            raise AssertionError(f"{key}: v1 {value!r} against v0 {v0[key]!r}")
    return {**v0, **v1}


def cvar(values: Sequence[float], level: float = CVAR_LEVEL, higher_is_worse: bool = True) -> float:
    """Conditional value at risk: the mean of the worst ``ceil(level * n)`` values (at least one).
    Worst is the largest when ``higher_is_worse``, else the smallest. NaN for no values."""
    x = np.sort(np.asarray(values, dtype=float))
    if x.size == 0:
        return math.nan
    k = max(1, math.ceil(level * x.size - 1e-9))
    return float(np.mean(x[-k:] if higher_is_worse else x[:k]))


def _std(x: np.ndarray) -> float:
    return float(np.std(x, ddof=1)) if x.size > 1 else 0.0


def rank_key(row: dict[str, Any]) -> tuple[float, float]:
    """The order of the tables: failure rate first, then the mean ``score`` (``rate_error_rad`` for
    records without it); lower is better for both. Rows of protocol v2 records (with ``score_v2_mean``)
    rank by ``failure_rate_v2`` (an unflyable flight counts as a failure, :mod:`.flyability`), then by the
    mean ``score_v2``."""
    if "score_v2_mean" in row:
        return (float(row["failure_rate_v2"]), float(row["score_v2_mean"]))
    return (float(row["failure_rate"]), float(row.get("score_mean", row["rate_error_rad_mean"])))


def rank(summary: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Set ``rank`` (1: the best, ties share the smaller place) in every row within its (suite,
    condition), by :func:`rank_key`; returns the rows sorted by suite and condition (in order of first
    appearance), then by rank (ties in order of appearance)."""
    groups: dict[tuple[Any, Any], list[dict[str, Any]]] = {}
    for r in summary:
        groups.setdefault((r["suite"], r["condition"]), []).append(r)
    out = []
    for rows in groups.values():
        ordered = sorted(rows, key=rank_key)
        for i, r in enumerate(ordered):
            same = i > 0 and rank_key(r) == rank_key(ordered[i - 1])
            r["rank"] = ordered[i - 1]["rank"] if same else i + 1
        out += ordered
    return out


def _rate_ci(events: np.ndarray) -> tuple[float, float]:
    """The Clopper-Pearson 95 % interval of the rate of the 0/1 ``events``."""
    return clopper_pearson(int(np.sum(events)), int(events.size))[1:]


def summarize(records: Iterable[dict[str, Any]], metrics: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """One row per (suite, condition, policy), in order of first appearance: ``n``, ``failure_rate``
    with its interval, the failure reasons with their counts, ``<metric>_mean``, ``_ci_low``,
    ``_ci_high``, ``_std``, ``_cvar10`` of every metric (default: :data:`SUMMARY_METRICS` and those of
    :data:`V1_METRICS` and :data:`~.flyability.V2_METRICS` the records carry) and ``rank`` (:func:`rank`).
    Records of protocol v2 (with ``flyable``) add ``unflyable_rate`` and ``failure_rate_v2`` (failed or
    unflyable), each with its interval. A rate's interval is the exact (Clopper-Pearson) one
    (:func:`~.stats.clopper_pearson`), every other the bootstrap's."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in records:
        groups.setdefault(tuple(r[k] for k in GROUP_KEYS), []).append(r)
    rows = []
    for key, recs in groups.items():
        first = recs[0]
        names = metrics if metrics is not None else SUMMARY_METRICS + tuple(m for m in V1_METRICS + V2_METRICS
                                                                              if m in first)
        row: dict[str, Any] = dict(zip(GROUP_KEYS, key))
        for k in ("group", "model", "wind"):
            if k in first:
                row[k] = first[k]
        row["n"] = len(recs)
        failed = np.array([bool(r["failed"]) for r in recs], dtype=float)
        row["failure_rate"] = float(np.mean(failed))
        row["failure_rate_ci_low"], row["failure_rate_ci_high"] = _rate_ci(failed)
        reasons: dict[str, int] = {}
        for r in recs:
            if r["failed"]:
                reasons[r["failure_reason"]] = reasons.get(r["failure_reason"], 0) + 1
        row["failure_reasons"] = "; ".join(f"{k}: {v}" for k, v in sorted(reasons.items()))
        if "flyable" in first:
            unflyable = np.array([not r["flyable"] for r in recs], dtype=float)
            row["unflyable_rate"] = float(np.mean(unflyable))
            row["unflyable_rate_ci_low"], row["unflyable_rate_ci_high"] = _rate_ci(unflyable)
            either = np.maximum(failed, unflyable)
            row["failure_rate_v2"] = float(np.mean(either))
            row["failure_rate_v2_ci_low"], row["failure_rate_v2_ci_high"] = _rate_ci(either)
        for m in names:
            x = np.array([r[m] for r in recs], dtype=float)
            row[f"{m}_mean"] = float(np.mean(x))
            row[f"{m}_ci_low"], row[f"{m}_ci_high"] = bootstrap_ci(x)
            row[f"{m}_std"] = _std(x)
            row[f"{m}_cvar10"] = cvar(x, CVAR_LEVEL, m not in HIGHER_IS_BETTER)
        rows.append(row)
    rank(rows)
    return rows


def normalise(summary: Sequence[dict[str, Any]], records: Iterable[dict[str, Any]], references: dict[str, str],
              metric: str = "score_v2") -> Sequence[dict[str, Any]]:
    """Add to each row of ``summary`` whose suite names a reference policy in ``references`` (suite name ->
    policy label) the normalised ``metric``: ``<metric>_norm`` with ``_norm_ci_low``, ``_norm_ci_high``
    (:func:`~.stats.normalised`: the zero policy 0, the reference 1, higher is better), over the seeds the
    row's policy, ``zero`` and the reference all flew in its condition. Rows without those flights are left
    as they are, and so is every row of a condition whose reference does not beat the zero policy (no
    scale). Returns ``summary``."""
    from .stats import normalised

    values = per_seed([r for r in records if metric in r], metric)
    for row in summary:
        ref = references.get(row["suite"])
        key = (row["suite"], row["condition"])
        z, r, x = (values.get((*key, p)) for p in ("zero", ref, row["policy"]))
        if not ref or not (z and r and x):
            continue
        common = sorted(set(z) & set(r) & set(x))
        if common:
            v, lo, hi = normalised([x[i] for i in common], [z[i] for i in common], [r[i] for i in common])
            if math.isfinite(v):                  # NaN: the reference does not beat the zero policy (no scale)
                row[f"{metric}_norm"], row[f"{metric}_norm_ci_low"], row[f"{metric}_norm_ci_high"] = v, lo, hi
    return summary


def per_seed(records: Iterable[dict[str, Any]], metric: str) -> dict[tuple[Any, ...], dict[int, float]]:
    """``{(suite, condition, policy): {seed: value}}`` of ``metric``."""
    out: dict[tuple[Any, ...], dict[int, float]] = {}
    for r in records:
        out.setdefault(tuple(r[k] for k in GROUP_KEYS), {})[int(r["seed"])] = float(r[metric])
    return out


def degradation(summary: Iterable[dict[str, Any]], metric: str = "rate_error_rad", reference_model: str = "rigid",
                records: Iterable[dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """Per (suite, group, policy), every non-reference condition against the reference (``rigid``) one:
    ``ratio = mean / mean_rigid``, ``diff = mean - mean_rigid`` (units of ``metric``), the same for the
    CVaR10, the failure rates (``failure_rate_<reference_model>``, ``failure_rate``) and
    ``failure_rate_diff``. A zero reference mean gives a ratio of ``inf`` (or NaN for 0/0). With
    ``records``: the paired comparison of the two conditions on their common seeds
    (:func:`.stats.paired` of ``metric``, model minus reference): ``paired_n``, ``diff_ci_low``,
    ``diff_ci_high``, ``p_wilcoxon``, ``p_ttest``, and the interval of the ratio of the means on those seeds
    (:func:`.stats.ratio`): ``ratio_ci_low``, ``ratio_ci_high`` (NaN without common seeds)."""
    rows = list(summary)
    seeds = per_seed(records, metric) if records is not None else None
    ref = {(r["suite"], r.get("group", r["suite"]), r["policy"]): r for r in rows if r.get("model") == reference_model}
    out = []
    for r in rows:
        key = (r["suite"], r.get("group", r["suite"]), r["policy"])
        if r.get("model") == reference_model or key not in ref:
            continue
        base = ref[key]
        d: dict[str, Any] = {"suite": r["suite"], "group": key[1], "policy": r["policy"], "metric": metric,
                             "reference": base["condition"], "condition": r["condition"], "model": r["model"]}
        for stat in ("mean", "cvar10"):
            a, b = float(r[f"{metric}_{stat}"]), float(base[f"{metric}_{stat}"])
            d[f"{reference_model}_{stat}"] = b
            d[f"{stat}"] = a
            d[f"{stat}_diff"] = a - b
            with np.errstate(divide="ignore", invalid="ignore"):
                d[f"{stat}_ratio"] = float(np.float64(a) / np.float64(b))
        d[f"failure_rate_{reference_model}"] = float(base["failure_rate"])
        d["failure_rate"] = float(r["failure_rate"])
        d["failure_rate_diff"] = float(r["failure_rate"] - base["failure_rate"])
        if seeds is not None:
            mine = seeds.get((r["suite"], r["condition"], r["policy"]), {})
            theirs = seeds.get((base["suite"], base["condition"], base["policy"]), {})
            common = sorted(set(mine) & set(theirs))
            d["paired_n"] = len(common)
            if common:
                a, b = [mine[s] for s in common], [theirs[s] for s in common]
                p = paired(a, b)
                d.update(diff_ci_low=p.ci_low, diff_ci_high=p.ci_high, p_wilcoxon=p.p_wilcoxon, p_ttest=p.p_ttest)
                d["ratio_ci_low"], d["ratio_ci_high"] = ratio(a, b)[1:]
            else:
                d.update(diff_ci_low=math.nan, diff_ci_high=math.nan, p_wilcoxon=math.nan, p_ttest=math.nan,
                         ratio_ci_low=math.nan, ratio_ci_high=math.nan)
        out.append(d)
    return out
