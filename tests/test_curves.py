"""``python -m experiments.training_speed.curves``: learning curves against wall time from run folders (hand-made folders here:
the fields are the ones CheckpointCallback writes, test_agents.py checks that it writes them)."""

from __future__ import annotations

import json
import math

import pytest

from experiments.training_speed import curves


def _condition(score: float, failures: float = 0.0) -> dict:
    return {"score_mean": score, "failure_rate": failures, "rate_error_rad_mean": score}


def _run(folder, evaluations, progress: str | None = None):
    folder.mkdir()
    (folder / "evaluations.json").write_text(json.dumps(evaluations))
    if progress is not None:
        (folder / "progress_000000000000.csv").write_text(progress)
    return folder


def test_curves_reach_and_best(tmp_path, capsys):
    run = _run(tmp_path / "robust-x-nonrigid-s0", [
        {"num_timesteps": 100, "train_wall_s": 60.0, "conditions": {"s/nonrigid": _condition(0.9), "s/rigid": _condition(0.5)}},
        {"num_timesteps": 200, "train_wall_s": 120.0, "conditions": {"s/nonrigid": _condition(0.6, 0.1), "s/rigid": _condition(0.4)}},
        {"num_timesteps": 300, "train_wall_s": 180.0, "conditions": {"s/nonrigid": _condition(0.65), "s/rigid": _condition(0.45)}},
    ])
    rows = curves.load_curves(run)
    assert len(rows) == 6 and {r["condition"] for r in rows} == {"nonrigid", "rigid"}
    non = [r for r in rows if r["condition"] == "nonrigid"]
    assert curves.reached(non, 0.7) == 180.0          # 0.6 at 120 s had a failure: it does not count
    assert curves.reached(non, 0.5) is None
    table = {t["condition"]: t for t in curves.summary_rows(rows, {"lqg/nonrigid": 0.7, "any": 0.5})}
    assert table["nonrigid"]["best"] == 0.65 and table["nonrigid"]["best_steps"] == 300     # fewest failures first
    assert table["nonrigid"]["reached lqg/nonrigid"] == 180.0 and table["rigid"]["reached lqg/nonrigid"] is None
    assert table["rigid"]["reached any"] == 60.0 and table["rigid"]["first"] == 0.5
    curves.main([str(run), "--reference", "lqg/nonrigid=0.7", "--out", str(tmp_path / "out")])
    text = capsys.readouterr().out
    assert "| robust-x-nonrigid-s0 | nonrigid | 0.9000 | 0.6500 | 0% | 0.00 | 3.0 | 3.0 |" in text
    assert (tmp_path / "out" / "curves.png").stat().st_size > 0
    assert (tmp_path / "out" / "curves.csv").read_text().count("\n") == 7


def test_old_runs_take_the_wall_time_from_the_progress_file(tmp_path):
    progress = "time/time_elapsed,time/total_timesteps\n10,50\n21,100\n40,200\n"
    run = _run(tmp_path / "old", [{"num_timesteps": 100, "conditions": {"s/rigid": _condition(0.5)}},
                                  {"num_timesteps": 250, "conditions": {"s/rigid": _condition(0.4)}}], progress)
    assert [r["train_wall_s"] for r in curves.load_curves(run)] == [21.0, 40.0]
    assert math.isnan(curves.load_curves(_run(tmp_path / "early", [
        {"num_timesteps": 10, "conditions": {"s/rigid": _condition(0.5)}}], progress))[0]["train_wall_s"])


def test_bad_inputs_are_one_line(tmp_path, capsys):
    with pytest.raises(SystemExit):
        curves.main([str(tmp_path)])
    assert "no evaluations.json" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        curves.main([str(tmp_path), "--reference", "lqg"])
    assert "NAME[/CONDITION]=SCORE" in capsys.readouterr().err
