"""The benchmark protocol (lvgym.benchmark) and evaluate.py: metrics by hand, determinism of the table
across runs and executors, Ray, the SB3 adapter and the command line end to end on a tiny case (the result
files: tests/test_result_files.py)."""

from __future__ import annotations

import csv
import importlib.util
import io
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lvgym.benchmark import (SUITES, ZERO, PolicySpec, Trajectory, ZeroPolicy, cvar,
                             degradation, episode_metrics, evaluate, get_suite, markdown_table, play_episode,
                             run_episode, summarize)
from lvgym.benchmark.results import csv_text
from lvgym.benchmark.suites import TEST_SEED0, VALIDATION_SEED0
from test_result_files import _complete, _evaluate_cmd

ROOT = Path(__file__).resolve().parents[1]
SHORT = 3.0   # s: mission time of the short episodes used here


def short_suite(name: str = "smile-windy"):
    return get_suite(name).with_options(mission_time_s=SHORT)


# ---------------------------------------------------------------------------------------------- metrics
def hand_trajectory(termination: str = "q-alpha beyond the structural limit") -> Trajectory:
    return Trajectory(
        dt_s=0.5,
        rate_error_radps=np.array([[0.1, 0.2, 0.0], [0.0, -0.4, 0.1], [0.3, 0.0, 0.2], [0.0, 0.2, 0.0]]),
        gimbal_rad=np.array([[0.01, -0.02], [0.0, 0.0], [0.03, 0.01], [-0.01, 0.0]]),
        alpha_total_rad=np.array([0.5, 0.1, 0.05, 0.02]),
        qalpha_pa_deg=np.array([10.0, 200.0, np.nan, 50.0]),
        reward=np.array([-1.0, -2.0, -0.5, 0.0]),
        time_s=np.array([0.5, 1.0, 1.5, 2.0]),
        qbar_pa=np.array([100.0, 6000.0, 20000.0, 4000.0]),
        termination=termination)


def test_episode_metrics_by_hand():
    m = episode_metrics(hand_trajectory())
    # pitch |e| = 0.2, 0.4, 0, 0.2 -> 0.8 * 0.5 s; yaw 0, 0.1, 0.2, 0 -> 0.3 * 0.5; roll 0.4 * 0.5
    assert m["rate_error_pitch_rad"] == pytest.approx(0.4)
    assert m["rate_error_yaw_rad"] == pytest.approx(0.15)
    assert m["rate_error_roll_rad"] == pytest.approx(0.2)
    assert m["rate_error_rad"] == pytest.approx(0.55)
    assert m["max_rate_pitch_radps"] == pytest.approx(0.4)
    assert m["max_rate_yaw_radps"] == pytest.approx(0.2)
    assert m["max_rate_radps"] == pytest.approx(0.4)
    # |gimbal| sums 0.03 + 0 + 0.04 + 0.01 = 0.08 -> 0.04 rad s
    assert m["effort_rad_s"] == pytest.approx(0.04)
    # alpha counts where qbar >= 5 kPa (steps 2 and 3): 0.1; the 0.5 rad at 100 Pa does not
    assert m["max_alpha_rad"] == pytest.approx(0.1)
    assert m["max_qalpha_pa_deg"] == pytest.approx(200.0)      # the NaN sample is ignored
    assert m["episode_return"] == pytest.approx(-3.5)
    assert m["duration_s"] == 2.0
    assert m["failed"] is True and m["failure_reason"] == "q-alpha beyond the structural limit"
    ok = episode_metrics(hand_trajectory(termination=""))
    assert ok["failed"] is False and ok["failure_reason"] == ""


def test_cvar_is_the_mean_of_the_worst_tenth():
    x = np.arange(1.0, 21.0)                      # 20 values: the worst 2 are 19 and 20
    assert cvar(x) == pytest.approx(19.5)
    assert cvar(x, higher_is_worse=False) == pytest.approx(1.5)
    assert cvar([3.0, 1.0, 2.0]) == 3.0           # fewer than 10: the single worst
    assert cvar(np.arange(11.0)) == pytest.approx(9.5)   # 11 values: ceil(1.1) = 2
    assert math.isnan(cvar([]))


def _rec(cond: str, model: str, value: float, failed: bool = False) -> dict:
    m = episode_metrics(hand_trajectory(""))
    m.update(rate_error_rad=value, failed=failed, failure_reason="x" if failed else "")
    return {"suite": "s", "condition": cond, "group": "s", "model": model, "wind": "none", "policy": "p", **m}


def test_summary_and_degradation_by_hand():
    recs = [_rec("s/rigid", "rigid", v) for v in (1.0, 2.0, 3.0)]
    recs += [_rec("s/nonrigid", "nonrigid", v, failed=(v == 6.0)) for v in (2.0, 4.0, 6.0)]
    rigid, nonrigid = summarize(recs)
    assert rigid["n"] == 3 and rigid["rate_error_rad_mean"] == 2.0 and rigid["rate_error_rad_std"] == 1.0
    assert rigid["rate_error_rad_cvar10"] == 3.0 and rigid["failure_rate"] == 0.0
    assert nonrigid["failure_rate"] == pytest.approx(1 / 3) and nonrigid["failure_reasons"] == "x: 1"
    (d,) = degradation([rigid, nonrigid])
    assert d["policy"] == "p" and d["condition"] == "s/nonrigid" and d["reference"] == "s/rigid"
    assert d["mean_ratio"] == 2.0 and d["mean_diff"] == 2.0
    assert d["cvar10_ratio"] == 2.0 and d["failure_rate_diff"] == pytest.approx(1 / 3)
    assert d["failure_rate_rigid"] == 0.0 and d["failure_rate"] == pytest.approx(1 / 3)
    lo, hi = rigid["rate_error_rad_ci_low"], rigid["rate_error_rad_ci_high"]
    assert 1.0 <= lo < 2.0 < hi <= 3.0                       # a bootstrap interval of the mean of 1, 2, 3
    table = markdown_table([rigid, nonrigid], [d])
    # 0 failed of 3: the exact interval [0, 1 - 0.025^(1/3)] = [0, 71 %]
    assert f"| rigid | p | 1 | 0 % [0, 71] | - | 2.0000 [{lo:.4f}, {hi:.4f}] | 3.0000 |" in table
    assert "| p | nonrigid | 0 % | 33 % | 2.0000 | 4.0000 | 2.000 | +2.0000 | - |" in table


# ---------------------------------------------------------------------------------------------- suites
def test_suites_are_frozen_and_seed_sets_disjoint():
    assert {"smile-calm", "smile-windy", "smile-dispersed", "slender-ld30"} <= set(SUITES)
    s = get_suite("smile-windy")
    assert s.seeds("test", 3) == [TEST_SEED0, TEST_SEED0 + 1, TEST_SEED0 + 2]
    assert s.seeds("validation", 2) == [VALIDATION_SEED0, VALIDATION_SEED0 + 1]
    assert not set(s.seeds("test", 10_000)) & set(s.seeds("validation", 10_000))
    for suite in SUITES.values():
        assert suite.version in ("v0", "v1", "v2", "v2-family") and \
            {c.model for c in suite.conditions} == {"rigid", "nonrigid"}
        assert not suite.reference or suite.version.startswith("v2")      # v0 and v1 name no reference
    assert get_suite("smile-v2").reference == get_suite("smile-v2-faults").reference == "lqg"
    assert {n for n, s in SUITES.items() if s.version == "v0"} == {"smile-calm", "smile-windy", "smile-dispersed",
                                                                   "slender-ld30"}
    assert get_suite("smile-v1").with_options(mission_time_s=1.0).version == "v1+override"
    short = short_suite()
    assert short.version == "v0+override" and dict(short.overrides) == {"mission_time_s": SHORT}
    assert get_suite("smile-windy").version == "v0"            # the frozen suite is untouched
    with pytest.raises(ValueError, match="smile-windy"):
        get_suite("no-such-suite")


@pytest.mark.parametrize("name", sorted(SUITES))
def test_every_condition_makes_its_env(name):
    for cond in get_suite(name).with_options(mission_time_s=0.1).conditions:
        env = cond.make_env()
        env.reset(seed=1)
        env.step(env.action_space.sample())
        env.close()


# ---------------------------------------------------------------------------------------------- determinism
def test_run_episode_does_not_depend_on_what_ran_before():
    cond = short_suite().conditions[1]
    a = run_episode(ZERO, cond, 10_000)
    b = run_episode(ZERO, cond, 10_001)
    assert a != b                                           # the seed draws the wind
    assert run_episode(ZERO, cond, 10_000) == a
    fresh = play_episode(ZeroPolicy(), cond.make_env(), 10_000)    # a new env: the same episode
    assert fresh == {k: a[k] for k in fresh}


def test_same_seeds_give_the_same_table_whatever_the_executor():
    suite = short_suite()
    runs = [evaluate([ZERO], [suite], 2, executor=ex, workers=2, progress=False)
            for ex in ("serial", "serial", "local")]
    tables, csvs = [], []
    for recs in runs:
        s = summarize(recs)
        tables.append(markdown_table(s, degradation(s)))
        csvs.append(csv_text(recs))
    assert tables[0] == tables[1] == tables[2]
    assert csvs[0] == csvs[1] == csvs[2]
    assert [r["seed"] for r in runs[0]] == [10_000, 10_001] * 2
    other = evaluate([ZERO], [suite], 2, seed_set="validation", executor="serial", progress=False)
    assert csv_text(other) != csvs[0]


@pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="ray is not installed (optional extra)")
def test_ray_executor_gives_the_serial_records():
    suite = short_suite()
    serial = evaluate([ZERO], [suite], 1, executor="serial", progress=False)
    ray = evaluate([ZERO], [suite], 1, executor="ray", workers=2, progress=False)
    # Ray workers run BLAS on one thread (OMP_NUM_THREADS=1): the modal analysis of the non-rigid
    # timeline then differs in the last bits, so floats agree to 1e-9, not bit for bit
    assert [r.keys() for r in ray] == [r.keys() for r in serial]
    for r, s in zip(ray, serial):
        assert r == {k: pytest.approx(v, rel=1e-9) if isinstance(v, float) else v for k, v in s.items()}
    table = [markdown_table(summarize(x), degradation(summarize(x))) for x in (serial, ray)]
    assert table[0] == table[1]


# ---------------------------------------------------------------------------------------------- policies, CLI
@pytest.fixture(scope="module")
def tiny_sb3(tmp_path_factory):
    """An untrained PPO saved with a VecNormalize pickle next to it."""
    import gymnasium
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    folder = tmp_path_factory.mktemp("sb3")
    venv = VecNormalize(DummyVecEnv([lambda: gymnasium.make("lvgym/SmileAscent-v0", model="rigid",
                                                            mission_time_s=0.2)]))
    model = PPO("MlpPolicy", venv, n_steps=8, batch_size=8, policy_kwargs={"net_arch": [8]}, device="cpu", seed=0)
    model.save(folder / "tiny.zip")
    venv.save(str(folder / "tiny_vecnormalize.pkl"))
    return folder / "tiny.zip"


def test_sb3_model_acts_as_a_policy(tiny_sb3):
    from lvgym.agents.policies.sb3 import SB3Policy

    p = SB3Policy(str(tiny_sb3))
    assert p.name == "tiny" and p.normalizer is not None
    p.reset()
    a = p.act(np.zeros(14, dtype=np.float32), {})
    assert a.shape == (2,) and np.all(np.abs(a) <= 1.0)
    spec = PolicySpec("tiny", "lvgym.agents.policies.sb3:load_policy", (("path", str(tiny_sb3)),))
    r = run_episode(spec, short_suite().conditions[0], 10_000)
    assert r["policy"] == "tiny" and r["duration_s"] == pytest.approx(SHORT)


def _evaluate_module(monkeypatch):
    spec = importlib.util.spec_from_file_location("evaluate_under_test", ROOT / "evaluate.py")
    mod = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, mod)
    spec.loader.exec_module(mod)
    return mod


def test_registry_names_what_is_missing(monkeypatch):
    ev = _evaluate_module(monkeypatch)
    monkeypatch.setitem(ev.POLICIES, "ghost", PolicySpec("ghost", "no_such_baselines.pid:GhostPID"))
    with pytest.raises(SystemExit, match="no_such_baselines"):
        ev.resolve_policy("ghost")
    with pytest.raises(SystemExit, match="zero"):
        ev.resolve_policy("not-a-policy")
    assert ev.resolve_policy("zero") == ZERO
    args = ev.parse_args([])
    # the default: protocol v2's suites, each flying its own policies (a v0 or v1 suite: DEFAULT_POLICIES);
    # with --policies alone, the main suite smile-v2
    assert args.policies is None and args.suites is None and ev.DEFAULT_SUITE == "smile-v2"
    assert ev.DEFAULT_SUITES == ["smile-v2", "smile-v2-maxq-gust", "smile-v2-faults", "stratos-tvc-v2", "slender-v2"]
    assert all(get_suite(n).policies and get_suite(n).version == "v2" for n in ev.DEFAULT_SUITES)
    assert ev.DEFAULT_POLICIES == ["zero", "gs-pid", "gs-pid-flex", "lqg", "lqg-front", "aac", "ppo-res-lqg"]
    assert args.executor == "local"
    assert args.reference is None and ev.parse_args(["--reference", "pid"]).reference == "pid"
    with pytest.raises(SystemExit, match="--reference = 'ghost'"):          # refused before any episode runs
        ev.main(["--policies", "zero", "--reference", "ghost", "--no-progress"])


def test_cli_end_to_end(tmp_path, tiny_sb3):
    out = tmp_path / "res"
    proc = subprocess.run(_evaluate_cmd(out, "--policies", "zero", str(tiny_sb3), "--suites", "smile-windy", "--episodes", "2",
                                          "--workers", "2"),
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "| rigid | zero |" in proc.stdout and "| nonrigid | tiny |" in proc.stdout
    assert "episodes" in proc.stderr                                  # the progress bar
    assert {"episodes.csv", "summary.csv", "degradation.csv", "comparison.csv", "table.md", "results.json",
            "rate_error.png", "degradation.png"} <= {p.name for p in out.iterdir()}
    assert "per flight phase" in proc.stdout and "Paired comparison" in proc.stdout
    _complete(out)
    rows = list(csv.DictReader(io.StringIO((out / "episodes.csv").read_text())))
    assert len(rows) == 2 * 2 * 2 and {r["policy"] for r in rows} == {"zero", "tiny"}
    data = json.loads((out / "results.json").read_text())
    assert data["meta"]["suites"]["smile-windy"]["version"] == "v0+override"
    assert data["meta"]["protocol"] == "v0+override"           # the suites' own versions, not a constant
    assert (out / "table.md").read_text() in proc.stdout


def test_v0_effort_metric_stays_the_sampled_one():
    """Protocol v0's ``effort_rad_s`` samples |gimbal| at the end of each control step; the env's reward
    (and ``info["effort_rad_s"]``) integrates it at every physics step. Both estimate the same integral,
    but they differ in the last digits of the README's table (0.001 to 0.01 deg s per 60 s episode), so
    the frozen v0 metric keeps its definition; protocol v1 reads the env's integral."""
    import gymnasium as gym

    from lvgym.baselines.pid import smile_tuned_pid
    from lvgym.benchmark.runner import play_episode
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="turbulence", randomize=["wind"],
                   mission_time_s=20.0)
    pol = smile_tuned_pid(env)
    v0 = play_episode(pol, env, 10_000)["effort_rad_s"]
    obs, info = env.reset(seed=10_000)
    pol.reset()
    integral, reward_effort = 0.0, 0.0
    while True:
        obs, r, term, trunc, info = env.step(pol.act(obs, info))
        integral += info["effort_rad_s"]
        reward_effort += info["reward_terms"]["effort"]
        if term or trunc:
            break
    assert reward_effort == pytest.approx(-env.unwrapped.task.effort_weight * integral, rel=1e-12)
    assert integral == pytest.approx(v0, rel=2e-3) and integral != v0


# ---------------------------------------------------------------------------------------------- v1 metrics
class HardOver:
    """The gimbal held hard over in pitch: the vehicle departs within a few seconds."""

    name = "hard-over"

    def reset(self) -> None:
        pass

    def act(self, observation, info):
        return np.array([1.0, 0.0], dtype=np.float32)


def test_records_carry_the_v1_metrics_and_failing_early_never_pays():
    import gymnasium as gym

    from lvgym.benchmark import V1_METRICS
    from lvgym.benchmark.scoring import PHASES
    env = gym.make("lvgym/SmileAscent-v0", wind="turbulence", randomize=["wind"], mission_time_s=20.0)
    for seed in (10_000, 10_001):
        zero = play_episode(ZeroPolicy(), env, seed)
        hard = play_episode(HardOver(), env, seed)
        for rec in (zero, hard):
            assert set(V1_METRICS) <= set(rec)
            assert rec["score"] >= rec["rate_error_rad"]
            assert sum(rec[f"rate_error_{p}_rad"] for p in PHASES) == pytest.approx(rec["rate_error_rad"], rel=1e-12)
        assert not zero["failed"] and zero["score"] == zero["rate_error_rad"]
        assert hard["failed"] and hard["duration_s"] < 6.0
        # the failing policy has the lower thesis criterion, and the worse score: by the mission it did not fly
        assert hard["rate_error_rad"] < zero["rate_error_rad"] < hard["score"]
        assert hard["score"] == pytest.approx(hard["rate_error_rad"] + 0.1 * (20.0 - hard["duration_s"]))
        assert hard["gimbal_rate_limit_s"] > 0 and zero["gimbal_rate_limit_s"] == 0.0


def test_gyro_minus_body_rate_against_the_ideal_observation():
    """The sensors observation's gyro against the body rate, checked side by side with the ideal-state
    observation of the same seed (whose rate entries are the body's): the zero policy flies the same
    flight under both observations."""
    import gymnasium as gym

    from lvgym.envs.layouts import OBS_SENSORS, OBS_STATE
    kw = {"model": "nonrigid", "wind": "turbulence", "randomize": ["wind"], "mission_time_s": 4.0}
    sens, ideal = (gym.make("lvgym/SmileAscent-v0", observation=o, **kw) for o in ("sensors", "state"))
    seed, dt = 10_000, 0.02
    sens.reset(seed=seed)
    ideal.reset(seed=seed)
    total = 0.0
    while True:
        o_s, _, te, tr, _ = sens.step(np.zeros(2, np.float32))
        o_i, *_ = ideal.step(np.zeros(2, np.float32))
        total += (abs(float(o_s[OBS_SENSORS.index("pitch_rate_error")]) - float(o_i[OBS_STATE.index("pitch_rate_error")]))
                  + abs(float(o_s[OBS_SENSORS.index("yaw_rate_error")]) - float(o_i[OBS_STATE.index("yaw_rate_error")])))
        if te or tr:
            break
    total *= dt
    rec = play_episode(ZeroPolicy(), sens, seed)
    assert rec["gyro_minus_body_rate_rad"] > 0
    # the observation is float32: the two ways agree to its rounding (1e-7 rad/s per sample and axis)
    assert rec["gyro_minus_body_rate_rad"] == pytest.approx(total, abs=200 * 2 * 1e-7 * dt + 1e-6 * total)
    assert play_episode(ZeroPolicy(), ideal, seed)["gyro_minus_body_rate_rad"] == 0.0      # no gyro: 0 by definition
    rigid = gym.make("lvgym/SmileAscent-v0", observation="sensors", **{**kw, "model": "rigid"})
    assert play_episode(ZeroPolicy(), rigid, seed)["gyro_minus_body_rate_rad"] < 1e-3 * rec["gyro_minus_body_rate_rad"]


def _v1_rec(policy: str, seed: int, score: float, failed: bool = False, cond: str = "s/rigid",
            model: str = "rigid") -> dict:
    r = _rec(cond, model, score if not failed else score / 2, failed)
    r.update(policy=policy, seed=seed, score=score, rate_error_boost_rad=0.25 * r["rate_error_rad"],
             rate_error_max_q_rad=0.5 * r["rate_error_rad"], rate_error_coast_rad=0.0,
             rate_error_upper_rad=0.25 * r["rate_error_rad"])
    return r


def test_tables_rank_by_failure_rate_then_score():
    recs = [_v1_rec("flies-badly", s, 3.0 + 0.1 * s) for s in range(4)]
    recs += [_v1_rec("fails-once", s, 1.0 + 0.1 * s, failed=(s == 0)) for s in range(4)]
    recs += [_v1_rec("flies-well", s, 2.0 + 0.1 * s) for s in range(4)]
    recs += [_v1_rec("flies-well-too", s, 2.0 + 0.1 * s) for s in range(4)]
    summary = summarize(recs)
    assert [r["policy"] for r in summary] == ["flies-badly", "fails-once", "flies-well", "flies-well-too"]
    assert {r["policy"]: r["rank"] for r in summary} == {"flies-well": 1, "flies-well-too": 1, "flies-badly": 3,
                                                        "fails-once": 4}
    table = markdown_table(summary, [])
    order = [line.split("|")[2].strip() for line in table.splitlines() if line.startswith("| rigid |")]
    assert order == ["flies-well", "flies-well-too", "flies-badly", "fails-once"]
    for r in summary:                                   # every mean with an interval that brackets it
        for m in ("score", "rate_error_rad", "max_rate_radps", "rate_error_boost_rad", "failure_rate"):
            mean = r[m if m == "failure_rate" else f"{m}_mean"]
            assert r[f"{m}_ci_low"] <= mean <= r[f"{m}_ci_high"], (r["policy"], m)
        assert r["score_ci_low"] < r["score_ci_high"]
        phases = sum(r[f"rate_error_{p}_rad_mean"] for p in ("boost", "max_q", "coast", "upper"))
        assert phases == pytest.approx(r["rate_error_rad_mean"])


def test_paired_comparison_and_agents_over_runs():
    from lvgym.benchmark import compare, run_groups
    from lvgym.benchmark.stats import paired
    recs = [_v1_rec("a", s, 1.0 + 0.1 * s) for s in range(5)]
    recs += [_v1_rec("b", s, 1.2 + 0.1 * s * s) for s in range(5)]
    summary = summarize(recs)
    rows = compare(recs, summary, reps=200)
    best, other = rows
    assert best["policy"] == best["reference"] == "a" and math.isnan(best["diff"])
    want = paired([1.2 + 0.1 * s * s for s in range(5)], [1.0 + 0.1 * s for s in range(5)])
    assert other["policy"] == "b" and other["reference"] == "a" and other["n"] == 5
    assert other["diff"] == pytest.approx(want.mean_diff) and other["p_wilcoxon"] == want.p_wilcoxon
    assert (other["wins"], other["ties"], other["losses"]) == (0, 0, 5)
    assert other["diff_ci_low"] <= other["diff"] <= other["diff_ci_high"]
    assert other["iqm_ci_low"] <= other["iqm"] <= other["iqm_ci_high"]
    assert 0.0 <= other["p_improvement_ci_low"] <= other["p_improvement"] <= other["p_improvement_ci_high"] < 0.5
    named = compare(recs, summary, reference="b", reps=200)
    assert [r["reference"] for r in named] == ["b", "b"] and named[0]["diff"] == pytest.approx(-want.mean_diff)
    table = markdown_table(summary, [], comparison=rows)
    assert "| rigid | a | 1 |" in table and "(reference)" in table and "| 0/0/5 |" in table
    runs = [dict(r, policy=f"agent-s{k}") for k, part in enumerate((recs[:5], recs[5:])) for r in part]
    (g,) = run_groups(runs, reps=200)
    assert g["agent"] == "agent" and g["runs"] == 2 and g["episodes"] == 5
    assert g["iqm_ci_low"] <= g["iqm"] <= g["iqm_ci_high"]


def test_v2_records_are_compared_by_score_v2():
    """evaluate.py compares a v2 suite by the protocol's score_v2 (it charges an unflyable flight), v1 by score."""
    from lvgym.benchmark import compare, protocol_metric, run_groups
    # "quiet" scores better by v1's score, "chatters" by score_v2 (v1's score does not charge the chatter)
    recs = [dict(_v1_rec("quiet", s, 1.0 + 0.1 * s), score_v2=2.0 + 0.1 * s, flyable=True) for s in range(5)]
    recs += [dict(_v1_rec("chatters", s, 1.5 + 0.1 * s), score_v2=1.0 + 0.05 * s * s, flyable=True) for s in range(5)]
    assert protocol_metric(recs) == "score_v2" and protocol_metric([_v1_rec("a", 0, 1.0)]) == "score"
    rows = compare(recs, summarize(recs), protocol_metric(recs), reference="quiet", reps=200)
    other = next(r for r in rows if r["policy"] == "chatters")
    assert other["metric"] == "score_v2" and other["diff"] == pytest.approx(-0.9) and other["wins"] == 5
    runs = [dict(r, policy=f"agent-s{k}") for k, part in enumerate((recs[:5], recs[5:])) for r in part]
    (g,) = run_groups(runs, protocol_metric(runs), reps=200)
    assert g["mean"] == pytest.approx(np.mean([r["score_v2"] for r in recs]))
    table = markdown_table(summarize(recs), [], comparison=rows, groups=[g])
    assert "IQM score_v2 [rad]" in table and "mean score_v2 [rad]" in table


def test_score_degradation_counts_failures_with_a_paired_test():
    recs = [_v1_rec("p", s, 1.0 + 0.1 * s) for s in range(4)]
    recs += [_v1_rec("p", s, 2.0 + 0.1 * s, failed=(s < 2), cond="s/nonrigid", model="nonrigid") for s in range(4)]
    summary = summarize(recs)
    (d,) = degradation(summary, "score", records=recs)
    assert d["metric"] == "score" and d["failure_rate_rigid"] == 0.0 and d["failure_rate"] == 0.5
    assert d["mean_diff"] == pytest.approx(1.0) and d["paired_n"] == 4
    assert d["diff_ci_low"] == pytest.approx(1.0) and d["diff_ci_high"] == pytest.approx(1.0)   # the same diff each seed
    (e,) = degradation(summary, "rate_error_rad", records=recs)
    assert e["mean_diff"] < d["mean_diff"]              # the failed episodes' rate errors stopped early
    table = markdown_table(summary, [d, e])
    assert "| p | nonrigid | 0 % | 50 % | 1.1500 | 2.1500 | 1.870 | +1.0000 [+1.0000, +1.0000] |" in table
