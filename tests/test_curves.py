"""``lvgym curves`` (lvgym.agents.training.curves): learning curves from run folders (hand-made folders here:
the fields are the ones CheckpointCallback writes, test_agents.py checks that it writes them)."""

from __future__ import annotations

import json
import math

import pytest

from lvgym.agents.training import curves


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


def test_v2_scores_rollouts_and_the_iqm_over_seeds(tmp_path, capsys):
    """score_v2 where the validation has it; the rollouts' cost from progress_*.csv (ppo-fast's and SB3's); the
    IQM over the seeds of one configuration: of 4 runs the mean of the middle two, of 3 runs (25 % of 3 rounds
    to none cut) the mean."""
    def v2(score, bad=0.0):
        return {**_condition(score + 1.0), "score_v2_mean": score, "failure_rate_v2": bad}

    runs = []
    for seed, (a, b) in enumerate([(0.9, 0.5), (0.8, 0.7), (1.3, 0.6), (0.7, 0.2)]):
        run = _run(tmp_path / f"fast-smile-v2-s{seed}-20261208-010203", [
            {"num_timesteps": 100, "train_wall_s": 10.0 + seed, "conditions": {"s/nonrigid": v2(a)}},
            {"num_timesteps": 200, "train_wall_s": 20.0 + seed, "conditions": {"s/nonrigid": v2(b, 0.1 * seed)}}],
            "time/total_timesteps,time/time_elapsed,time/train_wall_s,rollout/cost_mean,rollout/failure_rate\n"
            f"50,5,5,{2 + seed},0.5\n100,9,9,{1 + seed},0.25\n")
        runs.append(run)
    rows = curves.load_curves(runs[0])
    assert [(r["score"], r["failure_rate"]) for r in rows] == [(0.9, 0.0), (0.5, 0.0)]       # v2's, not v1's
    assert curves.config_name(runs[0].name) == "fast-smile-v2" == curves.config_name("fast-smile-v2-s12")
    roll = curves.load_rollouts(runs[2])
    assert [(r["num_timesteps"], r["train_wall_s"], r["cost"], r["failure_rate"]) for r in roll] == [
        (50, 5.0, 4.0, 0.5), (100, 9.0, 3.0, 0.25)]
    allrows = [r for run in runs for r in curves.load_curves(run)]
    iqm = {(r["source"], r["num_timesteps"]): r for r in curves.iqm_rows(allrows, "validation", "score")}
    assert iqm["validation", 100]["iqm"] == pytest.approx((0.8 + 0.9) / 2)          # sorted 0.7 0.8 0.9 1.3
    assert iqm["validation", 200]["iqm"] == pytest.approx((0.5 + 0.6) / 2)          # sorted 0.2 0.5 0.6 0.7
    assert iqm["validation", 200]["low"] <= iqm["validation", 200]["iqm"] <= iqm["validation", 200]["high"]
    assert iqm["validation", 200]["train_wall_s"] == pytest.approx(21.5) and iqm["validation", 200]["runs"] == 4
    three = [r for run in runs[:3] for r in curves.load_rollouts(run)]
    (first, last) = curves.iqm_rows(three, "rollouts", "cost")
    assert (first["iqm"], last["iqm"], last["condition"]) == (pytest.approx(3.0), pytest.approx(2.0), "rollouts")
    old = _run(tmp_path / "sb3-run", [{"num_timesteps": 10, "conditions": {"s/rigid": _condition(0.5)}}],
               "time/time_elapsed,time/total_timesteps,rollout/ep_rew_mean\n3,10,-1.25\n")
    assert [(r["cost"], r["train_wall_s"]) for r in curves.load_rollouts(old)] == [(1.25, 3.0)]
    curves.main([str(r) for r in runs] + ["--out", str(tmp_path / "out")])
    text = capsys.readouterr().out
    assert "| fast-smile-v2 | validation | nonrigid | 4 | 0.00 | 0.4 | 0.5500 [" in text
    for name, lines in (("curves.csv", 9), ("rollouts.csv", 9), ("iqm.csv", 5)):
        assert (tmp_path / "out" / name).read_text().count("\n") == lines, name
    assert (tmp_path / "out" / "curves.png").stat().st_size > 0
