"""The headline that decides (lvgym.benchmark.selection, lvgym headline, lvgym compare-headline): the choice by
the headline's rule, the refusal of a selection made with uncommitted changes, the rows on a block by hand, and a
rehearsal of `fly` on validation seeds with tiny missions (never the test block)."""

import json

import pytest

from lvgym.benchmark.ledger import read
from lvgym.benchmark.selection import block_rows, block_table, check_selection, choose
from lvgym.cli import headline as cli
from lvgym.cli.results_page import compare_main, page_main, page_text


def _rec(policy, cond, seed, score, lost=False):
    return {"suite": "s", "condition": f"s/{cond}", "policy": policy, "seed": seed, "score_v2": score,
            "failed": lost, "flyable": True, "group": "s", "model": cond, "wind": "none", "failure_reason": "x" * lost}


KINDS = {"c1": "classical", "c2": "classical", "l1": "learned", "p": "privileged", "z": "none"}


def test_choose_pools_both_models_and_never_names_a_policy_lost_on_more_than_half():
    recs = []
    for seed in range(4):
        for cond in ("rigid", "nonrigid"):
            recs += [_rec("c1", cond, seed, 1.0), _rec("c2", cond, seed, 0.5, lost=seed < 3),   # c2: lost 6 of 8
                     _rec("l1", cond, seed, 2.0 if cond == "rigid" else 0.2), _rec("p", cond, seed, 0.1),
                     _rec("z", cond, seed, 3.0)]
    chosen = choose(recs, KINDS, {"s": ["z", "c1", "c2", "l1", "p"]})["s"]
    assert (chosen["classical"], chosen["learned"], chosen["privileged"]) == ("c1", "l1", "p")
    assert chosen["validation"]["l1"] == {"score_v2": pytest.approx(1.1), "lost": 0.0, "n": 8}   # both models
    assert chosen["validation"]["c2"]["lost"] == pytest.approx(0.75)
    assert choose(recs, KINDS, {"s": ["z", "c2", "p"]})["s"]["classical"] is None              # none flyable


def test_check_selection():
    assert "no selection file" in check_selection(None)
    assert "no git commit" in check_selection({"version": "0.1.0"})
    assert "uncommitted changes" in check_selection({"commit": "a" * 40, "dirty": True})
    assert check_selection({"commit": "a" * 40, "dirty": False}) == ""


def test_block_rows_by_hand():
    recs = [_rec("c1", "rigid", s, v) for s, v in enumerate((2.0, 2.0, 4.0, 4.0))]
    recs += [_rec("l1", "rigid", s, v, lost=(s == 3)) for s, v in enumerate((1.0, 2.0, 3.0, 2.0))]
    cont = [_rec("c1", "rigid", 0, 2.0), _rec("l1", "rigid", 0, 1.0)]
    sel = {"suites": {"s": {"classical": "c1", "learned": "l1", "privileged": None}}}
    (row,) = block_rows(recs, cont, sel)
    assert row["gain"]["gain"] == pytest.approx(1.0 - 2.0 / 3.0) and row["gain"]["n"] == 4
    assert (row["both"]["n"], row["both"]["mean_a"], row["both"]["mean_b"]) == (3, 2.0, pytest.approx(8.0 / 3.0))
    assert row["continuity"]["gain"] == pytest.approx(0.5) and row["privileged"] is None
    assert row["learned"]["failed_count"] == 1 and row["learned"]["n"] == 4
    line = block_table([row])[2]
    assert "| +33 % [" in line and "2.667, 2.000 (3 of 4)" in line and "+50 % [+50, +50] (n 1)" in line


def _selection(path, dirty=False, **extra):
    doc = {"made_utc": "2026-12-07T00:00:00+00:00", "commit": "f" * 40, "dirty": dirty, "n_seeds": 200,
           "overrides": {}, "suites": {"smile-v2": {"classical": "lqg", "learned": "gs-pid-flex",
                                                    "privileged": "privileged", "validation": {},
                                                    "reported": [{"policy": "lqg", "joined": "2026-12-05"}]}},
           **extra}
    path.write_text(json.dumps(doc))
    return path


def test_fly_refuses_a_dirty_selection_and_a_short_test_flight(tmp_path):
    before = len(read())
    with pytest.raises(SystemExit, match="uncommitted changes"):
        cli.fly_main(["--selection", str(_selection(tmp_path / "dirty.json", dirty=True)), "--out", str(tmp_path)])
    with pytest.raises(SystemExit, match="only from a protocol selection"):
        cli.fly_main(["--selection", str(_selection(tmp_path / "s.json", n_seeds=2)), "--out", str(tmp_path)])
    with pytest.raises(SystemExit, match="no selection file"):
        cli.fly_main(["--selection", str(tmp_path / "none.json"), "--out", str(tmp_path)])
    flown = tmp_path / "headline.json"                              # the block flown from this selection already
    flown.write_text(json.dumps({"meta": {"seed_set": "test", "made_utc": "2026-12-08T00:00:00+00:00",
                                          "selection": {"made_utc": "2026-12-07T00:00:00+00:00"}}}))
    with pytest.raises(SystemExit, match="flown once per selection"):
        cli.fly_main(["--selection", str(_selection(tmp_path / "ok.json")), "--record", str(flown),
                      "--out", str(tmp_path)])
    assert len(read()) == before                                    # nothing flew, nothing logged


def test_fly_rehearsal_on_validation_seeds_then_page_and_compare(tmp_path, capsys):
    before = len(read())
    sel = _selection(tmp_path / "sel.json")
    record = cli.fly_main(["--selection", str(sel), "--seed-set", "validation", "--episodes", "2",
                           "--mission-time-s", "3", "--out", str(tmp_path / "out"), "--executor", "serial",
                           "--no-progress"])
    assert len(read()) == before                                    # validation seeds: no ledger line
    assert [r["model"] for r in record["rows"]] == ["rigid", "nonrigid"] and record["continuity"] == []
    assert {e["seed"] for e in record["episodes"]} == {0, 1} and len(record["episodes"]) == 12
    assert (tmp_path / "out" / "smile-v2" / "results.json").exists()
    path = tmp_path / "out" / "headline.json"
    assert json.loads(path.read_text())["meta"]["selection"]["commit"] == "f" * 40
    text = page_main(["--record", str(path), "--out", str(tmp_path / "results.md")])
    assert "| smile-v2 | rigid | `lqg` " in text and "`lqg` (2026-12-05)" in text
    assert "has not been flown yet" in page_text(None)
    capsys.readouterr()
    table = compare_main([str(tmp_path / "out" / "smile-v2"), "--record", str(path)])
    assert "| smile-v2 | rigid | `lqg` |" in table and "`lqg`: +0 % [+0, +0] (n 2)" in table


def test_fly_on_the_test_block_asks_evaluate_for_the_block_and_the_continuity_seeds(tmp_path, monkeypatch):
    """The test path without a flight: evaluate is replaced by a stand-in that records what it was asked."""
    asked = []

    def fake_evaluate(argv):
        asked.append(argv)
        seeds = range(12_000, 12_002) if "headline-200" in argv else range(10_000, 10_002)
        return {"records": [_rec(p, m, s, 1.0 if p == "lqg" else 0.5) | {"suite": "smile-v2",
                                                                          "condition": f"smile-v2/{m}"}
                            for p in ("lqg", "gs-pid-flex", "privileged") for m in ("rigid", "nonrigid")
                            for s in seeds]}

    monkeypatch.setattr(cli, "evaluate_main", fake_evaluate)
    record = cli.fly_main(["--selection", str(_selection(tmp_path / "sel.json")), "--record",
                           str(tmp_path / "headline.json"), "--out", str(tmp_path / "out"), "--no-progress"])
    block, cont = asked
    assert block[block.index("--block") + 1] == "headline-200" and cont[cont.index("--block") + 1] == "development-50"
    assert block[block.index("--policies") + 1:block.index("--only")] == ["lqg", "gs-pid-flex", "privileged"]
    assert cont[cont.index("--purpose") + 1].endswith("(continuity: the development seeds)")
    assert record["meta"]["block"] == "headline-200 (test seeds 12,000-12,199)"
    row = record["rows"][0]
    assert row["gain"]["gain"] == pytest.approx(0.5) and row["continuity"]["gain"] == pytest.approx(0.5)
    with pytest.raises(SystemExit, match="flown once per selection"):               # and only once
        cli.fly_main(["--selection", str(tmp_path / "sel.json"), "--record", str(tmp_path / "headline.json"),
                      "--out", str(tmp_path / "out")])
