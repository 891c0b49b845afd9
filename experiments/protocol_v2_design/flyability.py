"""Candidate flyability metrics of protocol v2, computed for the shipped policies from what the env records.

    python -m experiments.protocol_v2_design.flyability                       # the shipped policies, smile-v1, 3 validation seeds
    python -m experiments.protocol_v2_design.flyability --policies lqg gs-pid-flex --seeds 5 --models nonrigid

Each episode is flown twice on the same seed: as the protocol flies it and with the gyro's angle random walk
set to zero (the other draws are the same; as ``experiments.command_noise.cmdnoise`` does). From the first
flight, per control step ``k`` while the controller is on at ``k - 1`` and ``k`` (both axes pooled):

- ``cmd_rate``: the RMS of the commanded gimbal rate ``(u[k] - u[k-1]) / dt`` (``u`` the clipped command
  [rad], the action times the gimbal limit) over the servo's rate limit: what the policy asks of the actuator,
  computable from the actions alone;
- ``cmd_rate_peak``: the largest RMS of the same over a sliding 2 s window of controlled steps (a loud stretch
  that the whole flight's RMS would dilute);
- ``cmd_rate_noise``: the same of the difference of the two flights' commands (what the gyro noise asks);
- ``cmd_over``: the share of the steps whose commanded rate exceeds the rate limit on either axis;
- ``cmd_hf``: the share of the commanded rate's mean square above ``--hf-hz`` (5 Hz: above the servo's
  15 rad/s bandwidth and the rigid-body loop; a periodogram per controlled stretch);
- ``reversal_hz``: sign changes of the command's increment per second and axis (a command that alternates
  every sample reverses 50 times a second);
- ``gimbal_rate`` [deg/s]: the RMS of the gimbal's own rate (``info["gimbal_rate"]``, the servo's state);
- ``at_limit``: the share of the controlled steps with the gimbal at its rate limit (within 1 %);
- ``gimbal_acc`` [deg/s^2]: the RMS of the gimbal's acceleration (the rate's change per step): for an
  inertia-dominated electromechanical actuator, the motor torque and current, whose square heats the motor;
- ``travel_deg`` [deg]: the gimbal's travel, ``int (|rate_pitch| + |rate_yaw|) dt`` while on: what a blow-down
  hydraulic supply spends (the fluid is the piston area times the stroke).

A record also carries the failure and the largest q-alpha of the first flight. The table prints the mean over
the seeds (the range of ``cmd_rate`` in brackets) and whether the mean meets each candidate threshold
(``--thresholds``, fractions of the rate limit for ``cmd_rate``).
"""

from __future__ import annotations

import csv
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.runner import PolicySpec, build_policy
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition, get_suite
from lvgym.commandline import arg, command_name, parse
from lvgym.parallel import EXECUTORS, exit_on_sigterm, run_map

__all__ = ["FlyTask", "command_metrics", "fly", "flyability_episode", "flyability_table", "run_flyability"]

PROG = "python -m experiments.protocol_v2_design.flyability"
DEFAULT_POLICIES = ["zero", "gs-pid", "gs-pid-flex", "lqg", "lqg-front", "aac", "ppo-res-lqg"]
KEYS = ("cmd_rate", "cmd_rate_peak", "cmd_rate_noise", "cmd_over", "cmd_hf", "reversal_hz", "gimbal_rate", "at_limit",
        "gimbal_acc", "travel_deg")
#: the sliding window of ``cmd_rate_peak`` [s]
WINDOW_S = 2.0


@dataclass(frozen=True)
class FlyTask:
    """One seed of one policy on one condition."""

    policy: PolicySpec
    condition: Condition
    seed: int
    hf_hz: float = 5.0


def fly(spec: PolicySpec, condition: Condition, seed: int) -> dict[str, Any]:
    """One episode: per step the time, the clipped command [rad], the gimbal [rad] and its rate [rad/s],
    whether the controller acted, q-alpha [Pa deg]; the termination and the env's constants."""
    env = condition.make_env()
    policy = build_policy(spec, env)
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    u = env.unwrapped
    limit = float(u.gimbal_limit)
    t, cmd, gim, rate, on, qa = [], [], [], [], [], []
    while True:
        action = np.clip(np.asarray(policy.act(obs, info), float), -1.0, 1.0)
        obs, _, terminated, truncated, info = env.step(action)
        t.append(float(info["time"]))
        cmd.append(action * limit)
        gim.append(np.asarray(info["gimbal"], float))
        rate.append(np.asarray(info["gimbal_rate"], float))
        on.append(bool(info["controller_on"]))
        qa.append(float(info["qalpha_pa_deg"]))
        if terminated or truncated:
            break
    return {"t": np.array(t), "cmd": np.array(cmd), "gimbal": np.array(gim), "rate": np.array(rate),
            "on": np.array(on), "qalpha": np.array(qa), "termination": str(info.get("termination", "")),
            "failed": bool(terminated), "dt": float(u.task.control_dt_s), "limit": limit,
            "rate_limit": float(u.sim.servo.rate_limit)}


def _stretches(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[start, stop)`` of every run of True in ``mask``."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _hf_share(r: np.ndarray, both: np.ndarray, dt: float, hf_hz: float) -> float:
    """Share of the mean square of ``r`` (n, 2) over the steps ``both`` above ``hf_hz``: a periodogram of
    each controlled stretch of at least 32 steps, mean removed, summed over stretches and axes."""
    hi = tot = 0.0
    for a, b in _stretches(both):
        if b - a < 32:
            continue
        x = r[a:b] - r[a:b].mean(axis=0)
        p = np.abs(np.fft.rfft(x, axis=0)) ** 2
        f = np.fft.rfftfreq(b - a, dt)
        tot += float(p.sum())
        hi += float(p[f > hf_hz].sum())
    return hi / tot if tot > 0 else float("nan")


def command_metrics(flight: dict[str, Any], hf_hz: float = 5.0, quiet: dict[str, Any] | None = None) -> dict[str, float]:
    """The module docstring's metrics of one flight (``quiet``: the same seed without the gyro noise)."""
    dt, rl = flight["dt"], flight["rate_limit"]
    on, cmd = flight["on"], flight["cmd"]
    both = on.copy()
    both[1:] &= on[:-1]
    both[0] = False
    r = np.zeros_like(cmd)
    r[1:] = (cmd[1:] - cmd[:-1]) / dt
    rb = r[both]
    w = max(int(round(WINDOW_S / dt)), 1)
    sq = np.where(both[:, None], r ** 2, 0.0).sum(axis=1)
    csum, cnt = np.concatenate([[0.0], np.cumsum(sq)]), np.concatenate([[0], np.cumsum(both)])
    n_w = cnt[w:] - cnt[:-w]
    ms = np.where(n_w >= w // 2, (csum[w:] - csum[:-w]) / np.maximum(2 * n_w, 1), 0.0)
    out = {"cmd_rate": float(np.sqrt(np.mean(rb ** 2))) / rl if rb.size else float("nan"),
           "cmd_rate_peak": float(np.sqrt(ms.max())) / rl if ms.size else float("nan"),
           "cmd_over": float(np.mean(np.any(np.abs(rb) > rl, axis=1))) if rb.size else float("nan"),
           "cmd_hf": _hf_share(r, both, dt, hf_hz)}
    inc = np.sign(r)
    rev = (inc[1:] * inc[:-1] < 0) & both[1:, None] & both[:-1, None]
    out["reversal_hz"] = float(rev.sum()) / (2 * max(int(both[1:].sum()), 1) * dt)
    g = flight["rate"]
    out["gimbal_rate"] = math.degrees(float(np.sqrt(np.mean(g[on] ** 2)))) if on.any() else float("nan")
    out["at_limit"] = float(np.mean(np.any(np.abs(g[on]) >= 0.99 * rl, axis=1))) if on.any() else float("nan")
    acc = np.zeros_like(g)
    acc[1:] = (g[1:] - g[:-1]) / dt
    out["gimbal_acc"] = math.degrees(float(np.sqrt(np.mean(acc[both] ** 2)))) if rb.size else float("nan")
    out["travel_deg"] = math.degrees(float(np.abs(g[on]).sum()) * dt)
    out["cmd_rate_noise"] = float("nan")
    if quiet is not None:
        n = min(len(flight["t"]), len(quiet["t"]))
        both_q = both[:n] & quiet["on"][:n]
        both_q[1:] &= quiet["on"][: n - 1]
        d = cmd[:n] - quiet["cmd"][:n]
        rd = np.zeros_like(d)
        rd[1:] = (d[1:] - d[:-1]) / dt
        if both_q.any():
            out["cmd_rate_noise"] = float(np.sqrt(np.mean(rd[both_q] ** 2))) / rl
    return out


def flyability_episode(task: FlyTask) -> dict[str, Any]:
    """The two flights of ``task`` and their metrics (:func:`command_metrics`), with the labels, the failure
    and the largest q-alpha [kPa deg] of the flight with the noise."""
    loud = fly(task.policy, task.condition, task.seed)
    quiet = fly(task.policy, task.condition.with_options(gyro_arw_rad_per_sqrt_s=0.0), task.seed)
    rec = {"policy": task.policy.name, "condition": task.condition.name, "model": task.condition.model,
           "seed": int(task.seed), "failed": loud["failed"], "termination": loud["termination"],
           "duration_s": float(loud["t"][-1]), "max_qalpha_kpa_deg": float(np.max(loud["qalpha"])) / 1e3}
    rec.update(command_metrics(loud, task.hf_hz, quiet))
    return rec


def run_flyability(policies: Sequence[PolicySpec], suite: str = "smile-v1", seeds: int = 3, seed_set: str = "validation",
                   models: Sequence[str] | None = None, hf_hz: float = 5.0, executor: str = "local",
                   workers: int | None = None, progress: bool = True) -> list[dict[str, Any]]:
    """:func:`flyability_episode` of every policy, condition (``models``: all when None) and seed."""
    s = get_suite(suite)
    conds = [c for c in s.conditions if models is None or c.model in models]
    tasks = [FlyTask(p, c, seed, hf_hz) for p in policies for c in conds for seed in s.seeds(seed_set, seeds)]
    return run_map(flyability_episode, tasks, executor=executor, workers=workers, progress=progress,
                   desc="flyability", unit="episode pair")


def flyability_table(records: Sequence[dict[str, Any]], thresholds: Sequence[float] = (0.1, 0.2, 0.33)) -> str:
    """A Markdown table: per policy and condition, the means over the seeds (``cmd_rate`` with its range),
    and for each threshold whether the mean ``cmd_rate`` meets it."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in records:
        groups.setdefault((r["policy"], r["model"]), []).append(r)
    head = ("| policy | model | seeds | failed | commanded rate RMS [% of limit] | of it, the gyro noise [%] "
            "| peak 2 s RMS [%] | steps asking > limit [%] | above 5 Hz [%] | reversals [1/s] | gimbal rate RMS [deg/s] "
            "| at rate limit [%] | gimbal acc. RMS [deg/s^2] | travel [deg] | " + " | ".join(f"<= {100 * x:g} %" for x in thresholds) + " |")
    lines = [head, "|" + "---|" * 2 + "---:|" * (12 + len(thresholds))]

    def m(rs, k, scale=1.0, fmt="{:.1f}"):
        v = [scale * r[k] for r in rs if math.isfinite(r[k])]
        return fmt.format(np.mean(v)) if v else "-"

    for (pol, model), rs in groups.items():
        c = [100 * r["cmd_rate"] for r in rs]
        passes = ["yes" if np.mean(c) <= 100 * x else "no" for x in thresholds]
        lines.append(f"| {pol} | {model} | {len(rs)} | {sum(r['failed'] for r in rs)} "
                     f"| {np.mean(c):.1f} ({min(c):.1f}-{max(c):.1f}) | {m(rs, 'cmd_rate_noise', 100)} | {m(rs, 'cmd_rate_peak', 100)} "
                     f"| {m(rs, 'cmd_over', 100)} | {m(rs, 'cmd_hf', 100, '{:.0f}')} | {m(rs, 'reversal_hz')} "
                     f"| {m(rs, 'gimbal_rate', 1, '{:.2f}')} | {m(rs, 'at_limit', 100)} | {m(rs, 'gimbal_acc', 1, '{:.0f}')} | {m(rs, 'travel_deg', 1, '{:.0f}')} | "
                     + " | ".join(passes) + " |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.flyability --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(3, lo=1, hi=10_000)
    """seeds per policy and condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """test or validation"""
    models: list[str] | None = arg(None, metavar="MODEL")
    """the conditions' flight models (default: all of the suite)"""
    hf_hz: float = arg(5.0, lo=0.0, lo_open=True)
    """the frequency above which the commanded rate counts as high-frequency [Hz]"""
    thresholds: list[float] = arg(default_factory=lambda: [0.1, 0.2, 0.33], metavar="FRACTION")
    """candidate limits on the commanded rate's RMS, as fractions of the rate limit"""
    csv_out: Path | None = None
    """write every record to this CSV file"""
    executor: str = arg("local", choices=EXECUTORS)
    """local (process pool), serial or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000)
    """parallel workers (default: the CPUs available)"""
    progress: bool = True
    """show a progress bar"""


def main(argv: Sequence[str] | None = None) -> int:
    """Fly, print the table (and write the CSV)."""
    from lvgym.benchmark.registry import resolve_policy

    exit_on_sigterm()
    a = parse(Args, argv, PROG, __doc__)
    specs = [resolve_policy(p, command_name(PROG)) for p in a.policies]
    records = run_flyability(specs, a.suite, a.seeds, a.seed_set, a.models, a.hf_hz, a.executor, a.workers, a.progress)
    if a.csv_out is not None:
        a.csv_out.parent.mkdir(parents=True, exist_ok=True)
        with a.csv_out.open("w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=list(records[0]))
            w.writeheader()
            w.writerows(records)
    sys.stdout.write(flyability_table(records, a.thresholds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
