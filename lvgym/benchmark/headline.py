"""Protocol v2's headline: per suite and flight model, the best causal classical policy, the best learned
one, the privileged reference and the room between the best causal policy and the reference.

Each policy has a *kind* (:func:`policy_kind`), read from its factory: ``classical`` (a design of
``lvgym.baselines``), ``learned`` (a trained model of ``lvgym.agents``), ``privileged`` (a reference that
knows what a flight computer cannot: its factory's ``privileged``), ``none`` (the zero policy) or ``other``
(a user's policy that names no kind: causal, counted with the classical and learned ones for the room).

The room of a condition is ``(best causal - privileged) / best causal`` of the mean ``score_v2`` over the
seeds all of them flew (:func:`~.stats.room`, with its paired bootstrap interval), where ``best causal`` is the
policy of lowest mean ``score_v2`` among every kind but ``none`` and ``privileged``. Under about 10 % a
suite is solved by design (docs/benchmark.md, "Protocol v2").
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from .metrics import per_seed
from .runner import PolicySpec
from .stats import room

__all__ = ["KINDS", "SOLVED_ROOM", "flat", "headline", "policy_kind"]

#: the kinds of policy the headline tells apart
KINDS = ("classical", "learned", "privileged", "none", "other")
#: a room under this share of the best causal score: the suite is solved by design
SOLVED_ROOM = 0.10


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


def _cell(row: Mapping[str, Any]) -> dict[str, Any]:
    return {"policy": row["policy"], "mean": row["score_v2_mean"], "low": row["score_v2_ci_low"],
            "high": row["score_v2_ci_high"], "failed_or_unflyable": row["failure_rate_v2"], "n": row["n"]}


def _best(rows: Sequence[Mapping[str, Any]], kinds: Mapping[str, str], want: Iterable[str]) -> Mapping[str, Any] | None:
    mine = [r for r in rows if kinds.get(r["policy"], "other") in set(want)]
    return min(mine, key=lambda r: float(r["score_v2_mean"])) if mine else None


def headline(summary: Sequence[Mapping[str, Any]], records: Iterable[Mapping[str, Any]],
             kinds: Mapping[str, str]) -> list[dict[str, Any]]:
    """One row per (suite, condition) of protocol v2's rows of ``summary`` (those with ``score_v2_mean``), in
    order of appearance: ``suite``, ``condition``, ``model``; ``classical``, ``learned``, ``privileged`` (the
    best of the kind, by mean ``score_v2``: ``policy``, ``mean``, ``low``, ``high``, ``failed_or_unflyable``
    (a rate), ``n``; ``None`` when no policy of the kind flew); ``causal`` (the best causal policy's name);
    ``room``, ``room_low``, ``room_high`` (:func:`~.stats.room` on the seeds both flew; NaN without a
    privileged policy). ``kinds``: policy label -> kind (:func:`policy_kind`); a label it lacks is ``other``."""
    values = per_seed([r for r in records if "score_v2" in r], "score_v2")
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for r in summary:
        if "score_v2_mean" in r:
            groups.setdefault((r["suite"], r["condition"]), []).append(r)
    out = []
    for (suite, cond), rows in groups.items():
        best = {k: _best(rows, kinds, [k]) for k in ("classical", "learned", "privileged")}
        causal = _best(rows, kinds, ("classical", "learned", "other"))
        row: dict[str, Any] = {"suite": suite, "condition": cond, "model": cond.rsplit("/", 1)[-1],
                               **{k: _cell(v) if v else None for k, v in best.items()},
                               "causal": causal["policy"] if causal else None,
                               "room": float("nan"), "room_low": float("nan"), "room_high": float("nan")}
        if causal and best["privileged"]:
            b = values.get((suite, cond, causal["policy"]), {})
            p = values.get((suite, cond, best["privileged"]["policy"]), {})
            seeds = sorted(set(b) & set(p))
            if seeds:
                row["room"], row["room_low"], row["room_high"] = room([b[s] for s in seeds], [p[s] for s in seeds])
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
