"""experiments.training_speed.train_speed: throughput read from a run's progress table, by hand."""

import pytest

from experiments.training_speed.train_speed import speed_table, throughput

HEADER = "time/time_elapsed,time/fps,time/total_timesteps,time/train_wall_s,time/iterations,time/env_share\n"


def test_throughput_leaves_the_first_rollout_out(tmp_path):
    p = tmp_path / "progress_000000000000.csv"
    p.write_text(HEADER + "9,900,8192,9.5,1,0.30\n12,1300,16384,11.5,2,0.40\n14,1700,24576,13.5,3,0.45\n")
    r = throughput(p)
    assert r["steps_per_s"] == pytest.approx((24576 - 8192) / (13.5 - 9.5))
    assert r["env_share"] == 0.45 and r["rows"] == 3


def test_throughput_needs_two_rollouts(tmp_path):
    p = tmp_path / "progress_000000000000.csv"
    p.write_text(HEADER + "9,900,8192,9.5,1,0.30\n")
    with pytest.raises(ValueError, match="at least 2"):
        throughput(p)


def test_speed_table_medians_and_ratio():
    table = speed_table({"a": [{"steps_per_s": 1000.0, "env_share": 0.4}, {"steps_per_s": 1200.0, "env_share": 0.5}],
                         "b": [{"steps_per_s": 2200.0, "env_share": 0.6}]})
    assert "| a | 1,100 | 1,000, 1,200 | 1.00 | 0.45 |" in table
    assert "| b | 2,200 | 2,200 | 2.00 | 0.60 |" in table
