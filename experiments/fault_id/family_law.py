"""Whether the disturbance-observer student's law can fly the launcher family: the privileged reference with
and without its wind preview, on the true and on the flight computer's errors, beside ``auto-lqg``, on the
family's **validation** vehicles (no test vehicle is flown).

    python -m experiments.fault_id.family_law --seeds 3            # about 10 minutes on 2 cores

The student (:mod:`lvgym.agents.inversion`) can at best fly the reference's law on the flight computer's
errors without the wind ahead (``observed, no preview``: what its teacher flies, the law on the true terms).
Prints per variant and flight model the mean ``score_v2`` and the failed or unflyable flights over validation
seeds ``0 .. --seeds - 1`` of each of the 10 validation vehicles
(:data:`~lvgym.benchmark.suites.FAMILY_VALIDATION_VEHICLES`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lvgym.cli.args import arg, parse

from .privileges import reference
from .train import condition

#: the reference's variants (keywords of :func:`.privileges.reference`)
VARIANTS = {"privileged": {}, "no preview": {"preview": False}, "observed": {"observed": True},
            "observed, no preview": {"preview": False, "observed": True}}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.family_law --help``)."""

    seeds: int = arg(3, lo=1, hi=100)
    """validation seeds per vehicle and flight model"""
    models: list[str] = arg(default_factory=lambda: ["nonrigid"], choices=("rigid", "nonrigid"), metavar="MODEL")
    """flight models"""


def flights(model: str, seeds: int, variant: str | None) -> list[dict]:
    """The records of ``variant`` of :data:`VARIANTS` (None: ``auto-lqg``) on every validation vehicle."""
    import lvgym.cli.policies  # noqa: F401  (registers auto-lqg)
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy, play_episode
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES

    out = []
    for v in FAMILY_VALIDATION_VEHICLES:
        env = condition(model, "family-v2", privileged_info=variant is not None, vehicle=v).make_env()
        design = build_policy(resolve_policy("auto-lqg"), env) if variant is None else None
        for seed in range(seeds):
            law = reference(env, **VARIANTS[variant]) if design is None else design
            law.reset()
            out.append(play_episode(law, env, seed, flyability=True))
    return out


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.family_law", __doc__)
    print("| policy | model | mean score_v2 | failed or unflyable |\n|---|---|---|---|")
    for model in a.models:
        for variant in (*VARIANTS, None):
            rs = flights(model, a.seeds, variant)
            bad = sum(bool(r["failed"] or not r["flyable"]) for r in rs)
            mean = float(np.mean([r["score_v2"] for r in rs]))
            print(f"| {variant or 'auto-lqg'} | {model} | {mean:.3f} | {bad} of {len(rs)} |", flush=True)


if __name__ == "__main__":
    main()
