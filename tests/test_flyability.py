"""Protocol v2's flyability (lvgym.benchmark.flyability): the measure against hand numbers, the rule and the
charge, the ranking; flown: ``lqg`` with white chatter at the rate limit added to its command ranks below
plain ``lqg``, and smooth policies are never charged (short missions)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.batch import as_batch
from lvgym.benchmark.fingerprint import ProbePolicy
from lvgym.benchmark.flyability import (RMS_FRACTION, WINDOW_S, applies, command_metrics, commanded_rate,
                                        v2_score)
from lvgym.benchmark.metrics import summarize
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.rows import fly_rows
from lvgym.benchmark.runner import build_policy, play_episode, zero_policy
from lvgym.benchmark.suites import condition
from lvgym.benchmark.tables import flyability_table

R = math.radians(30.0)          # the rate limit [rad/s]
DT = 0.02                       # the SMILE control period [s]


def _t(n: int) -> np.ndarray:
    return DT * np.arange(1, n + 1)


def test_an_alternating_command_asks_twice_its_amplitude_per_step_and_spends_its_budget_early():
    n = 1001
    a = 0.25 * R * DT                                   # +-a every step: |rate| = 2 a / dt = R / 2
    u = np.tile(a * (-1.0) ** np.arange(n), (2, 1)).T
    m = command_metrics(u, np.ones(n, bool), _t(n), DT, R)
    assert m["cmd_rate_rms"] == pytest.approx(0.5) and m["cmd_rate_peak"] == pytest.approx(0.5)
    assert m["cmd_reversal_hz"] == pytest.approx(1 / DT)   # every step, on both axes
    # 1000 controlled steps (the first has no predecessor), each (R/2)^2: the budget (R/3)^2 * 1000 is spent
    # after 1000 * 4 / 9 = 444.4 steps, at the 445th controlled step, step index 445, t = 446 dt
    assert not m["flyable"] and m["unflyable_at_s"] == pytest.approx(446 * DT)


def test_a_slow_sinusoid_is_its_rate_amplitude_over_root_two_and_flyable():
    n, amp, f = 3000, math.radians(2.0), 0.5           # 2 deg at 0.5 Hz: 6.28 deg/s peak, 4.44 deg/s RMS
    u = np.tile(amp * np.sin(2 * math.pi * f * _t(n)), (2, 1)).T
    m = command_metrics(u, np.ones(n, bool), _t(n), DT, R)
    assert m["cmd_rate_rms"] == pytest.approx(2 * math.pi * f * amp / math.sqrt(2) / R, rel=1e-3)   # 0.148
    assert m["cmd_reversal_hz"] == pytest.approx(2 * f, rel=0.02)                                    # 2 per period
    assert m["flyable"] and math.isnan(m["unflyable_at_s"])


def test_a_two_second_burst_at_the_limit_breaks_the_rule_that_the_whole_flight_rms_would_dilute():
    n, start, burst = 3000, 1000, 150                   # 60 s, a 3 s triangle wave at 1.2 times the limit
    d = np.zeros(n)
    d[start:start + burst] = 1.2 * R * DT * np.where((np.arange(burst) // 10) % 2 == 0, 1.0, -1.0)
    u = np.tile(np.cumsum(d), (2, 1)).T
    m = command_metrics(u, np.ones(n, bool), _t(n), DT, R)
    assert m["cmd_rate_rms"] == pytest.approx(1.2 * math.sqrt(burst / (n - 1)))          # 0.27: within budget
    assert m["cmd_rate_rms"] < RMS_FRACTION and m["cmd_rate_peak"] == pytest.approx(1.2)
    # a window of w = 100 steps is over the limit once it holds more than 100 / 1.44 = 69.4 burst steps:
    # the first is the window ending at the 70th burst step, index start + 69
    assert int(round(WINDOW_S / DT)) == 100
    assert not m["flyable"] and m["unflyable_at_s"] == pytest.approx(_t(n)[start + 69])


def test_the_coast_and_the_switch_on_step_do_not_count_and_no_gimbal_is_flyable():
    n = 400
    on = np.ones(n, bool)
    on[100:200] = False                                 # a coast: the policy's actions are ignored
    u = np.zeros((n, 2))
    u[100:200] = 0.1                                    # jumps into and out of the coast, 5 rad in a step
    r, both = commanded_rate(u, on, DT)
    assert not both[0] and not both[100:201].any() and both[201:].all() and both[1:100].all()
    m = command_metrics(u, on, _t(n), DT, R)
    assert m["cmd_rate_rms"] == 0.0 and m["flyable"]
    assert command_metrics(None, on, _t(n), DT, R)["flyable"]                  # an RCS task: no gimbal


def test_an_unflyable_flight_is_charged_as_a_failure_at_the_breach_and_a_flyable_one_never():
    n, T = 100, 10.0
    t = np.arange(1, n + 1) / 20                        # 5 s flown of a 10 s mission
    e = np.tile([9.0, 0.01, 0.02], (n, 1))              # roll does not count
    assert v2_score(e, t, 0.05, 0.15, math.nan, T, 0.1) == 0.15                     # flyable: the score
    # broken at t = 1 s: steps 1..20 flown, 20 * 0.05 * 0.03 = 0.03 rad, plus 0.1 rad/s * 9 s
    assert v2_score(e, t, 0.05, 0.15, 1.0, T, 0.1) == pytest.approx(0.03 + 0.9)


def test_only_v2_and_later_protocols_charge_flyability():
    assert not any(map(applies, ["v0", "v1", "v1+override", "v1-draft", "", "x2"]))
    assert all(map(applies, ["v2", "v2-draft", "v2+override", "v3", "v10"]))


def _rec(policy, seed, score, failed=False, flyable=None, score_v2=None):
    r = {"suite": "s", "condition": "s/rigid", "policy": policy, "seed": seed, "failed": failed,
         "failure_reason": "qalpha" if failed else "", "score": score}
    r.update({m: 0.0 for m in ("rate_error_rad", "rate_error_pitch_rad", "rate_error_yaw_rad", "max_rate_radps",
                               "effort_rad_s", "max_alpha_rad", "max_qalpha_pa_deg", "episode_return")})
    if flyable is not None:
        r.update(flyable=flyable, score_v2=score if score_v2 is None else score_v2, cmd_rate_rms=0.0,
                 cmd_rate_peak=0.0, cmd_reversal_hz=0.0)
    return r


def test_v2_ranks_an_unflyable_policy_like_a_failing_one_and_v1_ranks_as_before():
    v1 = [_rec("chatter", s, 1.0) for s in (0, 1)] + [_rec("smooth", s, 2.0) for s in (0, 1)]
    assert {r["policy"]: r["rank"] for r in summarize(v1)} == {"chatter": 1, "smooth": 2}   # v1: by score
    v2 = ([_rec("chatter", s, 1.0, flyable=False, score_v2=5.0) for s in (0, 1)]
          + [_rec("smooth", s, 2.0, flyable=True) for s in (0, 1)]
          + [_rec("failing", 0, 1.5, failed=True, flyable=True), _rec("failing", 1, 1.5, flyable=True)])
    rows = sorted(summarize(v2), key=lambda r: r["rank"])
    assert [(r["policy"], r["rank"]) for r in rows] == [("smooth", 1), ("failing", 2), ("chatter", 3)]
    chatter = rows[2]
    assert chatter["unflyable_rate"] == 1.0 and chatter["failure_rate_v2"] == 1.0 and chatter["failure_rate"] == 0.0
    assert rows[1]["failure_rate_v2"] == 0.5 and rows[0]["score_v2_mean"] == rows[0]["score_mean"] == 2.0
    table = flyability_table(rows)                       # v2 rows: one line each, in rank order
    assert [line.split("|")[2].strip() for line in table[2:]] == ["smooth", "failing", "chatter"]
    unflyable = table[-1].split("|")[5].strip()                # chatter: unflyable on every flight, exact interval
    assert unflyable.startswith("100 % [") and unflyable.endswith(", 100]") and flyability_table(summarize(v1)) == []


class WhiteChatter:
    """``policy``'s action plus white Gaussian chatter whose commanded rate has the RMS of the rate limit:
    per axis ``sigma = R dt / sqrt(2) / gimbal_limit`` of the action (the difference of two independent
    draws has ``sqrt(2)`` times their deviation), drawn from a generator seeded at every reset."""

    def __init__(self, policy, env, seed: int = 7):
        u = env.unwrapped
        self.policy, self.name, self.seed = policy, f"{policy.name}+chatter", seed
        self.sigma = math.radians(u.task.gimbal_rate_limit_degps) * u.task.control_dt_s / math.sqrt(2) / u.gimbal_limit
        self.rng = np.random.default_rng(seed)

    def reset(self):
        self.policy.reset()
        self.rng = np.random.default_rng(self.seed)

    def act(self, observation, info):
        a = np.asarray(self.policy.act(observation, info), dtype=float)
        return (a + self.sigma * self.rng.standard_normal(a.shape)).astype(np.float32)


MISSION_S = 6.0     # the controllers switch on at 2 s: 4 s controlled


def test_lqg_with_white_chatter_at_the_rate_limit_ranks_below_plain_lqg_and_smooth_policies_are_never_charged():
    cond = condition("smile-v1", "nonrigid", mission_time_s=MISSION_S)
    env = cond.make_env()
    lqg = resolve_policy("lqg")
    makers = {"lqg": lambda: build_policy(lqg, env), "lqg+chatter": lambda: WhiteChatter(build_policy(lqg, env), env),
              "zero": lambda: zero_policy(env), "probe": lambda: ProbePolicy(env)}
    seeds = [0, 1]
    rows = [(name, s) for name in makers for s in seeds]
    groups = [(as_batch(make(), len(rows), make), [i for i, (n, _) in enumerate(rows) if n == name])
              for name, make in makers.items()]
    records = fly_rows(cond.make_vec_env(len(rows)), [s for _, s in rows], groups, flyability=True)
    for (name, seed), r in zip(rows, records):
        r.update(suite="smile-v1", condition=cond.name, policy=name, seed=seed)
        if name != "lqg+chatter":                          # smooth: flyable and not charged, to the bit
            assert r["flyable"] and r["score_v2"] == r["score"] and not r["failed"], (name, seed, r["cmd_rate_rms"])
        else:                                              # the chatter alone asks about the rate limit
            assert r["cmd_rate_rms"] > 0.9 and not r["flyable"] and r["score_v2"] > r["score"]
    summary = {r["policy"]: r for r in summarize(records)}
    assert summary["lqg+chatter"]["rank"] > summary["lqg"]["rank"]
    assert summary["lqg+chatter"]["failure_rate_v2"] == 1.0 and summary["lqg"]["failure_rate_v2"] == 0.0
    # the batched records are the single env's episodes, the flyability fields too
    single = play_episode(WhiteChatter(build_policy(lqg, env), env), env, seeds[1], flyability=True)
    batched = records[rows.index(("lqg+chatter", seeds[1]))]
    assert all(single[k] == batched[k] for k in ("cmd_rate_rms", "cmd_rate_peak", "cmd_reversal_hz", "flyable",
                                                 "unflyable_at_s", "score", "score_v2"))
