"""Where a v2 suite's room is for the disturbance-observer student: the privileged reference with and without
its wind preview, on the true and on the flight computer's errors, beside the suite's classical reference
design, on **validation** seeds (the family: on its validation vehicles; no test seed or vehicle is flown).

    python -m experiments.fault_id.law_room --suite family-v2 --seeds 3 --models nonrigid rigid   # 7 minutes
    python -m experiments.fault_id.law_room --suite stratos-tvc-v2 --seeds 20

The student (:mod:`lvgym.agents.policies.inversion`) can at best fly the reference's law on the flight computer's
errors without the wind ahead (``observed, no preview``: what its teacher flies, the law on the true terms).
Prints per variant and flight model the mean ``score_v2`` and the failed or unflyable flights over validation
seeds ``0 .. --seeds - 1`` (on the family, of each of its 10 validation vehicles,
:data:`~lvgym.benchmark.suites.FAMILY_VALIDATION_VEHICLES`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lvgym.commandline import arg, parse

from .privileges import reference
from .train import condition, scored

#: the reference's variants (keywords of :func:`.privileges.reference`)
VARIANTS = {"privileged": {}, "no preview": {"preview": False}, "observed": {"observed": True},
            "observed, no preview": {"preview": False, "observed": True},
            "observed, the moment extrapolated 5 steps": {"preview": False, "observed": True, "aero_ahead_steps": 5}}
#: the suites it takes, with the classical design each is compared with (the suite's reference design;
#: the slender vehicle's only design)
CLASSICAL = {"smile-v2": "lqg", "smile-v2-faults": "lqg", "smile-v2-maxq-gust": "gs-pd-relief",
             "stratos-tvc-v2": "gs-pid-flex-quiet", "slender-v2": "gs-pid-flex", "family-v2": "auto-lqg"}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.law_room --help``)."""

    suite: str = arg("family-v2", choices=tuple(CLASSICAL))
    """the v2 suite"""
    seeds: int = arg(3, lo=1, hi=300)
    """validation seeds (on the family: per validation vehicle)"""
    models: list[str] = arg(default_factory=lambda: ["nonrigid"], choices=("rigid", "nonrigid"), metavar="MODEL")
    """flight models"""


def places(suite: str, seeds: int) -> list[tuple[dict[str, Any], int]]:
    """The flights: (env keywords, seed) pairs, the family's spread over its validation vehicles."""
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES, get_suite

    if suite == "family-v2":
        return [({"vehicle": v}, k) for v in FAMILY_VALIDATION_VEHICLES for k in range(seeds)]
    return [({}, int(k)) for k in get_suite(suite).seeds("validation", seeds)]


def flights(suite: str, model: str, seeds: int, variant: str | None) -> list[dict]:
    """The records of ``variant`` of :data:`VARIANTS` (None: the suite's classical design) on ``suite``."""
    import lvgym.cli.policies  # noqa: F401  (registers the classical designs)
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy, play_episode

    out, envs = [], {}
    for options, seed in places(suite, seeds):
        key = tuple(options.items())
        if key not in envs:
            env = condition(model, suite, privileged_info=variant is not None, **options).make_env()
            design = build_policy(resolve_policy(CLASSICAL[suite]), env) if variant is None else None
            envs[key] = (env, design)
        env, design = envs[key]
        law = reference(env, **VARIANTS[variant]) if design is None else design
        out.append(play_episode(law, env, seed, flyability=True))
    return out


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.law_room", __doc__)
    print(f"{a.suite}, validation seeds 0-{a.seeds - 1}" + (" of each validation vehicle" if a.suite == "family-v2"
                                                                else ""))
    print("| policy | model | mean score_v2 | failed or unflyable |\n|---|---|---|---|")
    for model in a.models:
        for variant in (*VARIANTS, None):
            rs = flights(a.suite, model, a.seeds, variant)
            mean, bad = scored(rs)
            print(f"| {variant or CLASSICAL[a.suite]} | {model} | {mean:.3f} | {bad} of {len(rs)} |", flush=True)


if __name__ == "__main__":
    main()
