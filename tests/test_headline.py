"""Protocol v2's headline (lvgym.benchmark.headline): the room against hand numbers, the best of each kind,
the kinds of the registered policies, per-suite policies in the runner and the headline in the table."""

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
from lvgym.benchmark.headline import KINDS, flat, headline, policy_kind
from lvgym.benchmark.stats import room
from lvgym.benchmark.tables import headline_table
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
    summary, records = _rows({"zero": [4.0, 4.0], "pid": [1.0, 1.2], "lqg": [0.8, 0.8], "ppo": [0.6, 1.0],
                              "mine": [0.7, 0.7], "ref": [0.35, 0.35]}, failed={"pid": 1})
    kinds = {"zero": "none", "pid": "classical", "lqg": "classical", "ppo": "learned", "ref": "privileged"}
    [h] = headline(summary, records, kinds)                         # "mine" names no kind: other, causal
    assert (h["suite"], h["model"]) == ("s", "rigid")
    assert h["classical"]["policy"] == "lqg" and h["learned"]["policy"] == "ppo" and h["privileged"]["policy"] == "ref"
    assert h["causal"] == "mine" and h["room"] == pytest.approx(0.5)
    assert h["learned"]["mean"] == pytest.approx(0.8) and h["classical"]["failed_or_unflyable"] == 0.0
    [row] = flat([h])
    assert row["classical_policy"] == "lqg" and row["privileged_mean"] == pytest.approx(0.35) and "classical" not in row
    lines = headline_table([h])
    assert lines[2] == ("| s | rigid | `lqg` 0.800 [0.800, 0.800], 0/2 | `ppo` 0.800 [0.600, 1.000], 0/2 "
                        "| `ref` 0.350 [0.350, 0.350], 0/2 | 50 % [50, 50] of `mine` |")
    table = markdown_table([], [], headline=[h])
    assert table.startswith("### Headline (protocol v2)") and lines[2] in table


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
