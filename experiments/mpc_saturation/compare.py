"""How the constrained MPC and ``lqg`` with anti-windup fly against ``lqg``, where nothing saturates and where
the gimbal's limits bind.

    python -m experiments.mpc_saturation.compare                                  # smile-v1, 3 validation seeds
    python -m experiments.mpc_saturation.compare --suite smile-v1-maxq-gust --gimbal-limit-deg 2 --rate-limit-degps 10

Every episode is the benchmark's (:func:`lvgym.benchmark.runner.play_episode`, its record: ``score``,
``failed``, ``rate_error_rad``, ``gimbal_rate_limit_s``) with the policy wrapped to measure, per control
step: the wall time of its ``act`` [s], and the time [s] the gimbal sits at its angle limit (``|gimbal|``
within 1 % of the limit, from the ``info`` the policy is handed). ``--gimbal-limit-deg`` and
``--rate-limit-degps`` narrow the actuator (the env options ``gimbal_limit_deg``, ``gimbal_rate_limit_degps``;
the policies read the limits from the env): the same disturbance then asks for more than the gimbal gives,
which is a larger disturbance relative to the authority. One process (``--executor serial``) keeps the act
times of the policies comparable.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.runner import PolicySpec, build_policy, play_episode
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition, get_suite
from lvgym.commandline import arg, command_name, parse
from lvgym.parallel import EXECUTORS, exit_on_sigterm, run_map

__all__ = ["SatTask", "TimedPolicy", "fly", "run", "table"]

PROG = "python -m experiments.mpc_saturation.compare"
#: a gimbal within this fraction of its limit counts as at the limit [-]
AT_LIMIT = 0.99


class TimedPolicy:
    """``policy`` with the wall time of each ``act`` [s] (``act_s``) and each step's ``|gimbal|`` [rad]
    (``gimbal``, from the ``info`` it is handed) recorded."""

    def __init__(self, policy: Any) -> None:
        self.policy, self.name = policy, policy.name
        self.act_s: list[float] = []
        self.gimbal: list[float] = []

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if "gimbal" in info:
            self.gimbal.append(float(np.max(np.abs(info["gimbal"]))))
        t0 = time.perf_counter()
        a = self.policy.act(observation, info)
        self.act_s.append(time.perf_counter() - t0)
        return a


@dataclass(frozen=True)
class SatTask:
    """One seed of one policy on one condition."""

    policy: PolicySpec
    condition: Condition
    seed: int


def fly(task: SatTask) -> dict[str, Any]:
    """The benchmark record of ``task`` plus ``act_ms_mean``, ``act_ms_p99``, ``act_ms_max`` (the policy's act
    time per control step [ms]), ``angle_limit_s`` (time at the angle limit [s]) and, for the MPC, its
    ``qp_solves`` (periods OSQP was called) and ``qp_fallbacks``."""
    env = task.condition.make_env()
    inner = build_policy(task.policy, env)
    pol = TimedPolicy(inner)
    rec = play_episode(pol, env, task.seed)
    act = 1e3 * np.array(pol.act_s)
    dt = float(env.unwrapped.task.control_dt_s)
    limit = float(env.unwrapped.gimbal_limit)
    out = {"policy": task.policy.name, "condition": task.condition.name, "model": task.condition.model,
           "seed": int(task.seed), "score": rec["score"], "failed": bool(rec["failed"]),
           "rate_error_rad": rec["rate_error_rad"], "gimbal_rate_limit_s": rec["gimbal_rate_limit_s"],
           "angle_limit_s": dt * int(np.sum(np.array(pol.gimbal) >= AT_LIMIT * limit)),
           "act_ms_mean": float(act.mean()), "act_ms_p99": float(np.percentile(act, 99)), "act_ms_max": float(act.max())}
    if hasattr(inner, "qp_counts"):
        c = inner.qp_counts
        out.update(qp_solves=c["solves"], qp_fallbacks=c["fallbacks"])
    return out


def run(policies: Sequence[PolicySpec], suite: str, seeds: int, seed_set: str, models: Sequence[str] | None,
        options: dict[str, Any], executor: str = "serial", progress: bool = True) -> list[dict[str, Any]]:
    """:func:`fly` of every policy, condition (``models``: all when None) and seed, the env options
    ``options`` added to every condition."""
    s = get_suite(suite)
    conds = [c.with_options(**options) if options else c for c in s.conditions if models is None or c.model in models]
    tasks = [SatTask(p, c, seed) for c in conds for seed in s.seeds(seed_set, seeds) for p in policies]
    return run_map(fly, tasks, executor=executor, workers=1 if executor == "serial" else None, progress=progress,
                   desc="mpc saturation", unit="episode")


def table(records: Sequence[dict[str, Any]]) -> str:
    """Markdown: one line per policy and condition (means over the seeds; the seeds' scores listed)."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in records:
        groups.setdefault((r["condition"], r["policy"]), []).append(r)
    lines = ["| condition | policy | seeds | failed | score [rad] (per seed) | rate error [rad] | at angle limit [s] "
             "| at rate limit [s] | act [ms] mean / p99 / max | QP solves (fallbacks) |",
             "|---|---|---:|---:|---|---:|---:|---:|---|---|"]
    for (cond, pol), rs in sorted(groups.items()):
        def m(k: str) -> float:
            return float(np.mean([r[k] for r in rs]))
        qp = f"{sum(r['qp_solves'] for r in rs)} ({sum(r['qp_fallbacks'] for r in rs)})" if "qp_solves" in rs[0] else "-"
        scores = ", ".join(f"{r['score']:.4f}" for r in rs)
        lines.append(f"| {cond} | {pol} | {len(rs)} | {sum(r['failed'] for r in rs)} | {m('score'):.4f} "
                     f"({scores}) | {m('rate_error_rad'):.4f} | {m('angle_limit_s'):.2f} "
                     f"| {m('gimbal_rate_limit_s'):.2f} | {m('act_ms_mean'):.3f} / {m('act_ms_p99'):.3f} / "
                     f"{max(r['act_ms_max'] for r in rs):.2f} | {qp} |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.mpc_saturation.compare --help``)."""

    policies: list[str] = arg(default_factory=lambda: ["lqg", "lqg-aw", "mpc"], metavar="POLICY")
    """registered names"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(3, lo=1, hi=10_000)
    """seeds per policy and condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """validation (tuning) or test"""
    models: list[str] | None = arg(None, metavar="MODEL")
    """the conditions' flight models (default: all of the suite)"""
    gimbal_limit_deg: float | None = arg(None, lo=0.1, hi=30.0)
    """the gimbal's angle limit [deg] (default: the vehicle's, 5 deg)"""
    rate_limit_degps: float | None = arg(None, lo=0.1, hi=1000.0)
    """the servo's rate limit [deg/s] (default: the env's, 30 deg/s)"""
    mission_time_s: float | None = arg(None, lo=1.0, hi=1000.0)
    """shorten every episode (smoke runs)"""
    executor: str = arg("serial", choices=EXECUTORS)
    """serial (one process: comparable act times), local or ray"""
    progress: bool = False
    """show a progress bar"""


def main(argv: Sequence[str] | None = None) -> int:
    """Fly, print the table."""
    from lvgym.benchmark.registry import resolve_policy

    exit_on_sigterm()
    a = parse(Args, argv, PROG, __doc__)
    specs = [resolve_policy(p, command_name(PROG)) for p in a.policies]
    options = {k: v for k, v in (("gimbal_limit_deg", a.gimbal_limit_deg), ("gimbal_rate_limit_degps", a.rate_limit_degps),
                                 ("mission_time_s", a.mission_time_s)) if v is not None}
    records = run(specs, a.suite, a.seeds, a.seed_set, a.models, options, a.executor, a.progress)
    sys.stdout.write(table(records))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
