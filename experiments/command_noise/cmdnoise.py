"""How much gimbal rate the flight gyro's noise commands through a policy, measured in the nonlinear
simulation.

    python -m experiments.command_noise.cmdnoise                               # the default policies, smile-v1, 3 test seeds
    python -m experiments.command_noise.cmdnoise --policies gs-pid-flex lqg --seeds 5 --seed-set validation

Each episode is flown twice on the same seed: as the protocol flies it, and with the gyro's angle random
walk set to zero (``gyro_arw_rad_per_sqrt_s = 0``; the env still draws the same random numbers, so the
wind, the dispersions and the bias are those of the first flight). The difference of the two command
histories is the command's response to the gyro's white noise, plus whatever that noise changes in the
flight; its change per control period over the period is the gimbal rate the noise commands. Reported per
policy and condition, over the seeds: that rate's RMS while the controller is on, as a fraction of the
servo's rate limit, for the whole flight and per thrusting phase, and the RMS of the gimbal's own rate
[deg/s] in both flights (what the servo makes of it).

A linear loop's value at a frozen time is :func:`lvgym.baselines.design.noise.command_noise_rate` (the design
requirement of ``gs-pid-flex``, docs/flex-design.md); this measures it for any policy, learned ones
included, as :mod:`.margins` measures the gain and delay margins.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.commandline import arg, command_name, parse
from lvgym.parallel import EXECUTORS, exit_on_sigterm, run_map

from lvgym.benchmark.runner import PolicySpec, build_policy
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition, get_suite

__all__ = ["NoiseTask", "command_noise_episode", "run_command_noise", "noise_table"]

PROG = "python -m experiments.command_noise.cmdnoise"
DEFAULT_POLICIES = ["gs-pid", "gs-pid-flex", "lqg", "aac", "ppo-res-lqg"]
#: the thrusting phases of smile-v1's flight the table splits (boost from the controller's start to
#: burnout, upper stage from ignition to the end) [s]; a flight without them reports the whole only
PHASES = {"boost": (2.0, 43.0), "upper": (54.0, math.inf)}


@dataclass(frozen=True)
class NoiseTask:
    """One seed of one policy on one condition."""

    policy: PolicySpec
    condition: Condition
    seed: int


def _fly(spec: PolicySpec, condition: Condition, seed: int) -> dict[str, Any]:
    env = condition.make_env()
    policy = build_policy(spec, env)
    obs, info = env.reset(seed=int(seed))
    policy.reset()
    on_index = env.unwrapped.observation_layout.slice("controller_on").start
    t, a, rate, on = [], [], [], []
    while True:
        on.append(float(obs[on_index]) > 0.5)
        action = np.asarray(policy.act(obs, info), float)
        obs, _, terminated, truncated, info = env.step(action)
        t.append(float(info["time"]))
        a.append(action)
        rate.append(np.degrees(np.abs(np.asarray(info["gimbal_rate"], float))))
        if terminated or truncated:
            break
    u = env.unwrapped
    return {"t": np.array(t), "action": np.array(a), "rate": np.array(rate), "on": np.array(on),
            "dt": float(u.task.control_dt_s), "limit": float(u.gimbal_limit),
            "rate_limit": float(u.sim.servo.rate_limit)}


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x * x))) if x.size else float("nan")


def command_noise_episode(task: NoiseTask) -> dict[str, Any]:
    """The two flights of ``task`` and their difference ``d`` (the commands' difference [rad]): ``noise``
    (RMS of the commanded rate ``(d[k] - d[k-1]) / dt`` over the samples where the controller is on in
    both flights at both steps, as a fraction of the servo's rate limit; per phase ``noise_<phase>``),
    ``noise_deg_s`` (the same in deg/s), ``rate_deg_s`` and ``rate_quiet_deg_s`` (RMS gimbal rate of the
    flight and of the noiseless one while on [deg/s]) and ``samples`` (how many samples both share)."""
    loud = _fly(task.policy, task.condition, task.seed)
    quiet = _fly(task.policy, task.condition.with_options(gyro_arw_rad_per_sqrt_s=0.0), task.seed)
    n = min(len(loud["t"]), len(quiet["t"]))
    on = loud["on"][:n] & quiet["on"][:n]
    d = (loud["action"][:n] - quiet["action"][:n]) * loud["limit"]
    rate = np.zeros_like(d)
    rate[1:] = (d[1:] - d[:-1]) / loud["dt"]                 # the commanded rate the noise adds [rad/s]
    both = on.copy()
    both[1:] &= on[:-1]
    both[0] = False
    scale = 1.0 / loud["rate_limit"]
    out = {"policy": task.policy.name, "condition": task.condition.name, "model": task.condition.model,
           "seed": int(task.seed), "samples": int(n), "noise": scale * _rms(rate[both]),
           "noise_deg_s": math.degrees(_rms(rate[both])),
           "rate_deg_s": _rms(loud["rate"][:n][on]), "rate_quiet_deg_s": _rms(quiet["rate"][:n][on])}
    t = loud["t"][:n]
    for name, (lo, hi) in PHASES.items():
        m = both & (t > lo) & (t <= hi)
        out[f"noise_{name}"] = scale * _rms(rate[m])
    return out


def run_command_noise(policies: Sequence[PolicySpec], suite: str = "smile-v1", seeds: int = 3,
                      seed_set: str = "test", models: Sequence[str] | None = None, executor: str = "local",
                      workers: int | None = None, progress: bool = True) -> list[dict[str, Any]]:
    """:func:`command_noise_episode` of every policy, condition (``models``: all when None) and seed."""
    s = get_suite(suite)
    conds = [c for c in s.conditions if models is None or c.model in models]
    tasks = [NoiseTask(p, c, seed) for p in policies for c in conds for seed in s.seeds(seed_set, seeds)]
    return run_map(command_noise_episode, tasks, executor=executor, workers=workers, progress=progress,
                   desc="command noise", unit="episode pair")


def noise_table(records: Sequence[dict[str, Any]]) -> str:
    """A Markdown table: per policy and condition, the mean over the seeds of each record's RMS values
    (the commanded rate the noise adds in % of the servo's rate limit and in deg/s; the gimbal's rate in
    deg/s) and the range of the first."""
    keys: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in records:
        keys.setdefault((r["policy"], r["condition"]), []).append(r)
    lines = ["| policy | condition | seeds | gimbal rate commanded by the gyro noise [% of the rate limit] "
             "| [deg/s] | boost [%] | upper stage [%] | gimbal rate [deg/s] | gimbal rate without the noise [deg/s] |",
             "|---|---|---:|---|---:|---:|---:|---:|---:|"]
    for (pol, cond), rs in keys.items():
        def mean(k: str, scale: float = 1.0) -> str:
            v = [scale * r[k] for r in rs if math.isfinite(r[k])]
            return f"{np.mean(v):.2f}" if v else "-"
        noise = [100 * r["noise"] for r in rs]
        lines.append(f"| {pol} | {cond} | {len(rs)} | {np.mean(noise):.2f} ({min(noise):.2f}-{max(noise):.2f}) "
                     f"| {mean('noise_deg_s')} | {mean('noise_boost', 100)} | {mean('noise_upper', 100)} "
                     f"| {mean('rate_deg_s')} | {mean('rate_quiet_deg_s')} |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.command_noise.cmdnoise --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(3, lo=1, hi=10_000)
    """seeds per policy and condition"""
    seed_set: str = arg("test", choices=SEED_SETS)
    """test or validation"""
    models: list[str] | None = arg(None, metavar="MODEL")
    """the conditions' flight models (default: all of the suite)"""
    executor: str = arg("local", choices=EXECUTORS)
    """local (process pool), serial or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000)
    """parallel workers (default: the CPUs available)"""
    progress: bool = True
    """show a progress bar"""


def main(argv: Sequence[str] | None = None) -> int:
    """Fly, print the table."""
    from lvgym.benchmark.registry import resolve_policy

    exit_on_sigterm()
    a = parse(Args, argv, PROG, __doc__)
    specs = [resolve_policy(p, command_name(PROG)) for p in a.policies]
    records = run_command_noise(specs, a.suite, a.seeds, a.seed_set, a.models, a.executor, a.workers, a.progress)
    sys.stdout.write(noise_table(records))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
