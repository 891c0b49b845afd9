"""Protocol v2's headline: per suite and flight model, the best classical design the suite reports, the
best learned policy, the privileged reference and the room between the best causal policy and the reference;
beside it, a row of its own for every other policy flown (a user's).

Each policy has a *kind* (:func:`policy_kind`), read from its factory: ``classical`` (a design of
``lvgym.baselines``), ``learned`` (a trained model of ``lvgym.agents``), ``privileged`` (a reference that
knows what a flight computer cannot: its factory's ``privileged``), ``none`` (the zero policy) or ``other``
(a user's policy that names no kind).

The headline's columns are chosen among the policies the suite *reports* (``Suite.policies``; without that
list, every policy of a kind but ``other``): the best of a kind is its policy of lowest mean ``score_v2``
among those failed or unflyable on at most :data:`FLYABLE_SHARE` of their flights (``failure_rate_v2``); a
design lost or unflyable on more than half its flights is never named best, and a kind that flew but has no
such policy is *none flyable*. The privileged reference is the suite's best privileged policy, whatever its
failures (it is the yardstick, not a contender). The room of a condition is ``(best causal - privileged) /
best causal`` of the mean ``score_v2`` over the seeds both flew (:func:`~.stats.room`, with its paired
bootstrap interval), where ``best causal`` is the best of the reported classical and learned policies by the
same rule. Under about 10 % a suite is solved by design (docs/benchmark.md, "Protocol v2").

Every other policy flown on a v2 suite but ``none`` (a user's ``--policies``, a design the suite does not
report) gets a row of :func:`others`: its ``score_v2`` and failures as the headline's cells, and its own
room against the same privileged reference.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping, Sequence
from typing import Any

from .metrics import per_seed
from .runner import PolicySpec
from .stats import room

__all__ = ["CAUSAL", "FLYABLE_SHARE", "KINDS", "SOLVED_ROOM", "flat", "headline", "others", "policy_kind"]

#: the kinds of policy the headline tells apart
KINDS = ("classical", "learned", "privileged", "none", "other")
#: the kinds of the headline's contenders (the best causal policy is the best of these)
CAUSAL = ("classical", "learned")
#: a room under this share of the best causal score: the suite is solved by design
SOLVED_ROOM = 0.10
#: a policy failed or unflyable on more than this share of its flights is never named the best of its kind
FLYABLE_SHARE = 0.5

Row = Mapping[str, Any]


def policy_kind(spec: PolicySpec) -> str:
    """The kind of ``spec``'s policy (module docstring): its factory's ``privileged`` or ``kind`` attribute
    (the zero policy's is ``none``), else ``other``; ``privileged`` too for a policy that flies with
    privileged env options (:func:`~.runner.policy_options`: a teacher). Imports the factory's module."""
    from .runner import policy_options

    if policy_options(spec):                        # a privileged reference's or a teacher's options
        return "privileged"
    kind = getattr(spec.resolve(), "kind", "other")
    if kind not in KINDS:
        raise ValueError(f"policy {spec.name!r}: kind = {kind!r}: one of {KINDS}")
    return kind


def _cell(row: Row) -> dict[str, Any]:
    return {"policy": row["policy"], "mean": row["score_v2_mean"], "low": row["score_v2_ci_low"],
            "high": row["score_v2_ci_high"], "failed_or_unflyable": row["failure_rate_v2"], "n": row["n"]}


def _flyable(row: Row) -> bool:
    """Failed or unflyable on at most :data:`FLYABLE_SHARE` of its flights."""
    return float(row["failure_rate_v2"]) <= FLYABLE_SHARE


def _best(rows: Sequence[Row], kinds: Mapping[str, str], want: Iterable[str], flyable: bool = True) -> Row | None:
    mine = [r for r in rows if kinds.get(r["policy"], "other") in set(want) and (_flyable(r) or not flyable)]
    return min(mine, key=lambda r: float(r["score_v2_mean"])) if mine else None


def _groups(summary: Iterable[Row]) -> dict[tuple[str, str], list[Row]]:
    """Protocol v2's rows of ``summary`` (those with ``score_v2_mean``) per (suite, condition), in order."""
    groups: dict[tuple[str, str], list[Row]] = {}
    for r in summary:
        if "score_v2_mean" in r:
            groups.setdefault((r["suite"], r["condition"]), []).append(r)
    return groups


def _is_reported(row: Row, kinds: Mapping[str, str], reported: Mapping[str, Collection[str]] | None) -> bool:
    if reported is None or row["suite"] not in reported:
        return kinds.get(row["policy"], "other") != "other"
    return row["policy"] in reported.get(row["suite"], ())


def _room(values: Mapping[tuple[str, str, str], Mapping[int, float]], suite: str, cond: str, policy: str,
          reference: str) -> tuple[float, float, float]:
    """:func:`~.stats.room` of ``policy`` against ``reference`` on the seeds both flew (NaNs without any)."""
    b, p = values.get((suite, cond, policy), {}), values.get((suite, cond, reference), {})
    seeds = sorted(set(b) & set(p))
    return room([b[s] for s in seeds], [p[s] for s in seeds]) if seeds else (float("nan"),) * 3


def headline(summary: Sequence[Row], records: Iterable[Row], kinds: Mapping[str, str],
             reported: Mapping[str, Collection[str]] | None = None) -> list[dict[str, Any]]:
    """One row per (suite, condition) of protocol v2's rows of ``summary`` (those with ``score_v2_mean``), in
    order of appearance: ``suite``, ``condition``, ``model``; ``classical``, ``learned``, ``privileged`` (the
    best of the kind among the reported policies, module docstring: ``policy``, ``mean``, ``low``, ``high``,
    ``failed_or_unflyable`` (a rate), ``n``; ``None`` when none qualifies); ``none_flyable`` (the kinds,
    space-separated, that flew but whose every policy failed or was unflyable on more than half its flights;
    ``""`` when none); ``causal`` (the best causal policy's name, or ``None``); ``room``, ``room_low``,
    ``room_high`` (:func:`~.stats.room` on the seeds both flew; NaN without a best causal or a privileged
    policy). ``kinds``: policy label -> kind (:func:`policy_kind`; a label it lacks is ``other``);
    ``reported``: suite -> the labels of the policies it reports (``Suite.policies``; for a suite it lacks, or
    ``None``: every policy of a kind but ``other``)."""
    values = per_seed([r for r in records if "score_v2" in r], "score_v2")
    out = []
    for (suite, cond), rows in _groups(summary).items():
        mine = [r for r in rows if _is_reported(r, kinds, reported)]
        best = {k: _best(mine, kinds, [k]) for k in CAUSAL}
        best["privileged"] = _best(mine, kinds, ["privileged"], flyable=False)
        causal = _best(mine, kinds, CAUSAL)
        flew = {kinds.get(r["policy"], "other") for r in mine}
        row: dict[str, Any] = {"suite": suite, "condition": cond, "model": cond.rsplit("/", 1)[-1],
                               **{k: _cell(v) if v else None for k, v in best.items()},
                               "none_flyable": " ".join(k for k in CAUSAL if k in flew and best[k] is None),
                               "causal": causal["policy"] if causal else None,
                               "room": float("nan"), "room_low": float("nan"), "room_high": float("nan")}
        if causal and best["privileged"]:
            row["room"], row["room_low"], row["room_high"] = _room(values, suite, cond, causal["policy"],
                                                                   best["privileged"]["policy"])
        out.append(row)
    return out


def others(summary: Sequence[Row], records: Iterable[Row], kinds: Mapping[str, str],
           reported: Mapping[str, Collection[str]] | None = None) -> list[dict[str, Any]]:
    """One row per policy of protocol v2's rows of ``summary`` that :func:`headline` leaves out (not reported,
    ``reported`` as there; never the kind ``none``), per (suite, condition) in order of appearance:
    ``suite``, ``condition``, ``model``, ``kind``, the headline's cell (``policy``, ``mean``, ``low``, ``high``,
    ``failed_or_unflyable``, ``n``), ``reference`` (the headline's privileged reference, or ``None``) and its
    ``room``, ``room_low``, ``room_high`` against it (:func:`~.stats.room`: ``(policy - reference) / policy``
    on the seeds both flew; NaN without a reference)."""
    values = per_seed([r for r in records if "score_v2" in r], "score_v2")
    out = []
    for (suite, cond), rows in _groups(summary).items():
        ref = _best([r for r in rows if _is_reported(r, kinds, reported)], kinds, ["privileged"], flyable=False)
        for r in rows:
            kind = kinds.get(r["policy"], "other")
            if _is_reported(r, kinds, reported) or kind == "none":
                continue
            row = {"suite": suite, "condition": cond, "model": cond.rsplit("/", 1)[-1], "kind": kind, **_cell(r),
                   "reference": ref["policy"] if ref else None}
            row["room"], row["room_low"], row["room_high"] = (
                _room(values, suite, cond, r["policy"], ref["policy"]) if ref else (float("nan"),) * 3)
            out.append(row)
    return out


def flat(rows: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """:func:`headline`'s rows with each kind's cell spread into columns (``classical_policy``,
    ``classical_mean``, ...; empty where no policy of the kind flew), for a CSV file."""
    out = []
    for r in rows:
        row = {k: v for k, v in r.items() if k not in ("classical", "learned", "privileged")}
        for kind in ("classical", "learned", "privileged"):
            cell = r.get(kind) or {}
            row.update({f"{kind}_{k}": cell.get(k, "") for k in ("policy", "mean", "low", "high",
                                                                   "failed_or_unflyable", "n")})
        out.append(row)
    return out
