"""How far is minus the score reward's return from the flight's ``score_v2`` where the flyability rule's budget
depends on steps not yet flown?

    python -m experiments.score_reward.deviation                          # smile-v2 non-rigid, 200 validation seeds
    python -m experiments.score_reward.deviation --suite smile-v2-maxq-gust --seeds 200

Each validation seed is flown twice, as the rows of one batched env each: by the benchmark (the suite's
condition, :func:`lvgym.benchmark.rows.fly_rows`, its record's ``score_v2``) and with the score reward
(``reward_kind="score_v2"``), by the same policy. The policy draws per row, from one seeded generator, a
gain on the suite's reference law (``lqg``; the gimbal at zero for a suite without one) uniform in
[0, 3], and with probability one half a command that alternates every step with an amplitude uniform in
[0, 1.5] times the rate limit's, from a time uniform over the mission: flights that fly, that fail, that
break the rule by a burst or by the budget, and that do both. It prints how the flights ended, how many of
them give minus the return equal to ``score_v2`` to 1e-9, and the largest deviation.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.batch import as_batch
from lvgym.benchmark.flyability import RMS_FRACTION
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.rows import fly_rows
from lvgym.benchmark.runner import build_policy
from lvgym.benchmark.suites import SUITES, VALIDATION_SEED0, condition, get_suite
from lvgym.commandline import arg, parse

__all__ = ["RandomLaw", "deviations", "main"]

PROG = "python -m experiments.score_reward.deviation"


class RandomLaw:
    """The study's batch policy (module docstring): ``inner``'s action times ``gain[row]`` plus, from flight
    time ``start_s[row]`` on, ``amplitude[row]`` [-] with the sign of the step's parity."""

    name = "random-law"

    def __init__(self, inner: Any, gain: np.ndarray, amplitude: np.ndarray, start_s: np.ndarray, dt: float) -> None:
        self.inner, self.gain, self.amplitude, self.start_s, self.dt = inner, gain, amplitude, start_s, dt

    def reset(self, rows: np.ndarray) -> None:
        self.inner.reset(rows)

    def act(self, rows: np.ndarray, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        a = np.asarray(self.inner.act(rows, observations, info), dtype=float) * self.gain[rows, None]
        t = np.asarray(info["time"], dtype=float)[rows]
        sign = np.where(np.round(t / self.dt) % 2 == 0, 1.0, -1.0)
        return a + (np.where(t >= self.start_s[rows], self.amplitude[rows], 0.0) * sign)[:, None]


def _law(cond: Any, reference: str, n: int, seed: int) -> RandomLaw:
    """A fresh :class:`RandomLaw` of ``n`` rows (the same draws for the same ``seed``)."""
    env = cond.make_env()
    task = env.unwrapped.task
    step = math.radians(task.gimbal_rate_limit_degps) * task.control_dt_s / (2.0 * env.unwrapped.gimbal_limit)
    rng = np.random.default_rng(seed)
    gain = rng.uniform(0.0, 3.0, n)
    amplitude = np.where(rng.uniform(size=n) < 0.5, rng.uniform(0.0, 1.5, n) * step, 0.0)
    start = rng.uniform(0.0, task.mission_time_s, n)
    spec = resolve_policy(reference or "zero")
    inner = as_batch(build_policy(spec, env), n, lambda: build_policy(spec, env))
    return RandomLaw(inner, gain, amplitude, start, task.control_dt_s)


def _returns(cond: Any, seeds: list[int], law: RandomLaw) -> tuple[np.ndarray, list[str]]:
    """Each row's return and how it ended in the score reward's env (``info["termination"]``)."""
    n = len(seeds)
    venv = cond.with_options(reward_kind="score_v2").make_vec_env(n)
    obs, info = venv.reset(seed=seeds)
    rows = np.arange(n)
    law.reset(rows)
    ret, done, ended = np.zeros(n), np.zeros(n, dtype=bool), [""] * n
    while not done.all():
        live = rows[~done]
        actions = np.zeros((n, 2))
        actions[live] = law.act(live, obs[live], info)
        obs, reward, terminated, truncated, info = venv.step(actions)
        ret[live] += reward[live]
        for b in live[(terminated | truncated)[live]].tolist():
            ended[b], done[b] = str(info["termination"][b]), True
    return ret, ended


def deviations(suite: str, model: str, n: int, seed: int = 59) -> list[dict[str, Any]]:
    """Per validation seed ``0 .. n - 1``: the benchmark's record's fields of interest, minus the score
    reward's return and how its episode ended."""
    cond = condition(suite, model)
    seeds = [VALIDATION_SEED0 + i for i in range(n)]
    reference = get_suite(suite).reference
    records = fly_rows(cond.make_vec_env(n), seeds, [(_law(cond, reference, n, seed), list(range(n)))],
                       flyability=True)
    ret, ended = _returns(cond, seeds, _law(cond, reference, n, seed))
    return [{"seed": s, "score_v2": r["score_v2"], "score": r["score"], "failed": r["failed"], "flyable": r["flyable"],
             "cmd_rate_rms": r["cmd_rate_rms"], "unflyable_at_s": r["unflyable_at_s"], "duration_s": r["duration_s"],
             "minus_return": float(-ret[b]), "ended": ended[b], "deviation": float(-ret[b] - r["score_v2"])}
            for b, (s, r) in enumerate(zip(seeds, records))]


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.score_reward.deviation --help``)."""

    suite: str = arg("smile-v2", metavar="SUITE", choices=lambda: sorted(s for s in SUITES if s.endswith("v2")
                                                                          or "-v2-" in s))
    """the v2 suite flown"""
    model: str = arg("nonrigid", choices=("rigid", "nonrigid"))
    """the flight model"""
    seeds: int = arg(200, lo=1, hi=10_000)
    """validation seeds (the rows of one batched env)"""
    seed: int = 59
    """the seed of the policy's draws"""
    out: Path | None = None
    """write every flight's fields to this JSON file"""


def main(argv: Sequence[str] | None = None) -> int:
    """Fly, print the summary (and write the JSON)."""
    a = parse(Args, argv, PROG, __doc__)
    rows = deviations(a.suite, a.model, a.seeds, a.seed)
    dev = np.array([abs(r["deviation"]) for r in rows])
    off = [r for r in rows if abs(r["deviation"]) > 1e-9]
    worst = rows[int(np.argmax(dev))]
    print(f"{a.suite} {a.model}, validation seeds {VALIDATION_SEED0}-{VALIDATION_SEED0 + a.seeds - 1}: "
          f"{sum(r['failed'] for r in rows)} failed, {sum(not r['flyable'] for r in rows)} unflyable, "
          f"{sum(r['failed'] and r['cmd_rate_rms'] > RMS_FRACTION for r in rows)} failed over the budget of their "
          f"own steps")
    print(f"minus the return equals score_v2 to 1e-9 in {len(rows) - len(off)} of {len(rows)} flights; "
          f"the largest deviation {dev.max():.3g} rad (seed {worst['seed']}: score_v2 {worst['score_v2']:.4f} rad, "
          f"minus the return {worst['minus_return']:.4f} rad, ended {worst['ended']!r})")
    for r in off:
        print(f"  seed {r['seed']}: deviation {r['deviation']:+.4f} rad, score_v2 {r['score_v2']:.4f}, failed "
              f"{r['failed']}, flyable {r['flyable']}, rms {r['cmd_rate_rms']:.3f}, ended {r['ended']!r}")
    if a.out is not None:
        a.out.write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
