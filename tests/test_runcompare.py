"""Agents compared over training runs across results folders (experiments.training_configurations.runcompare), against hand numbers."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from experiments.training_configurations import runcompare
from lvgym.errors import ConfigError

SUITE, COND = "smile-v1", "smile-v1/nonrigid"


def write(folder: Path, scores: dict[str, list[float]], seeds: list[int] | None = None) -> Path:
    """An evaluate.py-like folder whose episodes.csv holds ``scores[policy][i]`` on seed ``seeds[i]``."""
    folder.mkdir(parents=True, exist_ok=True)
    seeds = seeds or [10000 + i for i in range(len(next(iter(scores.values()))))]
    with open(folder / "episodes.csv", "w", newline="") as f:
        w = csv.DictWriter(f, ["suite", "condition", "policy", "seed", "score", "rate_error_rad"])
        w.writeheader()
        for pol, vals in scores.items():
            for s, v in zip(seeds, vals):
                w.writerow({"suite": SUITE, "condition": COND, "policy": pol, "seed": s, "score": v,
                            "rate_error_rad": v})
    return folder


def test_matrices_group_runs_and_keep_the_common_seeds(tmp_path):
    a = write(tmp_path / "a", {"ppo-s0": [1, 2, 3], "ppo-s1": [4, 5, 6], "lqg": [7, 8, 9]})
    b = write(tmp_path / "b", {"rppo-s0": [1, 1], "lqg": [7, 8]})
    mats, seeds = runcompare.agent_matrices(runcompare.merge([a, b]), SUITE, COND)
    assert seeds == [10000, 10001]                       # the seeds every policy flew
    assert set(mats) == {"ppo", "rppo", "lqg"}
    np.testing.assert_array_equal(mats["ppo"], [[1, 2], [4, 5]])
    np.testing.assert_array_equal(mats["lqg"], [[7, 8]])


def test_iqm_and_probability_of_improvement_against_hand_numbers(tmp_path):
    # per episode, runs of "a" score 1 and 3, runs of "b" 2 and 4: of the four pairs a is lower in three
    # (1<2, 1<4, 3<4), so P(a better than b) = 0.75 on every episode
    a = write(tmp_path / "a", {"a-s0": [1.0] * 4, "a-s1": [3.0] * 4, "b-s0": [2.0] * 4, "b-s1": [4.0] * 4,
                               "c-s0": [1.0, 2.0, 3.0, 4.0], "c-s1": [5.0, 6.0, 7.0, 8.0]})
    rows = runcompare.compare_agents(runcompare.merge([a]), reps=200)
    est = {r["agent"]: r for r in rows if r["kind"] == "iqm"}
    assert est["a"]["iqm"] == pytest.approx(2.0)          # pooled 1,1,1,1,3,3,3,3: middle half 1,1,3,3
    assert est["c"]["iqm"] == pytest.approx(4.5)          # 1..8: middle half 3,4,5,6
    assert est["c"]["mean"] == pytest.approx(4.5)
    assert [r["agent"] for r in rows if r["kind"] == "iqm"] == ["a", "b", "c"]      # ordered by IQM
    p = {(r["agent"], r["other"]): r for r in rows if r["kind"] == "p_improvement"}
    assert set(p) == {("a", "b"), ("a", "c"), ("b", "c")}
    assert p[("a", "b")]["p"] == pytest.approx(0.75)
    assert p[("a", "b")]["ci_low"] <= 0.75 <= p[("a", "b")]["ci_high"]   # the bootstrap resamples the runs
    # per episode, a's runs 1 and 3 against c's 1|5, 2|6, 3|7, 4|8 (a tie counts one half): 2.5, 3, 3.5, 4 of 4
    assert p[("a", "c")]["p"] == pytest.approx(np.mean([0.625, 0.75, 0.875, 1.0]))


def test_one_label_with_two_values_is_refused(tmp_path):
    a = write(tmp_path / "a", {"lqg": [1.0, 2.0]})
    b = write(tmp_path / "b", {"lqg": [1.0, 2.5]})
    with pytest.raises(ConfigError, match=r"nonrigid/lqg seed 10001.*2\.5.*one label, one policy"):
        runcompare.merge([a, b])


def test_bad_inputs_name_what_is_allowed(tmp_path):
    a = write(tmp_path / "a", {"lqg": [1.0]})
    with pytest.raises(ConfigError, match="episodes.csv"):
        runcompare.read_episodes(tmp_path / "missing")
    with pytest.raises(ConfigError, match="--metric.*rate_error_rad"):
        runcompare.read_episodes(a, "effort")
    with pytest.raises(ConfigError, match="--metric.*a numeric column.*'smile-v1'"):
        runcompare.read_episodes(a, "suite")
    with pytest.raises(ConfigError, match="--condition.*smile-v1/nonrigid"):
        runcompare.compare_agents(runcompare.merge([a]), ["rigid"])


def test_command_line(tmp_path):
    a = write(tmp_path / "a", {"x-s0": [1.0, 2.0], "x-s1": [1.5, 2.5], "lqg": [3.0, 3.0]})
    run = subprocess.run([sys.executable, "-m", "experiments.training_configurations.runcompare", str(a), "--condition", "nonrigid",
                          "--reps", "100"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "| smile-v1 | smile-v1/nonrigid | x | 2 | 2 |" in run.stdout
    assert "| smile-v1 | smile-v1/nonrigid | x | lqg | 1.000 [1.000, 1.000] |" in run.stdout
    bad = subprocess.run([sys.executable, "-m", "experiments.training_configurations.runcompare", str(tmp_path / "nope")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 1
    assert bad.stderr.strip().count("\n") == 0 and "episodes.csv" in bad.stderr
