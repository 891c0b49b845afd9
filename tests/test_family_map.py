"""The family design map's bookkeeping (experiments.family_map.design_map) on hand-made cells: the shares, the
ratios, where the rigid design holds, the CSV lines and the figures. The flights themselves are the
evaluation's (tested elsewhere); the study is run by its command."""

from __future__ import annotations

import math

import numpy as np

from experiments.family_map import design_map as dm


def _cell(ld: float, tw: float, bad: dict[tuple[str, str], int], score: dict[tuple[str, str], float],
          unflyable: dict[tuple[str, str], int] | None = None) -> dict:
    """A cell's record: ``bad`` failed flights, plus ``unflyable`` ones that did not fail."""
    more = unflyable or {}
    flights = [{"policy": p, "model": m, "episodes": 5, "bad": bad.get((p, m), 0) + more.get((p, m), 0),
                "failed": bad.get((p, m), 0),
                "score_v2": score.get((p, m), 1.0)} for p in dm.POLICIES for m in dm.MODELS]
    return {"ld": ld, "tw": tw, "seed": 0, "finned": False, "stages": 1, "design_s": 40.0, "cached": False,
            "flex_rows_met": 8, "lqg_rows_met": 7, "rigid_rows_stable_nonrigid": 6, "rows": 8, "flights": flights}


CELLS = [
    _cell(10.0, 1.3, {}, {("auto-lqg", "rigid"): 0.4, ("auto-lqg", "nonrigid"): 0.6},
          {("auto-gs-pid", "rigid"): 5}),                           # unflyable, not failed: it holds
    _cell(20.0, 1.3, {("auto-gs-pid", "nonrigid"): 3}, {}),
    _cell(10.0, 2.5, {("auto-gs-pid", "rigid"): 5, ("auto-gs-pid", "nonrigid"): 5}, {}),
    _cell(20.0, 2.5, {("auto-gs-pid", "rigid"): 1}, {}),
    {"ld": 20.0, "tw": 2.5, "seed": 1000, "flights": []},          # a cell's second draw without a vehicle
]


def test_shares_ratios_and_holding_by_hand():
    grid = dm._grid(CELLS, [10.0, 20.0], [1.3, 2.5], lambda c: dm._flight(c, "auto-gs-pid", "nonrigid", "bad"))
    assert np.array_equal(grid, [[0.0, 0.6], [1.0, 0.0]])
    assert dm._flight(CELLS[:1], "auto-gs-pid", "rigid", "bad") == 1.0
    assert dm._flight(CELLS[:1], "auto-gs-pid", "rigid", "failed") == 0.0
    ratio = dm._grid(CELLS, [10.0, 20.0], [1.3, 2.5],
                     lambda c: dm._flight(c, "auto-lqg", "nonrigid", "score") / dm._flight(c, "auto-lqg", "rigid", "score"))
    assert math.isclose(ratio[0, 0], 1.5) and ratio[1, 1] == 1.0
    assert [dm.HOLDS[dm.holding([c])] for c in CELLS[:4]] == [
        "holds both", "holds the rigid vehicle only", "holds neither", "holds the flexible vehicle only"]
    assert dm.flown(CELLS) == CELLS[:4]
    empty = dm._grid(CELLS, [10.0, 30.0], [1.3], lambda c: 1.0)
    assert empty[0, 0] == 1.0 and math.isnan(empty[0, 1])


def test_csv_lines_and_figures(tmp_path):
    lines = dm.cell_rows(CELLS)
    assert len(lines) == 4 * len(dm.POLICIES) * len(dm.MODELS)
    assert lines[0] == {"ld": 10.0, "tw": 1.3, "seed": 0, "finned": False, "stages": 1, "policy": "privileged",
                        "model": "rigid", "episodes": 5, "bad": 0, "failed": 0, "score_v2": 1.0}
    paths = dm.draw(CELLS, [10.0, 20.0], [1.3, 2.5], tmp_path)
    assert [p.name for p in paths] == ["failures.png", "ratio.png", "rigid_design.png"]
    assert all(p.stat().st_size > 10_000 for p in paths)
