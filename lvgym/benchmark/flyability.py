"""Protocol v2's flyability: what a policy's gimbal command asks of the thrust-vector actuator, and the rule
that makes a flight unflyable (ranked like a failure). Protocols v0 and v1 do not use it.

The measure is the policy's own command, not the gimbal's response: per control step ``k`` the clipped
action times the gimbal limit, ``u_k = clip(a_k, -1, 1) * gimbal_limit`` [rad] (pitch, yaw), and its rate
``r_k = (u_k - u_{k-1}) / dt`` [rad/s] over the *controlled* steps (the controller acted at ``k - 1`` and at
``k``: ``info["controller_on"]``; a coast and the switch-on step are left out). ``R`` is the servo's rate
limit (``gimbal_rate_limit_degps``, 30 deg/s by default). The servo filters and rate-limits what it is
asked, so the gimbal's own rate cannot show a command that asks 3.5 times the limit at 25 Hz; the command
can. An RCS (roll pulse) task commands no gimbal: every measure is 0 and the flight is flyable.

==========================  ======  =================================================================
cmd_rate_rms                -       ``sqrt(mean_k mean_axis r^2) / R`` over the controlled steps
cmd_rate_peak               -       the largest RMS of ``r`` over a sliding :data:`WINDOW_S` window (at
                                    least half of its steps controlled) over ``R``
cmd_reversal_hz             1/s     sign changes of the command's increment per second and axis (a
                                    command that alternates every step reverses ``1 / dt`` times a second)
flyable                     -       neither part of the rule below is broken
unflyable_at_s              s       when the rule was first broken (NaN: never)
score_v2                    rad     the v2 headline: ``score`` for a flyable flight; an unflyable flight is
                                    charged as a failure at ``unflyable_at_s`` (a step it flew, so never
                                    after a failure of its own): its rate error up to then plus
                                    ``failure_penalty_rad_per_s`` times the mission time left
==========================  ======  =================================================================

The rule's per-step terms (the command, its rate and square, the budget, the burst window, the charge of the
mission left) are :mod:`lvgym.envs.scoreterms`'s, which the env's score reward (``reward_kind="score_v2"``)
charges step by step. The rule (docs/flyability.md has the reasons and the sources):

- **budget**: ``cmd_rate_rms <= RMS_FRACTION`` (1/3): the rate limit is at least three standard deviations of
  the commanded rate (a Gaussian command exceeds it in 0.27 % of the steps). It breaks when the running sum
  ``sum_k mean_axis r_k^2`` passes the flight's budget ``(RMS_FRACTION R)^2 n`` (``n`` its controlled steps),
  so a flight that spends its budget early is charged from then;
- **burst**: ``cmd_rate_peak <= WINDOW_FRACTION`` (1.0): over no :data:`WINDOW_S` stretch does the command
  ask, in the RMS, more than the actuator can give (chatter or a limit cycle at the rate limit that the whole
  flight's RMS would dilute). It breaks at the end of the first such window.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from lvgym.envs.scoreterms import (RMS_FRACTION, WINDOW_FRACTION, WINDOW_S, budget, burst_limit, command_rate,
                                   mission_charge, rate_square, window_mean, window_quorum, window_steps)

__all__ = ["RMS_FRACTION", "V2_METRICS", "WINDOW_FRACTION", "WINDOW_S", "applies", "command_metrics",
           "commanded_rate", "flyability_metrics", "v2_score"]

#: the metrics a v2 record adds (summarised per suite beside v0's and v1's)
V2_METRICS = ("score_v2", "cmd_rate_rms", "cmd_rate_peak", "cmd_reversal_hz")
_VERSION = re.compile(r"^v(\d+)")


def applies(version: str) -> bool:
    """Whether protocol ``version`` (``"v2"``, ``"v2-draft"``, ``"v2+override"``, ...) charges flyability:
    from v2 on; v0 and v1 never do."""
    m = _VERSION.match(str(version))
    return bool(m) and int(m.group(1)) >= 2


def commanded_rate(command_rad: np.ndarray, on: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The commanded rate ``r`` (N, 2) [rad/s] of the commands ``command_rad`` (N, 2) [rad] and the mask (N,)
    of the controlled steps (``on`` at the step and the one before; the first step never)."""
    u = np.asarray(command_rad, dtype=float)
    on = np.asarray(on, dtype=bool).reshape(-1)
    both = on.copy()
    if both.size:
        both[1:] &= on[:-1]
        both[0] = False
    r = np.zeros_like(u)
    r[1:] = command_rate(u[1:], u[:-1], dt)
    return r, both


def command_metrics(command_rad: np.ndarray | None, on: np.ndarray, time_s: np.ndarray, dt: float,
                    rate_limit_radps: float) -> dict[str, Any]:
    """The module docstring's measures of one flight: ``command_rad`` (N, 2) [rad] (None: no gimbal), ``on``
    (N,) the controller acted at the step, ``time_s`` (N,) [s] the steps' end times, ``dt`` [s], the rate
    limit [rad/s]. Returns ``cmd_rate_rms``, ``cmd_rate_peak``, ``cmd_reversal_hz``, ``flyable`` and
    ``unflyable_at_s`` (NaN when flyable)."""
    out: dict[str, Any] = {"cmd_rate_rms": 0.0, "cmd_rate_peak": 0.0, "cmd_reversal_hz": 0.0, "flyable": True,
                           "unflyable_at_s": math.nan}
    if command_rad is None or len(command_rad) == 0:
        return out
    r, both = commanded_rate(command_rad, on, dt)
    n = int(both.sum())
    if n == 0:
        return out
    lim = float(rate_limit_radps)
    sq = np.where(both, rate_square(r), 0.0)                     # per step, the mean over the axes
    cum = np.cumsum(sq)
    out["cmd_rate_rms"] = math.sqrt(cum[-1] / n) / lim
    w = window_steps(dt)
    csum = np.concatenate([[0.0], cum])
    cnt = np.concatenate([[0], np.cumsum(both)])
    n_w = cnt[w:] - cnt[:-w] if len(sq) >= w else np.array([n])
    s_w = csum[w:] - csum[:-w] if len(sq) >= w else np.array([cum[-1]])
    ok = n_w >= window_quorum(w)
    ms = np.where(ok, window_mean(s_w, n_w), 0.0)
    out["cmd_rate_peak"] = math.sqrt(float(ms.max())) / lim if ms.size else 0.0
    inc = np.sign(r)
    rev = (inc[1:] * inc[:-1] < 0) & both[1:, None] & both[:-1, None]
    pairs = int((both[1:] & both[:-1]).sum())
    out["cmd_reversal_hz"] = float(rev.sum()) / (r.shape[1] * pairs * dt) if pairs else 0.0
    t = np.asarray(time_s, dtype=float)
    breaks = []
    allowed = budget(lim, n)
    if cum[-1] > allowed:
        breaks.append(float(t[int(np.argmax(cum > allowed))]))
    over = ms > burst_limit(lim)
    if over.any():                                             # window j ends at step j + w - 1
        end = int(np.argmax(over)) + (w - 1 if len(sq) >= w else len(sq) - 1)
        breaks.append(float(t[end]))
    if breaks:
        out["flyable"] = False
        out["unflyable_at_s"] = min(breaks)
    return out


def v2_score(rate_error_radps: np.ndarray, time_s: np.ndarray, dt: float, score: float,
             unflyable_at_s: float, mission_time_s: float, penalty_rad_per_s: float) -> float:
    """The v2 headline of one flight: ``score`` (v1's) when ``unflyable_at_s`` is NaN (flyable); else (a
    breach is a step of the flight, so never after a failure) the pitch + yaw rate error of the steps up to
    ``unflyable_at_s`` [s] (``rate_error_radps`` (N, 3) [rad/s], summed as v1 sums it) plus
    ``penalty_rad_per_s`` times the mission time left [rad]."""
    if math.isnan(unflyable_at_s):
        return float(score)
    t = np.asarray(time_s, dtype=float)
    n = len(t)
    e = np.abs(np.nan_to_num(np.reshape(rate_error_radps, (n, 3)), nan=0.0))
    keep = t <= unflyable_at_s
    integral = e[keep].sum(axis=0) * dt if keep.any() else np.zeros(3)
    return float(integral[1] + integral[2]) + mission_charge(penalty_rad_per_s, mission_time_s, unflyable_at_s)


def flyability_metrics(facts: Any, columns: Any, record: dict[str, Any]) -> dict[str, Any]:
    """The v2 fields of one flight: :func:`command_metrics` of ``columns`` (a :class:`~.scoring.FlightColumns`
    with ``command_rad`` and ``controller_on``) and ``score_v2`` (:func:`v2_score`, from ``record``'s v1
    ``score``); ``facts``: the task's :class:`~.scoring.FlightFacts`."""
    dt = float(facts.dt_s)
    t = np.asarray(columns.time_s, dtype=float)
    on = columns.controller_on if columns.controller_on is not None else np.ones(len(t), dtype=bool)
    m = command_metrics(columns.command_rad, on, t, dt, float(facts.gimbal_rate_limit_radps))
    m["score_v2"] = v2_score(columns.rate_error_radps, t, dt, record["score"], m["unflyable_at_s"],
                             facts.mission_time_s, facts.failure_penalty_rad_per_s)
    return m
