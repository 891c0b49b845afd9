"""A vehicle file's structural q-alpha limit, constant or over Mach or time (lvgym/vehicle/limits.py): the file's
key and its errors, the env's kernel against numpy's interpolation, a flight that ends on a tabled limit, the
step's info and the score's q-alpha cost at each step's limit, and the option refused beside a file's limit."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from lvgym.benchmark import play_episode
from lvgym.benchmark.policy import ZeroPolicy
import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs.limits import qalpha_task_entries
from lvgym.envs.layouts import TASK
from lvgym.envs.signals import qalpha_limit_rows
from lvgym.errors import ConfigError
from lvgym.vehicle import load_vehicle
from lvgym.vehicle.limits import QAlphaLimit

SMILE = (Path(lvgym.__file__).parent / "vehicles" / "smile_v1.yaml").read_text(encoding="utf-8")
TABLE = "qalpha_limit:\n  over: mach\n  table: [[0.0, 300000], [0.6, 300000], [0.9, 2000]]\n"


def _vehicle(tmp_path: Path, extra: str) -> Path:
    path = tmp_path / "smile_limited.yaml"
    path.write_text(SMILE + "\n" + extra, encoding="utf-8")
    return path


def test_the_file_gives_a_number_or_a_table(tmp_path):
    assert load_vehicle(_vehicle(tmp_path, "qalpha_limit: 180000\n")).qalpha_limit == QAlphaLimit.constant(180e3)
    lim = load_vehicle(_vehicle(tmp_path, TABLE)).qalpha_limit
    assert lim.over == "mach" and lim.table == ((0.0, 3e5), (0.6, 3e5), (0.9, 2e3)) and not lim.is_constant
    np.testing.assert_allclose(lim.at([0.3, 0.75, 2.0], 0.0), [3e5, 151e3, 2e3])
    assert load_vehicle(_vehicle(tmp_path, "")).qalpha_limit is None             # the env's option then


@pytest.mark.parametrize("extra, message", [
    ("qalpha_limit: -5\n", "qalpha_limit = -5"),
    ("qalpha_limit: {over: altitude, table: [[0, 1], [1, 2]]}\n", "qalpha_limit.over = 'altitude'"),
    ("qalpha_limit: {over: time, table: [[0, 1e5], [0, 2e5]]}\n", r"qalpha_limit.table\[1\]"),
    ("qalpha_limit: {over: time, table: [[0, 1e5], [10, 0]]}\n", r"limits in \(0, 1e\+09\] Pa deg"),
    ("qalpha_limit: {over: time, table: [" + ", ".join(f"[{i}, 1e5]" for i in range(9)) + "]}\n", "2 to 8 rows"),
    ("qalpha_limit: {over: time, table: [[0, 1e5], [10, 2e5]], at: 3}\n", "unknown key"),
])
def test_a_bad_limit_names_the_file_the_key_and_what_is_allowed(tmp_path, extra, message):
    with pytest.raises(ConfigError, match=message) as err:
        load_vehicle(_vehicle(tmp_path, extra))
    assert "smile_limited.yaml" in str(err.value)


@pytest.mark.parametrize("over", ["mach", "time"])
def test_the_kernel_interpolates_as_numpy_does(over):
    lim = QAlphaLimit(over, ((0.5, 2e5), (1.0, 1.5e5), (2.5, 2.5e5), (4.0, 2.5e5)))
    task = TASK.pack({"qalpha_limit": 9e9, **qalpha_task_entries(lim)})
    x = np.concatenate([np.linspace(0.0, 5.0, 101), [0.5, 1.0, 2.5, 4.0]])
    t, mach = (x, np.zeros_like(x)) if over == "time" else (np.zeros_like(x), x)
    out = np.empty_like(x)
    qalpha_limit_rows(task, t, mach, out)
    np.testing.assert_allclose(out, lim.at(mach, t), rtol=1e-15)
    const = TASK.pack(qalpha_task_entries(QAlphaLimit.constant(1.23e5)))
    qalpha_limit_rows(const, t, mach, out)
    assert set(out) == {1.23e5}


def test_a_flight_ends_on_the_tabled_limit_and_the_info_follows_it(tmp_path):
    env = gym.make("lvgym/SmileAscent-v1", vehicle=str(_vehicle(tmp_path, TABLE)), wind="none", randomize=[])
    env.reset(seed=0)
    done, info, limits, qalpha = False, {}, [], []
    while not done:
        _, reward, terminated, truncated, info = env.step(np.zeros(2, np.float32))
        done = terminated or truncated
        limits.append(info["qalpha_limit_pa_deg"])
        qalpha.append(info["qalpha_pa_deg"])
        if not done:
            assert info["qalpha_limit_pa_deg"] == pytest.approx(np.interp(info["mach"], [0, 0.6, 0.9], [3e5, 3e5, 2e3]))
    assert info["termination"] == "q-alpha beyond the structural limit" and 0.6 < info["mach"]
    assert info["qalpha_pa_deg"] > info["qalpha_limit_pa_deg"]
    # the score's q-alpha cost counts the steps above 80 % of each step's own limit
    want = np.sum(np.array(qalpha) > 0.8 * np.array(limits)) * env.unwrapped.task.control_dt_s
    assert play_episode(ZeroPolicy(), env, 0)["qalpha_cost_s"] == pytest.approx(want) and want > 0.0


def test_the_shipped_vehicles_keep_the_option_and_both_set_is_refused(tmp_path):
    env = gym.make("lvgym/SmileAscent-v1", qalpha_limit_pa_deg=123e3)
    env.reset(seed=0)
    assert env.step(np.zeros(2, np.float32))[4]["qalpha_limit_pa_deg"] == 123e3
    with pytest.raises(ConfigError, match="qalpha_limit_pa_deg = 123000.0: its default"):
        gym.make("lvgym/SmileAscent-v1", vehicle=str(_vehicle(tmp_path, TABLE)), qalpha_limit_pa_deg=123e3)
