"""Protocol v2's headline (lvgym.benchmark.headline): the room against hand numbers, the best of each kind
(never a design failed or unflyable on more than half its flights), the rows of the other policies, the
kinds of the registered policies, per-suite policies in the runner and evaluate.py, and the headline in the
table."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lvgym.benchmark import (
    SUITES,
    ZERO,
    PolicySpec,
    get_suite,
    make_tasks,
    markdown_table,
)
from lvgym.benchmark.headline import FLYABLE_SHARE, KINDS, flat, headline, others, policy_kind
from lvgym.benchmark.stats import room
from lvgym.benchmark.tables import NONE_FLYABLE_NOTE, headline_table, others_table
from lvgym.cli.policies import resolve_policy


def test_room_against_hand_numbers():
    best, ref = [1.0, 2.0, 3.0, 2.0], [0.5, 1.0, 1.5, 1.0]           # the reference halves every seed
    value, lo, hi = room(best, ref)
    assert value == pytest.approx(0.5) and lo == pytest.approx(0.5) and hi == pytest.approx(0.5)
    value, lo, hi = room([1.0, 1.0, 1.0, 1.0], [1.2, 0.8, 1.1, 0.9])    # the reference no better on the mean
    assert value == pytest.approx(0.0) and lo < 0.0 < hi
    assert room([2.0, 4.0], [3.0, 5.0])[0] == pytest.approx(-1 / 3)     # worse than the best causal: negative
    assert all(map(math.isnan, room([0.0, 0.0], [0.0, 0.0])))
    with pytest.raises(ValueError, match="one value per common seed"):
        room([1.0, 2.0], [1.0])


def _rows(scores: dict[str, list[float]], failed: dict[str, int] | None = None):
    """A hand-made summary and records of one v2 condition: per policy its per-seed score_v2."""
    summary, records = [], []
    for pol, xs in scores.items():
        summary.append({"suite": "s", "condition": "s/rigid", "policy": pol, "n": len(xs), "score_v2_mean": float(np.mean(xs)),
                        "score_v2_ci_low": min(xs), "score_v2_ci_high": max(xs),
                        "failure_rate_v2": (failed or {}).get(pol, 0) / len(xs)})
        records += [{"suite": "s", "condition": "s/rigid", "policy": pol, "seed": 10_000 + i, "score_v2": x}
                    for i, x in enumerate(xs)]
    return summary, records


def test_headline_takes_the_best_of_each_kind_and_the_room_of_the_best_causal():
    summary, records = _rows({"zero": [4.0, 4.0], "pid": [1.0, 1.2], "lqg": [0.8, 0.8], "ppo": [0.6, 0.9],
                              "mine": [0.7, 0.7], "ref": [0.375, 0.375]}, failed={"pid": 1})
    kinds = {"zero": "none", "pid": "classical", "lqg": "classical", "ppo": "learned", "ref": "privileged"}
    [h] = headline(summary, records, kinds)                         # "mine" names no kind: other, a row of its own
    assert (h["suite"], h["model"]) == ("s", "rigid")
    assert h["classical"]["policy"] == "lqg" and h["learned"]["policy"] == "ppo" and h["privileged"]["policy"] == "ref"
    assert h["causal"] == "ppo" and h["room"] == pytest.approx(0.5) and h["none_flyable"] == ""   # (0.75 - 0.375) / ...
    assert h["learned"]["mean"] == pytest.approx(0.75) and h["classical"]["failed_or_unflyable"] == 0.0
    [row] = flat([h])
    assert row["classical_policy"] == "lqg" and row["privileged_mean"] == pytest.approx(0.375)
    assert "classical" not in row
    lines = headline_table([h])
    assert lines[2] == ("| s | rigid | `lqg` 0.800 [0.800, 0.800], 0/2 | `ppo` 0.750 [0.600, 0.900], 0/2 "
                        "| `ref` 0.375 [0.375, 0.375], 0/2 | 50 % [38, 58] of `ppo` |")   # resamples: 0.6 or 0.9 twice
    [mine] = others(summary, records, kinds)                         # the user's policy: its own row and room
    assert (mine["policy"], mine["kind"], mine["reference"]) == ("mine", "other", "ref")
    assert mine["mean"] == pytest.approx(0.7) and mine["room"] == pytest.approx((0.7 - 0.375) / 0.7)
    assert others_table([mine])[2] == ("| s | rigid | `mine` | other | 0.700 [0.700, 0.700], 0/2 | `ref` "
                                       "| 46 % [46, 46] |")
    table = markdown_table([], [], headline=[h], others=[mine])
    assert table.startswith("### Headline (protocol v2)") and lines[2] in table
    assert table.index("### Other policies beside the headline") > table.index(lines[2])
    assert others_table([]) == [] and "Other policies" not in markdown_table([], [], headline=[h])


def test_an_unflyable_design_is_never_named_best():
    """A design failed or unflyable on more than half its flights is never the best of its kind, however low
    its mean; half is allowed; with no other design of the kind, "none flyable" and a note, and no room."""
    summary, records = _rows({"zero": [4.0, 4.0], "flex": [0.5, 0.5], "half": [0.9, 0.9], "lqg": [1.0, 1.0],
                              "ref": [0.45, 0.45]}, failed={"flex": 2, "half": 1})
    kinds = {"zero": "none", "flex": "classical", "half": "classical", "lqg": "classical", "ref": "privileged"}
    [h] = headline(summary, records, kinds)
    assert h["classical"]["policy"] == "half" and h["causal"] == "half" and h["room"] == pytest.approx(0.5)
    assert h["classical"]["failed_or_unflyable"] == 0.5 and FLYABLE_SHARE == 0.5
    summary, records = _rows({"zero": [4.0, 4.0], "flex": [1.0, 1.0], "ref": [0.6, 0.6]}, failed={"flex": 2, "ref": 2})
    [h] = headline(summary, records, {"zero": "none", "flex": "classical", "ref": "privileged"})
    assert h["classical"] is None and h["none_flyable"] == "classical" and h["causal"] is None
    assert math.isnan(h["room"]) and h["privileged"]["policy"] == "ref"        # the reference: named whatever it lost
    lines = headline_table([h])
    assert lines[2] == "| s | rigid | none flyable | - | `ref` 0.600 [0.600, 0.600], 2/2 | - |"
    assert lines[-1] == NONE_FLYABLE_NOTE and lines[-2] == ""
    assert flat([h])[0]["none_flyable"] == "classical"


def test_the_headline_names_the_suites_reported_designs_and_others_get_rows():
    """With the suite's reported labels, a flown classical design it does not report (a user's) is no
    contender: it gets a row of its own with its room against the suite's privileged reference."""
    summary, records = _rows({"zero": [4.0, 4.0], "lqg": [0.8, 0.8], "gs-pid": [0.6, 0.6], "mine": [0.5, 0.5],
                              "privileged": [0.4, 0.4]})
    kinds = {"zero": "none", "lqg": "classical", "gs-pid": "classical", "privileged": "privileged"}
    reported = {"s": ["zero", "lqg", "privileged"]}
    [h] = headline(summary, records, kinds, reported)
    assert h["classical"]["policy"] == "lqg" and h["causal"] == "lqg" and h["room"] == pytest.approx(0.5)
    rows = others(summary, records, kinds, reported)
    assert [(o["policy"], o["kind"]) for o in rows] == [("gs-pid", "classical"), ("mine", "other")]
    assert [o["room"] for o in rows] == [pytest.approx(1 / 3), pytest.approx(0.2)]       # (0.6 - 0.4) / 0.6, ...
    assert headline(summary, records, kinds, {"other-suite": []})[0]["classical"]["policy"] == "gs-pid"   # by kind


def test_headline_without_a_kind_or_a_reference():
    summary, records = _rows({"zero": [4.0, 4.0], "lqg": [0.8, 0.8]})
    [h] = headline(summary, records, {"zero": "none", "lqg": "classical"})
    assert h["learned"] is None and h["privileged"] is None and math.isnan(h["room"])
    assert headline_table([h])[2] == "| s | rigid | `lqg` 0.800 [0.800, 0.800], 0/2 | - | - | - |"
    v1 = [{k: v for k, v in r.items() if not k.startswith(("score_v2", "failure_rate_v2"))} for r in summary]
    assert headline(v1, records, {}) == [] and headline_table([]) == []       # v0 and v1 rows: no headline


def test_the_kinds_of_the_registered_policies():
    assert policy_kind(ZERO) == "none"
    for name in ("gs-pid", "gs-pid-flex", "gs-pid-flex-quiet", "aac-quiet", "lqg", "lqg-front", "lqg-aw", "mpc",
                 "gs-pd-relief"):
        assert policy_kind(resolve_policy(name)) == "classical", name
    assert policy_kind(resolve_policy("ppo-res-lqg")) == "learned"
    assert policy_kind(resolve_policy("privileged")) == "privileged"
    assert policy_kind(PolicySpec("mine", "lvgym.benchmark.policy:ZeroPolicy")) == "other"
    assert set(KINDS) == {"classical", "learned", "privileged", "none", "other"}


def test_every_v2_suite_reports_registered_policies_of_every_kind_it_needs():
    v2 = [s for s in SUITES.values() if s.version == "v2"]
    assert [s.name for s in v2] == ["smile-v2", "smile-v2-maxq-gust", "smile-v2-faults", "stratos-tvc-v2", "slender-v2"]
    for s in v2:
        kinds = {policy_kind(resolve_policy(n)) for n in s.policies}
        assert {"none", "classical", "privileged"} <= kinds, s.name
        assert not s.reference or s.reference in s.policies


def test_tasks_with_policies_per_suite():
    a, b = get_suite("smile-v2"), get_suite("slender-v2")
    lqg = resolve_policy("lqg")
    tasks = make_tasks({a.name: [ZERO, lqg], b.name: [ZERO]}, [a, b], 2)
    assert [(t.suite, t.condition.model, t.policy.name, t.seed) for t in tasks][:5] == [
        ("smile-v2", "rigid", "zero", 10_000), ("smile-v2", "rigid", "zero", 10_001), ("smile-v2", "rigid", "lqg", 10_000),
        ("smile-v2", "rigid", "lqg", 10_001), ("smile-v2", "nonrigid", "zero", 10_000)]
    assert {t.policy.name for t in tasks if t.suite == "slender-v2"} == {"zero"} and len(tasks) == 8 + 4
    assert [t.index for t in tasks] == list(range(len(tasks)))
    with pytest.raises(ValueError, match=r"none given for \['slender-v2'\]"):
        make_tasks({a.name: [ZERO]}, [a, b], 1)


def test_evaluate_flies_the_reported_classical_designs_beside_a_users_policies():
    from lvgym.cli.evaluate import parse_args, suite_policies

    s = get_suite("smile-v2")
    mine = PolicySpec("mine", "lvgym.benchmark.policy:ZeroPolicy")
    specs, reported = suite_policies(s, [mine])
    beside = ["gs-pid-flex", "gs-pid-flex-quiet", "aac-quiet", "lqg", "lqg-front", "gs-pd-relief", "privileged"]
    assert [p.name for p in specs] == ["mine", *beside] and reported == beside        # the suite's order
    assert [p.name for p in suite_policies(s, [mine], only=True)[0]] == ["mine"]
    assert [p.name for p in suite_policies(s, [mine], vehicle="my_rocket.yaml")[0]] == ["mine"]
    specs, reported = suite_policies(s, [resolve_policy("lqg"), resolve_policy("zero")])   # given: not twice
    assert [p.name for p in specs] == ["lqg", "zero", *(n for n in beside if n != "lqg")] and "zero" in reported
    specs, reported = suite_policies(s, [PolicySpec("lqg", "lvgym.benchmark.policy:ZeroPolicy")])   # a label=...
    assert [p.name for p in specs].count("lqg") == 1 and "lqg" not in reported
    specs, reported = suite_policies(get_suite("smile-v1"), [mine])                  # v1 reports none
    assert [p.name for p in specs] == ["mine"] and reported == []
    specs, reported = suite_policies(get_suite("slender-v2"), None)
    assert [p.name for p in specs] == reported == ["zero", "gs-pid-flex", "privileged"]
    assert parse_args(["--only"]).only and not parse_args([]).only
