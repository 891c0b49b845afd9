"""A first probe of in-flight faults on the shipped policies, emulated between the policy and the env.

    python -m experiments.protocol_v2_design.faults                        # lqg, gs-pid-flex, aac, ppo-res-lqg; 3 validation seeds
    python -m experiments.protocol_v2_design.faults --policies lqg aac --seeds 5 --models rigid nonrigid

lvgym's envs have no fault injection yet; these faults act on what the policy sees or sends, from the onset
time on (the env is the protocol's, unchanged):

- ``loe50``, ``loe70``: loss of effectiveness, the command times 0.5 / 0.3 on both axes (an actuator or nozzle
  that moves less than commanded; for the servo loop the same as a thrust-vector gain loss);
- ``stuck``: the pitch command frozen at its value at the onset (a jammed pitch actuator holds its position);
- ``hardover``: the pitch command at +1 (the gimbal limit) for 1 s, then released (a runaway caught by
  redundancy management);
- ``lag``: a first-order lag of 0.1 s on the command (a servo that lost bandwidth: 10 rad/s, beside the
  15 rad/s servo);
- ``bias``: a pitch gyro bias step of 0.5 deg/s: the observed pitch rate error shifts by it, and the strapdown
  pitch attitude error drifts by it (what the flight computer's integration of that gyro does);
- ``sign``: the pitch gyro's sign inverted (rate and strapdown attitude), the Proton-M 2013 fault, from lift-off.

Each is flown on the suite's validation seeds (never the test seeds: this is a design study); reported: failures
(and why) and the mean score over the seeds.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.runner import PolicySpec, build_policy, play_episode
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition, get_suite
from lvgym.commandline import arg, command_name, parse
from lvgym.parallel import EXECUTORS, exit_on_sigterm, run_map

__all__ = ["FAULTS", "FaultPolicy", "FaultTask", "fault_episode", "fault_table", "run_faults"]

PROG = "python -m experiments.protocol_v2_design.faults"
#: fault name -> onset [s]
FAULTS = {"none": 0.0, "loe50": 15.0, "loe70": 15.0, "stuck": 15.0, "hardover": 25.0, "lag": 15.0, "bias": 15.0,
          "sign": 0.0}
BIAS_RADPS = math.radians(0.5)
LAG_S = 0.1
I_PITCH_RATE, I_PITCH_ATT = 1, 3                  # the flight observation's pitch rate and attitude errors


class FaultPolicy:
    """``base`` with the fault ``fault`` from ``onset`` [s] (module docstring)."""

    def __init__(self, base: Any, fault: str, onset: float, dt: float) -> None:
        self.base, self.fault, self.onset, self.dt = base, fault, onset, dt
        self.name = f"{getattr(base, 'name', 'policy')}+{fault}"

    def reset(self) -> None:
        self.base.reset()
        self.t = 0.0
        self.frozen: float | None = None
        self.lagged = np.zeros(2)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        t = float(info.get("time", 0.0)) if info else 0.0
        on = t >= self.onset
        obs = np.array(observation, dtype=np.float32, copy=True)
        if on and self.fault == "bias":
            obs[I_PITCH_RATE] += BIAS_RADPS
            obs[I_PITCH_ATT] += BIAS_RADPS * (t - self.onset)
        if on and self.fault == "sign":
            obs[I_PITCH_RATE] = -obs[I_PITCH_RATE]
            obs[I_PITCH_ATT] = -obs[I_PITCH_ATT]
        u = np.clip(np.asarray(self.base.act(obs, info), dtype=float), -1.0, 1.0)
        if not on or self.fault in ("none", "bias", "sign"):
            return u.astype(np.float32)
        if self.fault in ("loe50", "loe70"):
            u = u * (0.5 if self.fault == "loe50" else 0.3)
        elif self.fault == "stuck":
            if self.frozen is None:
                self.frozen = float(u[0])
            u[0] = self.frozen
        elif self.fault == "hardover" and t < self.onset + 1.0:
            u[0] = 1.0
        elif self.fault == "lag":
            self.lagged += (u - self.lagged) * (1.0 - math.exp(-self.dt / LAG_S))
            u = self.lagged.copy()
        return u.astype(np.float32)


@dataclass(frozen=True)
class FaultTask:
    """One seed of one policy with one fault on one condition."""

    policy: PolicySpec
    fault: str
    condition: Condition
    seed: int


def fault_episode(task: FaultTask) -> dict[str, Any]:
    """The protocol's episode record of ``task`` (``play_episode``), with its labels."""
    env = task.condition.make_env()
    pol = FaultPolicy(build_policy(task.policy, env), task.fault, FAULTS[task.fault],
                      float(env.unwrapped.task.control_dt_s))
    rec = play_episode(pol, env, task.seed)
    return {"policy": task.policy.name, "fault": task.fault, "model": task.condition.model, "seed": task.seed,
            "score": rec["score"], "failed": rec["failed"], "failure_reason": rec["failure_reason"],
            "duration_s": rec["duration_s"], "max_qalpha_kpa_deg": rec["max_qalpha_pa_deg"] / 1e3}


def run_faults(policies: Sequence[PolicySpec], faults: Sequence[str], suite: str = "smile-v1", seeds: int = 3,
               seed_set: str = "validation", models: Sequence[str] | None = ("nonrigid",), executor: str = "local",
               workers: int | None = None, progress: bool = True) -> list[dict[str, Any]]:
    """:func:`fault_episode` of every policy, fault, condition and seed."""
    s = get_suite(suite)
    conds = [c for c in s.conditions if models is None or c.model in models]
    tasks = [FaultTask(p, f, c, seed) for p in policies for f in faults for c in conds
             for seed in s.seeds(seed_set, seeds)]
    return run_map(fault_episode, tasks, executor=executor, workers=workers, progress=progress,
                   desc="faults", unit="episode")


def fault_table(records: Sequence[dict[str, Any]]) -> str:
    """Markdown: a row per policy and model, a column per fault: failures / seeds and the mean score [rad]."""
    faults = list(dict.fromkeys(r["fault"] for r in records))
    keys = list(dict.fromkeys((r["policy"], r["model"]) for r in records))
    lines = ["| policy | model | " + " | ".join(f"{f} (onset {FAULTS[f]:g} s)" for f in faults) + " |",
             "|---|---|" + "---|" * len(faults)]
    for pol, model in keys:
        cells = []
        for f in faults:
            rs = [r for r in records if r["policy"] == pol and r["model"] == model and r["fault"] == f]
            n_fail = sum(r["failed"] for r in rs)
            why = sorted({r["failure_reason"].split(" ")[0] for r in rs if r["failed"]})
            cells.append(f"{n_fail}/{len(rs)}" + (f" ({', '.join(why)})" if why else "")
                         + f", {np.mean([r['score'] for r in rs]):.2f}")
        lines.append(f"| {pol} | {model} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.faults --help``)."""

    policies: list[str] = arg(default_factory=lambda: ["lqg", "gs-pid-flex", "aac", "ppo-res-lqg"], metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    faults: list[str] = arg(default_factory=lambda: list(FAULTS), metavar="FAULT", choices=tuple(FAULTS))
    """the faults flown"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(3, lo=1, hi=10_000)
    """seeds per policy, fault and condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """test or validation"""
    models: list[str] = arg(default_factory=lambda: ["nonrigid"], metavar="MODEL")
    """the conditions' flight models"""
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
    records = run_faults(specs, a.faults, a.suite, a.seeds, a.seed_set, a.models, a.executor, a.workers, a.progress)
    sys.stdout.write(fault_table(records))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
