"""The headline that decides: its policies chosen on validation seeds and frozen in a selection file, then flown
once on the named test block (:data:`~.suites.HEADLINE_BLOCK`), with the statistics of :mod:`.decide`.

- :func:`choose`: per suite, the best classical design, the best learned policy and the privileged reference
  among the policies it reports, by the headline's rule (:func:`~.headline.headline`: the lowest mean
  ``score_v2`` among those failed or unflyable on at most half their flights), on every flight of the suite
  (both flight models pooled).
- :func:`selection_document`, :func:`check_selection`: the frozen selection file (the names chosen, every
  policy's validation score, the commit and the date, each suite's reported list with when each entry joined);
  the test block is flown only from a selection made at a clean commit.
- :func:`block_rows`, :func:`block_table`: per suite and flight model the selected classical, learned and
  privileged policies on the block (mean ``score_v2`` with its bootstrap interval, the failed and unflyable
  rates with exact intervals), the paired gain of learned over classical with its interval, both policies'
  scores on the flights both survived, and the same gain on the 50 development seeds (the continuity column).
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .decide import both_survived, gain, rates
from .headline import headline
from .metrics import summarize
from .stats import bootstrap_ci

__all__ = ["KINDS_CHOSEN", "SELECTION_IN_REPO", "block_rows", "block_table", "check_selection", "choose",
           "selection_document"]

#: the project's selection file, relative to the repository's root
SELECTION_IN_REPO = Path("docs") / "data" / "headline-selection.json"
#: the kinds the selection names per suite
KINDS_CHOSEN = ("classical", "learned", "privileged")

Row = Mapping[str, Any]


def choose(records: Sequence[Row], kinds: Mapping[str, str],
           reported: Mapping[str, Sequence[str]]) -> dict[str, dict[str, Any]]:
    """Per suite of ``records`` (protocol v2's, with ``score_v2``): ``classical``, ``learned``, ``privileged``
    (the chosen policy's name, ``None`` when none qualifies) and ``validation`` (per policy: ``score_v2`` mean,
    ``lost`` rate (failed or unflyable), flights ``n``), the suite's flights pooled over its conditions.
    ``kinds``, ``reported``: as :func:`~.headline.headline` takes them."""
    pooled = [{**r, "condition": r["suite"]} for r in records if "score_v2" in r]
    summary = summarize(pooled, ["score_v2"])
    out: dict[str, dict[str, Any]] = {}
    for h in headline(summary, pooled, kinds, reported):
        out[h["suite"]] = {k: (h[k] or {}).get("policy") for k in KINDS_CHOSEN}
        out[h["suite"]]["validation"] = {r["policy"]: {"score_v2": r["score_v2_mean"], "lost": r["failure_rate_v2"],
                                                       "n": r["n"]} for r in summary if r["suite"] == h["suite"]}
    return out


def selection_document(chosen: Mapping[str, Mapping[str, Any]], joined: Mapping[str, Sequence[Mapping[str, Any]]],
                       kinds: Mapping[str, str], source: Mapping[str, Any], seeds: Sequence[int],
                       overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The selection file's content: ``made_utc``, the ``source`` (``commit`` and ``dirty``, or ``version``),
    the validation ``seeds`` (first, last, count), ``overrides`` (env options that make it no protocol
    selection, e.g. a short mission), and per suite the chosen names, the validation scores, ``reported`` (its
    list with when each entry joined) and each reported policy's kind."""
    return {"made_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"), **dict(source),
            "seed_set": "validation", "first_seed": int(min(seeds)), "last_seed": int(max(seeds)),
            "n_seeds": len(seeds), "overrides": dict(overrides or {}),
            "rule": "per suite, the lowest mean score_v2 over both flight models among the reported policies of a "
                    "kind failed or unflyable on at most half their flights (lvgym.benchmark.headline)",
            "suites": {s: {**{k: c.get(k) for k in KINDS_CHOSEN}, "validation": dict(c["validation"]),
                           "reported": [dict(j) for j in joined.get(s, ())],
                           "kinds": {j["policy"]: kinds.get(j["policy"], "other") for j in joined.get(s, ())}}
                       for s, c in chosen.items()}}


def check_selection(doc: Mapping[str, Any] | None) -> str:
    """Why the test block may not be flown from selection ``doc`` (``""``: it may): no selection, or one made
    outside a checkout or at a commit with uncommitted changes."""
    if doc is None:
        return "no selection file: make one with `lvgym headline select` (validation seeds) and commit it"
    if not doc.get("commit"):
        return "the selection names no git commit: make it with `lvgym headline select` in the repository's checkout"
    if doc.get("dirty", True):
        return (f"the selection was made at commit {doc['commit'][:12]} with uncommitted changes: commit them and "
                "select again, so that the selection is reproducible")
    return ""


def _cell(records: Sequence[Row], suite: str, cond: str, policy: str | None) -> dict[str, Any] | None:
    if not policy:
        return None
    values = [float(r["score_v2"]) for r in records
              if r["suite"] == suite and r["condition"] == cond and r["policy"] == policy]
    if not values:
        return None
    low, high = bootstrap_ci(values)
    return {"policy": policy, "mean": sum(values) / len(values), "low": low, "high": high,
            **rates(records, suite, cond, policy)}


def block_rows(records: Sequence[Row], continuity: Sequence[Row],
               selection: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Per (suite, condition) of ``records`` (the block's flights) whose suite ``selection`` names:
    ``classical``, ``learned``, ``privileged`` (:func:`_cell`: mean ``score_v2`` [low, high], ``n``, ``failed``
    and ``unflyable`` rates with their exact intervals; ``None`` when not chosen or not flown), ``gain`` (of
    learned over classical, :func:`~.decide.gain`), ``both`` (:func:`~.decide.both_survived`, a = learned, b =
    classical) and ``continuity`` (the same gain on the ``continuity`` records: the development seeds)."""
    out = []
    for suite, cond in dict.fromkeys((r["suite"], r["condition"]) for r in records):
        chosen = selection.get("suites", {}).get(suite)
        if chosen is None:
            continue
        row: dict[str, Any] = {"suite": suite, "condition": cond, "model": cond.rsplit("/", 1)[-1],
                               **{k: _cell(records, suite, cond, chosen.get(k)) for k in KINDS_CHOSEN}}
        a, b = chosen.get("learned"), chosen.get("classical")
        nan = {"n": 0, "gain": math.nan, "gain_low": math.nan, "gain_high": math.nan}
        row["gain"] = gain(records, suite, cond, a, b) if a and b else nan
        row["both"] = both_survived(records, suite, cond, a, b) if a and b else {"n": 0, "of": 0}
        row["continuity"] = gain(continuity, suite, cond, a, b) if a and b and continuity else nan
        out.append(row)
    return out


def _pct(rate: float, low: float, high: float) -> str:
    return f"{100 * rate:.0f} % [{100 * low:.0f}, {100 * high:.0f}]"


def _cell_text(cell: Row | None) -> str:
    if not cell:
        return "-"
    return (f"`{cell['policy']}` {cell['mean']:.3f} [{cell['low']:.3f}, {cell['high']:.3f}]; failed "
            f"{_pct(cell['failed'], cell['failed_low'], cell['failed_high'])}, unflyable "
            f"{_pct(cell['unflyable'], cell['unflyable_low'], cell['unflyable_high'])}")


def _gain_text(g: Row) -> str:
    if not g.get("n") or not math.isfinite(g["gain"]):
        return "-"
    return f"{100 * g['gain']:+.0f} % [{100 * g['gain_low']:+.0f}, {100 * g['gain_high']:+.0f}] (n {g['n']})"


def block_table(rows: Sequence[Row]) -> list[str]:
    """Lines of the headline's table on the test block (:func:`block_rows`)."""
    out = ["| suite | model | best classical | best learned | privileged | gain of learned over classical "
           "[95 % CI] | both survived: classical, learned (flights) | 50 development seeds: gain [95 % CI] |",
           "|---|---|---|---|---|---:|---|---:|"]
    for r in rows:
        both = r["both"]
        survived = (f"{both['mean_b']:.3f}, {both['mean_a']:.3f} ({both['n']} of {both['of']})"
                    if both.get("n") else "-")
        out.append(f"| {r['suite']} | {r['model']} | {_cell_text(r['classical'])} | {_cell_text(r['learned'])} "
                   f"| {_cell_text(r['privileged'])} | {_gain_text(r['gain'])} | {survived} "
                   f"| {_gain_text(r['continuity'])} |")
    return out
