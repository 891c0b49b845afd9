"""Load-relief variants of a gs-pid-flex schedule flown on a suite's validation seeds (the tuning table of
docs/flex-design.md, "The slender vehicle").

A variant scales each row's integral gain (``ki_scale``, one number or one per row), its proportional and
derivative gains (``kp_scale``) and sets its accelerometer gain (``accel_gain`` [rad/s per m/s^2], one
number or one per row; :mod:`.pid`, "Load relief"); ``signs`` replaces the policies' :data:`.pid.ACCEL_SIGNS` (to check
the sign). :func:`evaluate` flies it on every condition of the suite and returns, per flight model, the
failures, the mean score [rad], the largest and the median peak q-alpha [kPa deg].

``python -m experiments.load_relief.relief_sweep --schedule results/schedules/slender_flex.yaml "ki_scale=0.05"
"ki_scale=0.05, accel_gain=0.001"`` prints one line per variant (validation seeds 0-9 of ``slender-v1``).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml

from lvgym.benchmark.runner import play_episode
from lvgym.benchmark.suites import SUITES, get_suite
from lvgym.commandline import arg, parse

from lvgym.baselines.pid import GainSchedule, GainScheduledPIDPolicy

__all__ = ["variant", "evaluate"]


def _per_row(value: Any, n: int) -> list[float]:
    return [float(v) for v in value] if isinstance(value, (list, tuple)) else [float(value)] * n


def variant(doc: dict[str, Any], ki_scale: Any = 1.0, kp_scale: float = 1.0, accel_gain: Any = 0.0) -> GainSchedule:
    """The schedule of ``doc`` (a schedule document) with its rows changed as the module docstring says."""
    doc = copy.deepcopy(doc)
    n = len(doc["rows"])
    for row, ks, ka in zip(doc["rows"], _per_row(ki_scale, n), _per_row(accel_gain, n)):
        row["ki"] *= ks
        row["kp"] *= kp_scale
        row["kd"] *= kp_scale
        row["accel_gain"] = ka
    return GainSchedule.from_dict(doc)


def evaluate(doc: dict[str, Any], suite: str = "slender-v1", seeds: int = 10, signs: tuple | None = None,
             envs: dict | None = None, **changes: Any) -> dict[str, tuple[int, float, float, float]]:
    """Fly the variant of ``doc`` on the suite's validation seeds ``0 .. seeds-1`` (``envs``: the
    conditions' envs by model, reused across calls)."""
    conds = get_suite(suite).conditions
    envs = envs if envs is not None else {c.model: c.make_env() for c in conds}
    sched = variant(doc, **changes)
    out = {}
    for model, env in envs.items():
        policy = GainScheduledPIDPolicy(sched, env=env)
        if signs is not None:
            policy.accel_signs = np.asarray(signs, dtype=float)
        recs = [play_episode(policy, env, s) for s in range(seeds)]
        peaks = [r["max_qalpha_pa_deg"] / 1e3 for r in recs]
        out[model] = (sum(r["failed"] for r in recs), float(np.mean([r["score"] for r in recs])),
                      float(np.max(peaks)), float(np.median(peaks)))
    return out


def _keywords(spec: str) -> dict[str, Any]:
    """``"ki_scale=0.05, accel_gain=[0.001, 0.002]"`` as keywords: literals only (``ast.literal_eval``)."""
    import ast

    call = ast.parse(f"f({spec})", mode="eval").body
    if not isinstance(call, ast.Call) or call.args or any(k.arg is None for k in call.keywords):
        raise SystemExit(f"python -m experiments.load_relief.relief_sweep: variant {spec!r}: KEY=LITERAL, ... only")
    return {k.arg: ast.literal_eval(k.value) for k in call.keywords}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.load_relief.relief_sweep --help``)."""

    schedule: str
    """a schedule YAML (a plain flexdesign output)"""
    variants: list[str] = arg(positional=True, metavar="VARIANT")
    """keyword lists, e.g. 'ki_scale=0.05, accel_gain=0.001'"""
    suite: str = arg("slender-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(10, lo=1, hi=10_000)
    """validation seeds 0 .. n-1"""


def main(argv: list[str] | None = None) -> int:
    """Fly every variant, print a line each."""
    a = parse(Args, argv, "python -m experiments.load_relief.relief_sweep", __doc__)
    with open(a.schedule) as f:
        doc = yaml.safe_load(f)
    envs = {c.model: c.make_env() for c in get_suite(a.suite).conditions}
    for spec in a.variants:
        changes = _keywords(spec)
        res = evaluate(doc, a.suite, a.seeds, envs=envs, **changes)
        print(spec, "  ".join(f"{m}: {f}/{a.seeds} failed, score {s:.3f}, peak q-alpha max {mx:.1f} median {md:.1f} kPa deg"
                              for m, (f, s, mx, md) in res.items()), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
