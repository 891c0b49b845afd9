"""The comparison as Markdown: per suite the ranked summary, the rate error per flight phase, the
rigid-to-non-rigid degradation and the paired comparison of the policies.

Every mean is printed with its 95 % bootstrap interval over the seeds as ``mean [low, high]``
(:func:`.metrics.summarize`). Rows of a condition are in the order of :func:`.metrics.rank`: failure
rate, then mean score (lower is better); protocol v2's rows by failed or unflyable, then ``score_v2``
(:func:`flyability_table`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from .decide import fault_table
from .metrics import rank
from .scoring import PHASES

__all__ = ["comparison_table", "degradation_table", "flyability_table", "headline_table", "markdown_table",
           "others_table", "phase_table", "run_groups_table", "summary_table"]

Row = Mapping[str, Any]


def _ci(row: Row, metric: str, fmt: str = ".4f", scale: float = 1.0) -> str:
    """``mean [low, high]`` of ``metric`` in ``row`` (times ``scale``); ``-`` when the row lacks it."""
    if f"{metric}_mean" not in row:
        return "-"
    m, lo, hi = (scale * float(row.get(f"{metric}_{k}", math.nan)) for k in ("mean", "ci_low", "ci_high"))
    return f"{m:{fmt}} [{lo:{fmt}}, {hi:{fmt}}]"


def _interval(mean: float, lo: float, hi: float, fmt: str = ".4f") -> str:
    return f"{mean:{fmt}} [{lo:{fmt}}, {hi:{fmt}}]"


def _pct(x: float) -> str:
    return f"{100.0 * x:.0f} %"


def _failures(row: Row) -> str:
    text = _pct(row["failure_rate"])
    if "failure_rate_ci_low" in row:
        text += f" [{100.0 * row['failure_rate_ci_low']:.0f}, {100.0 * row['failure_rate_ci_high']:.0f}]"
    return text + (f" ({row['failure_reasons']})" if row.get("failure_reasons") else "")


def _p(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x:.3g}"


def _short(condition: str) -> str:
    return condition.split("/")[-1]


def _suites(rows: Sequence[Row]) -> list[str]:
    return list(dict.fromkeys(r["suite"] for r in rows))


def _of_suite(rows: Sequence[Row], suite: str) -> list[Row]:
    return [r for r in rows if r["suite"] == suite]


def summary_table(summary: Sequence[Row]) -> list[str]:
    """Lines of one suite's ranked table (condition x policy)."""
    deg = math.degrees
    out = ["| condition | policy | rank | failures [95 % CI] | score [rad] | rate error [rad] | CVaR10 [rad] "
           "| max rate [deg/s] | effort [deg s] | max alpha [deg] | max q-alpha [kPa deg] |",
           "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rank([dict(r) for r in summary]):
        out.append(f"| {_short(r['condition'])} | {r['policy']} | {r['rank']} | {_failures(r)} | {_ci(r, 'score')} "
                   f"| {_ci(r, 'rate_error_rad')} | {r['rate_error_rad_cvar10']:.4f} "
                   f"| {_ci(r, 'max_rate_radps', '.2f', deg(1.0))} | {_ci(r, 'effort_rad_s', '.1f', deg(1.0))} "
                   f"| {_ci(r, 'max_alpha_rad', '.2f', deg(1.0))} | {_ci(r, 'max_qalpha_pa_deg', '.1f', 1e-3)} |")
    return out


def flyability_table(summary: Sequence[Row]) -> list[str]:
    """Lines of one suite's table of protocol v2's flyability (:mod:`.flyability`) in rank order: failed or
    unflyable, unflyable, ``score_v2``, the commanded gimbal rate's RMS and 2 s peak in % of the rate limit;
    none when the rows are not v2's."""
    if not summary or "score_v2_mean" not in summary[0]:
        return []
    norm = any("score_v2_norm" in r for r in summary)        # the suite names a reference (metrics.normalise)
    out = ["| condition | policy | rank | failed or unflyable [95 % CI] | unflyable [95 % CI] | score_v2 [rad] "
           + ("| normalised (zero 0, reference 1) " if norm else "")
           + "| commanded rate RMS [% of limit] | 2 s peak [% of limit] |",
           "|---|---|---:|---:|---:|---:|" + ("---:|" if norm else "") + "---:|---:|"]
    for r in rank([dict(r) for r in summary]):
        either = (f"{_pct(r['failure_rate_v2'])} [{100.0 * r['failure_rate_v2_ci_low']:.0f}, "
                  f"{100.0 * r['failure_rate_v2_ci_high']:.0f}]")
        normalised = ""
        if norm:
            normalised = (f"| {_interval(r['score_v2_norm'], r['score_v2_norm_ci_low'], r['score_v2_norm_ci_high'], '.2f')} "
                          if "score_v2_norm" in r else "| - ")
        unflyable = (f"{_pct(r['unflyable_rate'])} [{100.0 * r['unflyable_rate_ci_low']:.0f}, "
                     f"{100.0 * r['unflyable_rate_ci_high']:.0f}]")
        out.append(f"| {_short(r['condition'])} | {r['policy']} | {r['rank']} | {either} | {unflyable} "
                   f"| {_ci(r, 'score_v2')} {normalised}| {_ci(r, 'cmd_rate_rms', '.1f', 100.0)} "
                   f"| {_ci(r, 'cmd_rate_peak', '.1f', 100.0)} |")
    return out


def _headline_cell(cell: Mapping[str, Any] | None, named: bool = True, none_flyable: bool = False) -> str:
    if not cell:
        return "none flyable" if none_flyable else "-"
    failed = round(cell["failed_or_unflyable"] * cell["n"])
    who = f"`{cell['policy']}` " if named else ""
    return f"{who}{_interval(cell['mean'], cell['low'], cell['high'], '.3f')}, {failed}/{cell['n']}"


def _room(h: Row, of: str | None) -> str:
    if not math.isfinite(h["room"]):
        return "-"
    text = f"{100.0 * h['room']:.0f} % [{100.0 * h['room_low']:.0f}, {100.0 * h['room_high']:.0f}]"
    return f"{text} of `{of}`" if of else text


def _where(h: Row) -> str:
    cond = h.get("condition", "")
    return cond.rsplit("/", 1)[0] if "/" in cond else h["suite"]          # a family suite: the vehicle


#: the note under the headline when a kind had no flyable policy
NONE_FLYABLE_NOTE = ("none flyable: every such policy the suite reports failed or was unflyable on more than half "
                     "its flights (its rows in the suite's flyability table); none of them is named best")


def headline_table(headline: Sequence[Row]) -> list[str]:
    """Lines of protocol v2's headline (:func:`~.headline.headline`): per suite and model the best classical
    design the suite reports, the best learned policy and the privileged ``score_v2`` (mean [95 % CI], failed
    or unflyable of the seeds) and the room with its interval; "none flyable" (and a note under the table) for
    a kind whose every policy failed or was unflyable on more than half its flights; none without rows."""
    if not headline:
        return []
    out = ["| suite | model | best causal classical | best learned | privileged reference | room [95 % CI] of the best causal |",
           "|---|---|---|---|---|---:|"]
    for h in headline:
        gone = h.get("none_flyable", "").split()
        out.append(f"| {_where(h)} | {h['model']} | {_headline_cell(h['classical'], none_flyable='classical' in gone)} "
                   f"| {_headline_cell(h['learned'], none_flyable='learned' in gone)} "
                   f"| {_headline_cell(h['privileged'])} | {_room(h, h['causal'])} |")
    if any(h.get("none_flyable") for h in headline):
        out += ["", NONE_FLYABLE_NOTE]
    return out


def others_table(others: Sequence[Row]) -> list[str]:
    """Lines of the headline's table of the other policies flown (:func:`~.headline.others`: a user's), with
    the headline's columns: per suite, model and policy its ``score_v2`` (mean [95 % CI], failed or unflyable
    of the seeds), the privileged reference and its room against it; none without rows."""
    if not others:
        return []
    out = ["| suite | model | policy | kind | score_v2 [rad] [95 % CI], failed or unflyable | privileged reference "
           "| room [95 % CI] against the reference |", "|---|---|---|---|---|---|---:|"]
    for o in others:
        out.append(f"| {_where(o)} | {o['model']} | `{o['policy']}` | {o['kind']} | {_headline_cell(o, named=False)} "
                   f"| {'`' + o['reference'] + '`' if o.get('reference') else '-'} | {_room(o, None)} |")
    return out


def phase_table(summary: Sequence[Row]) -> list[str]:
    """Lines of one suite's table of the cumulative pitch + yaw rate error per flight phase (policy x
    model; the phases add up to the total), or none when the rows lack the phases."""
    if not summary or f"rate_error_{PHASES[0]}_rad_mean" not in summary[0]:
        return []
    head = " | ".join(f"{p.replace('_', ' ')} [rad]" for p in PHASES)
    out = [f"| policy | model | {head} | total [rad] | failures |", "|---|---|" + "---:|" * (len(PHASES) + 2)]
    policies = list(dict.fromkeys(r["policy"] for r in summary))
    for pol in policies:
        for r in (r for r in summary if r["policy"] == pol):
            cells = " | ".join(_ci(r, f"rate_error_{p}_rad") for p in PHASES)
            out.append(f"| {pol} | {r.get('model', _short(r['condition']))} | {cells} | {_ci(r, 'rate_error_rad')} "
                       f"| {_pct(r['failure_rate'])} |")
    return out


def degradation_table(degradation: Sequence[Row]) -> list[str]:
    """Lines of one suite's rigid-to-non-rigid table: the failure rates of both, then the score and the
    rate error of both with the ratio and the paired difference (non-rigid - rigid) where computed."""
    by_key: dict[tuple[Any, ...], dict[str, Row]] = {}
    for g in degradation:
        by_key.setdefault((g["policy"], g["condition"]), {})[g["metric"]] = g
    metrics = [m for m in ("score", "rate_error_rad") if any(m in v for v in by_key.values())]
    head, align = "| policy | condition | failures rigid | failures non-rigid |", "|---|---|---:|---:|"
    label = {"score": "score", "rate_error_rad": "rate error"}
    for m in metrics:
        head += f" {label[m]} rigid [rad] | {label[m]} non-rigid [rad] | ratio | diff [rad] [95 % CI] | p (Wilcoxon) |"
        align += "---:|---:|---:|---:|---:|"
    out = [head, align]
    for (pol, cond), rows in by_key.items():
        first = next(iter(rows.values()))
        line = (f"| {pol} | {_short(cond)} | {_pct(first['failure_rate_rigid'])} | {_pct(first['failure_rate'])} |"
                if "failure_rate_rigid" in first else f"| {pol} | {_short(cond)} | - | - |")
        for m in metrics:
            g = rows.get(m)
            if g is None:
                line += " - | - | - | - | - |"
                continue
            diff = f"{g['mean_diff']:+.4f}"
            if "diff_ci_low" in g:
                diff += f" [{g['diff_ci_low']:+.4f}, {g['diff_ci_high']:+.4f}]"
            line += (f" {g['rigid_mean']:.4f} | {g['mean']:.4f} | {g['mean_ratio']:.3f} | {diff} "
                     f"| {_p(g.get('p_wilcoxon', math.nan))} |")
        out.append(line)
    return out


def comparison_table(comparison: Sequence[Row]) -> list[str]:
    """Lines of one suite's paired comparison with the reference policy of each condition."""
    if not comparison:
        return []
    metric = comparison[0].get("metric", "score")
    out = [f"| condition | policy | rank | IQM {metric} [rad] | against | diff [rad] [95 % CI] | wins/ties/losses "
           "| p (Wilcoxon) | p (t) | P(better) [95 % CI] |", "|---|---|---:|---:|---|---:|---:|---:|---:|---:|"]
    for c in comparison:
        iqm = _interval(c["iqm"], c["iqm_ci_low"], c["iqm_ci_high"])
        if c["policy"] == c["reference"]:
            out.append(f"| {_short(c['condition'])} | {c['policy']} | {c['rank']} | {iqm} | (reference) | | | | | |")
            continue
        diff = f"{c['diff']:+.4f} [{c['diff_ci_low']:+.4f}, {c['diff_ci_high']:+.4f}]"
        poi = _interval(c["p_improvement"], c["p_improvement_ci_low"], c["p_improvement_ci_high"], ".2f")
        out.append(f"| {_short(c['condition'])} | {c['policy']} | {c['rank']} | {iqm} | {c['reference']} | {diff} "
                   f"| {c['wins']}/{c['ties']}/{c['losses']} | {_p(c['p_wilcoxon'])} | {_p(c['p_ttest'])} | {poi} |")
    return out


def run_groups_table(groups: Sequence[Row]) -> list[str]:
    """Lines of one suite's table of agents over their training runs."""
    if not groups:
        return []
    metric = groups[0].get("metric", "score")
    out = [f"| condition | agent | runs | episodes | mean {metric} [rad] | IQM {metric} [rad] [95 % CI] |",
           "|---|---|---:|---:|---:|---:|"]
    for g in groups:
        out.append(f"| {_short(g['condition'])} | {g['agent']} | {g['runs']} | {g['episodes']} | {g['mean']:.4f} "
                   f"| {_interval(g['iqm'], g['iqm_ci_low'], g['iqm_ci_high'])} |")
    return out


def _section(title: str, lines: list[str]) -> list[str]:
    return ["", title, "", *lines] if lines else []


def markdown_table(summary: Sequence[Row], degradation: Sequence[Row], meta: Mapping[str, Any] | None = None,
                   comparison: Sequence[Row] = (), groups: Sequence[Row] = (), headline: Sequence[Row] = (),
                   family: Sequence[str] = (), others: Sequence[Row] = (), faults: Sequence[Row] = ()) -> str:
    """The comparison as Markdown: a family suite's table over its vehicles (``family``: the lines of
    :func:`~.family.family_table`, when given), protocol v2's headline over every suite (:func:`headline_table`,
    when ``headline`` has rows; a family suite's rows named by their vehicle's group) and the other policies
    flown beside it (``others``: :func:`others_table`, when given), then per suite: the ranked summary
    (:func:`summary_table`), the rate error per phase (:func:`phase_table`), the degradation
    (:func:`degradation_table`), the paired comparison (:func:`comparison_table`) and the agents over training
    runs (:func:`run_groups_table`); with ``faults`` (:func:`~.decide.by_fault`), a suite's table by kind of
    in-flight fault (:func:`~.decide.fault_table`)."""
    meta = dict(meta or {})
    out: list[str] = []
    if family:                                      # a family suite's vehicles gathered (:mod:`.family`)
        out += ["### The launcher family, over its vehicles", "", "Each vehicle flies the same wind seeds; 95 % "
                "intervals by resampling the vehicles and the seeds (lvgym.benchmark.family); held: no failed or "
                "unflyable flight of the vehicle. Per vehicle: the tables below.", "", *family, ""]
    if headline:
        out += ["### Headline (protocol v2)", "", "score_v2 [rad] (lower is better): mean [95 % CI], failed or "
                "unflyable of the seeds; the best of a kind among the policies the suite reports, never one failed "
                "or unflyable on more than half its flights; the room is the best causal policy's score minus the "
                "privileged reference's, of the former, on the same seeds (under 10 %: solved by design)", "",
                *headline_table(headline), ""]
    if others:
        out += ["### Other policies beside the headline (protocol v2)", "", "Policies flown that the suite does "
                "not report (yours): score_v2 [rad] as in the headline; the room is the policy's score minus the "
                "privileged reference's, of the former, on the same seeds", "", *others_table(others), ""]
    for suite in _suites(summary):
        rows = _of_suite(summary, suite)
        info = meta.get("suites", {}).get(suite, {}) if isinstance(meta.get("suites"), Mapping) else {}
        head = f"### {suite}"
        if info:
            head += (f" (protocol {info.get('version', '?')}, {meta.get('seed_set', '?')} seeds "
                     f"{info.get('first_seed', '?')}-{info.get('last_seed', '?')}, {rows[0]['n']} episodes each)")
        out += [head, "", "Ranked by failure rate, then by score (a failed episode's rate error plus the failure "
                "penalty for the mission left); means with 95 % bootstrap intervals over the seeds.", "",
                *summary_table(rows)]
        out += _section(f"Flyability ({suite}, protocol v2): the rank is by failed or unflyable (the commanded "
                        "gimbal rate over the rate limit, docs/flyability.md), then by score_v2 (an unflyable "
                        "flight charged as a failure from the breach)", flyability_table(rows))
        out += _section(f"Cumulative pitch + yaw rate error per flight phase ({suite}): boost to max q, the max-q "
                        "region, the staging coast, the upper stage; the phases add up to the total",
                        phase_table(rows))
        deg = _of_suite(degradation, suite)
        out += _section(f"Rigid-to-non-rigid degradation ({suite}): ratio = non-rigid / rigid, diff = non-rigid - "
                        "rigid on the same seeds. The score charges a failed episode for the mission left, so its "
                        "degradation counts the failures; the rate error (the thesis's criterion) stops at a "
                        "failure", degradation_table(deg) if deg else [])
        comp = _of_suite(comparison, suite)
        if comp:
            out += _section(f"Paired comparison of the {comp[0]['metric']} ({suite}) with the reference policy of "
                            "each condition on the same seeds: diff = policy - reference (negative: better); P(better): "
                            "the probability that an episode of the policy scores lower", comparison_table(comp))
        out += _section(f"score_v2 by kind of in-flight fault ({suite}): mean [rad] (the median over the seeds of "
                        "the per-seed ratio to the suite's reference), flights failed or unflyable of the kind's",
                        fault_table(_of_suite(faults, suite)))
        grp = _of_suite(groups, suite)
        out += _section(f"Agents over their training runs ({suite}): IQM of the "
                        f"{grp[0]['metric'] if grp else 'score'} over (runs, episodes)", run_groups_table(grp))
        out.append("")
    return "\n".join(out)
