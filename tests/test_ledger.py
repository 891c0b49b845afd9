"""The ledger of test flights (lvgym.benchmark.ledger): what a line holds, who writes it, the per-policy count,
and that the test session never writes the committed ledger."""

import json
import os
from pathlib import Path

import pytest

from lvgym.benchmark import ZERO, evaluate, get_suite
from lvgym.benchmark.ledger import (ENV_VAR, LEDGER_IN_REPO, blocks, checkout, ledger_path, log_flight, per_policy,
                                    read, table)
from lvgym.benchmark.ledger import test_seeds as among_test_seeds
from lvgym.benchmark.suites import DEVELOPMENT_BLOCK, HEADLINE_BLOCK, TEST_SEED0
from lvgym.cli import ledger as ledger_cli

ROOT = Path(__file__).resolve().parents[1]


def test_the_session_never_writes_the_committed_ledger():
    assert os.environ[ENV_VAR] and ledger_path() == Path(os.environ[ENV_VAR])
    assert ledger_path().resolve() != (ROOT / LEDGER_IN_REPO).resolve()


def test_committed_ledger_starts_with_the_history():
    lines = read(ROOT / LEDGER_IN_REPO)
    history = [ln for ln in lines if ln.get("history")]
    assert [ln["n_seeds"] for ln in history[:2]] == [50, 150]
    assert history[0]["seeds"] == [[10_000, 10_049]] and history[1]["seeds"] is None     # range not recorded
    assert all(ln["policies"] is None for ln in history)                               # every policy of the time


def test_blocks_are_ranges_of_consecutive_seeds():
    assert blocks([5, 3, 4, 9, 10, 12, 3]) == [[3, 5], [9, 10], [12, 12]]


def test_a_line_per_call_and_nothing_for_validation_seeds(tmp_path):
    path = tmp_path / "ledger.jsonl"
    assert log_flight(range(0, 10), ["smile-v2"], ["rigid"], ["lqg"], path=path) is None
    assert among_test_seeds([9_999, 10_000, 19_999, 20_000, 100_000]) == [10_000, 19_999]    # not the training seeds
    assert log_flight([100_000, 100_001], ["smile-v2"], ["rigid"], ["lqg"], path=path) is None
    log_flight([10_000, 10_001, 12_000], ["smile-v2", "smile-v2"], ["rigid", "nonrigid"], ["lqg", "zero", "lqg"],
               purpose="a check", command="evaluate", path=path)
    (line,) = read(path)
    assert line["seeds"] == [[10_000, 10_001], [12_000, 12_000]] and line["n_seeds"] == 3
    assert line["suites"] == ["smile-v2"] and line["models"] == ["rigid", "nonrigid"]
    assert line["policies"] == ["lqg", "zero"] and line["purpose"] == "a check" and line["command"] == "evaluate"
    assert line["utc"].endswith("+00:00") and ("commit" in line or "version" in line)
    if checkout() is not None:                                   # run from the checkout: its commit
        assert len(line["commit"]) == 40 and isinstance(line["dirty"], bool)


def test_per_policy_counts_calls_and_blocks(tmp_path):
    path = tmp_path / "ledger.jsonl"
    path.write_text(json.dumps({"history": True, "policies": None, "seeds": [[10_000, 10_049]], "n_seeds": 50,
                                "flights": "many", "purpose": "development"}) + "\n")
    for seeds, who in (([10_000, 10_001], ["lqg", "zero"]), ([10_000, 10_001], ["lqg"]), ([12_000], ["lqg"])):
        log_flight(seeds, ["smile-v2"], ["rigid"], who, path=path)
    rows = {r["policy"]: r for r in per_policy(read(path))}
    assert rows["lqg"]["calls"] == 3 and rows["lqg"]["blocks"] == {"10,000-10,001": 2, "12,000": 1}
    assert rows["zero"]["calls"] == 1 and rows["zero"]["history"] == ["10,000-10,049: many"]
    text = table(read(path), ["lqg", "aac"])
    assert "| `lqg` | 3 | 10,000-10,001 (2); 12,000 (1) |" in text and "| `aac` | 0 | - | - |" in text
    assert "- 10,000-10,049: many (development)" in text


def test_evaluate_on_test_seeds_is_logged_and_on_validation_not(capsys):
    suite = get_suite("smile-v2").with_options(mission_time_s=0.2)
    before = len(read())
    evaluate([ZERO], [suite], 1, "validation", "serial", progress=False)
    assert len(read()) == before
    evaluate([ZERO], [suite], 2, "test", "serial", progress=False, purpose="ledger test", first=2_000)
    last = read()[-1]
    assert len(read()) == before + 1 and last["seeds"] == [[12_000, 12_001]] and last["purpose"] == "ledger test"
    assert last["policies"] == ["zero"] and last["suites"] == ["smile-v2"]


def test_named_blocks():
    assert DEVELOPMENT_BLOCK.seeds() == list(range(TEST_SEED0, TEST_SEED0 + 50))
    assert HEADLINE_BLOCK.seeds() == list(range(12_000, 12_200))
    assert get_suite("smile-v2").seeds("test", 200, HEADLINE_BLOCK.first) == HEADLINE_BLOCK.seeds()
    with pytest.raises(ValueError, match="from its seed 9999"):
        get_suite("smile-v2").seeds("test", 2, 9_999)


def test_ledger_command_prints_the_headline_policies(tmp_path, capsys):
    path = tmp_path / "l.jsonl"
    log_flight([10_003], ["smile-v2"], ["rigid"], ["lqg"], path=path)
    text = ledger_cli.main(["--headline", "--file", str(path)])
    assert "| `lqg` | 1 | 10,003 (1) |" in text and "| `gs-pd-relief` | 0 | - | - |" in text
    ledger_cli.announce("prog", [3, 10_004, 10_002])
    assert capsys.readouterr().err.startswith("prog: flying 2 test seeds (10,002-10,004)")
