"""The error budget (experiments.error_budget.budget): the variants by hand, the shares against hand numbers, and a short
flight whose nominal row equals the runner's episodes of the same condition."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from experiments.error_budget import budget
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import run_episode
from lvgym.benchmark.suites import V1_DISPERSIONS, get_suite
from lvgym.environment import make
from lvgym.environment.wind import RandomGustWind
from lvgym.envs.spec import wind_spec

PLANT = tuple(sorted(set(V1_DISPERSIONS) - {"wind", "thrust_misalignment", "sensor_noise"}))


def smile_nonrigid():
    return next(c for c in get_suite("smile-v1").conditions if c.model == "nonrigid")


def test_sources_of_smile_v1():
    src = budget.sources(smile_nonrigid())
    assert list(src) == ["turbulence", "gust", "thrust_misalignment", "sensor_noise", "plant"]
    assert src["gust"] == (("gust",), ())
    assert src["sensor_noise"] == ((), ("sensor_noise",))
    assert src["plant"] == ((), PLANT)                                      # 11 dispersions that move the plant


def test_variants_of_smile_v1_by_hand():
    cond = smile_nonrigid()
    v = budget.variants(cond)
    assert list(v) == ["nominal", "none"] + [f"{k} {s}" for s in ("turbulence", "gust", "thrust_misalignment",
                                                                   "sensor_noise", "plant") for k in ("without", "only")]
    assert (v["nominal"].wind, v["nominal"].randomize) == ("turbulence_gust", cond.randomize)
    assert (v["none"].wind, v["none"].randomize) == ("none", ("wind",))      # ``wind`` is kept: not a source
    assert v["without turbulence"].wind == "random_gust"
    assert v["without gust"].wind == "turbulence"
    assert (v["only gust"].wind, v["only gust"].randomize) == ("random_gust", ("wind",))
    assert v["without sensor_noise"].randomize == tuple(r for r in cond.randomize if r != "sensor_noise")
    assert v["without sensor_noise"].wind == "turbulence_gust"
    assert (v["only thrust_misalignment"].wind, v["only thrust_misalignment"].randomize) == (
        "none", ("thrust_misalignment", "wind"))
    assert (v["only plant"].wind, set(v["only plant"].randomize)) == ("none", set(PLANT) | {"wind"})
    assert v["without plant"].randomize == ("sensor_noise", "thrust_misalignment", "wind")
    for label, c in v.items():                       # the rest of the condition is untouched
        assert (c.env_id, c.model, c.options, c.group) == (cond.env_id, cond.model, cond.options, cond.group)
        assert c.name == f"{cond.name}|{label}"


def test_a_tier_without_parts_is_one_source():
    cond = next(c for c in get_suite("smile-v1-maxq-gust").conditions if c.model == "rigid")
    v = budget.variants(cond)
    assert list(budget.sources(cond))[0] == "wind"
    assert v["without wind"].wind == "none" and v["only wind"].wind == "maxq_gust"


def record(variant, seed, score, failed=False, base="c"):
    return {"policy": "p", "base": base, "variant": variant, "seed": seed, "score": score, "failed": failed,
            **{f"rate_error_{p}_rad": score / 4 for p in budget.PHASES}}


def test_shares_against_hand_numbers():
    recs = [record("nominal", 0, 1.0), record("nominal", 1, 2.0),
            record("without x", 1, 1.0), record("without x", 0, 0.5),       # order of seeds does not matter
            record("only x", 0, 0.3, failed=True), record("only x", 1, 0.6)]
    rows = {r["variant"]: r for r in budget.budget_rows(recs)}
    assert rows["nominal"]["score"] == pytest.approx(1.5)
    assert rows["without x"]["share_removed"] == pytest.approx((0.5 + 1.0) / 2 / 1.5)          # 0.5
    assert rows["without x"]["share_removed_low"] <= 0.5 <= rows["without x"]["share_removed_high"]
    assert math.isnan(rows["without x"]["share_alone"])
    assert rows["only x"]["share_alone"] == pytest.approx(0.45 / 1.5)                           # 0.3
    assert rows["only x"]["failures"] == 1 and rows["only x"]["episodes"] == 2
    assert rows["only x"]["boost_rad"] == pytest.approx(0.45 / 4)
    assert math.isnan(rows["nominal"]["share_removed"])
    table = budget.budget_table(list(rows.values()))
    assert "| p | c | without x | 0.7500" in table and "| 30 % |" in table


def test_shares_need_the_nominal():
    with pytest.raises(ValueError, match="no nominal"):
        budget.budget_rows([record("only x", 0, 0.3)])


def test_random_gust_tier_is_the_gust_alone():
    """The ``random_gust`` tier is the random 1-cosine gust of ``turbulence_gust`` without the steady wind and
    the turbulence: calm below its onset, a gust of the drawn amplitude inside it."""
    wind = make("wind", wind_spec("random_gust", 70.0))
    wind.reset(np.random.default_rng(3))
    (gust,) = wind.children
    assert isinstance(gust, RandomGustWind)
    onset, length, amplitude = (gust.drawn[k] for k in ("onset", "length", "amplitude"))
    np.testing.assert_array_equal(wind.velocity_ned(onset - 1.0), 0.0)
    assert np.linalg.norm(wind.velocity_ned(onset + length)) == pytest.approx(amplitude)   # the 1-cosine's peak
    full = make("wind", wind_spec("turbulence_gust", 70.0))
    assert [type(m) for m in full.children][-1] is RandomGustWind
    cond = smile_nonrigid().with_options(mission_time_s=3.0)
    env = budget.variants(cond)["only gust"].make_env()
    env.reset(seed=3)
    assert env.unwrapped.task.wind == "random_gust"


def test_short_budget_matches_the_runner(tmp_path):
    """Two seeds of a 3 s flight of lqg: twelve variants, and the nominal row is the runner's own episodes."""
    rows = budget.main(["--policies", "lqg", "--episodes", "2", "--mission-time-s", "3", "--executor", "serial",
                        "--no-progress", "--out", str(tmp_path)])
    assert len(rows) == 12
    assert {p.name for p in tmp_path.iterdir()} == {"episodes.csv", "budget.csv", "budget.json"}
    nominal = next(r for r in rows if r["variant"] == "nominal")
    cond = smile_nonrigid().with_options(mission_time_s=3.0)
    direct = [run_episode(resolve_policy("lqg"), cond, s)["score"] for s in (0, 1)]
    assert nominal["score"] == pytest.approx(np.mean(direct), rel=0, abs=0)
    none = next(r for r in rows if r["variant"] == "none")
    assert none["score"] <= nominal["score"]
    assert all(r["failures"] == 0 for r in rows)


@pytest.mark.parametrize("args, message", [
    (["--episodes", "1"], "--episodes = 1: an integer in [2, 10000]"),
    (["--episodes", "many"], "--episodes = 'many': an integer in [2, 10000]"),
    (["--models", "wobbly"], "--models wobbly: suite 'smile-v1' has ['nonrigid', 'rigid']"),
])
def test_command_line_errors_are_one_line(args, message):
    out = subprocess.run([sys.executable, "-m", "experiments.error_budget.budget", *args, "--no-progress"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], out.stderr
