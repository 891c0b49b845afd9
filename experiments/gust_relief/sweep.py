"""The gust-relief study's table (README.md): which law flies protocol v2's max-q gust without breaking the
q-alpha limit, and what the same cure does on the fault suite.

    python -m experiments.gust_relief.sweep --seeds 100
    python -m experiments.gust_relief.sweep --variants gs-pd-relief lqg lqg-released --suites smile-v2-faults

Flies each variant of :data:`VARIANTS` (registered designs, the laws of :mod:`.laws`) on the given v2 suites,
rigid and non-rigid, validation seeds ``0 .. seeds - 1``, and prints per suite the mean ``score_v2`` of every
variant with its failed or unflyable flights. A study: it flies no test seed.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lvgym.benchmark import evaluate, get_suite
from lvgym.benchmark.runner import PolicySpec
from lvgym.commandline import arg, parse
from lvgym.errors import ConfigError

from .laws import released_schedule

LAWS = "experiments.gust_relief.laws"
#: where the released LQG schedules are written
RESULTS = Path("results") / "gust_relief"
#: the max-q rows of SMILE's LQG schedules (20, 28.8 and 36 s)
MAXQ_ROWS = (2, 3, 4)


def _soft(**kw: object) -> tuple[str, tuple]:
    return f"{LAWS}:soft_law", tuple(sorted(kw.items()))


def _faded(**kw: object) -> tuple[str, tuple]:
    return f"{LAWS}:faded", tuple(sorted(kw.items()))


#: the variants by name: (factory, kwargs), or a registered name (None), or an LQG schedule to release
VARIANTS: dict[str, tuple[str, tuple] | None | tuple[str, float, float]] = {
    "lqg-front": None,
    "lqg": None,
    "gs-pd-relief": None,
    "lqg-front-faded-0.5-0.9": _faded(onset=0.5, full=0.9),
    "lqg-front-faded-0.3-0.7": _faded(onset=0.3, full=0.7),
    "reference-law-w1-as-it-acts": _soft(w=1.0, z=1.0, signals="true", moment=1.0),
    "pd-w1.5-z1.5": _soft(w=1.5, z=1.5),
    "pd-w2-z1": _soft(w=2.0, z=1.0),
    "pd-w3-z3": _soft(w=3.0, z=3.0),
    "pd-w2-z1-integral": _soft(w=2.0, z=1.0, ki=0.2),
    "pd-w2-z1-integral-frozen-50kPa": _soft(w=2.0, z=1.0, ki=0.2, q_off=5e4),
    "lqg-released": ("smile_lqg", 0.0, 1.0),
    "lqg-front-released": ("smile_lqg_front", 0.0, 1.0),
    "lqg-leak": ("smile_lqg", 1.0, 1.0),
}


def specs(names: Sequence[str]) -> list[PolicySpec]:
    """The policies of the variants ``names`` (a released LQG schedule is written under ``results/``)."""
    out = []
    for name in names:
        if name not in VARIANTS:
            raise ConfigError("variants", name, f"one of {list(VARIANTS)}")
        v = VARIANTS[name]
        if v is None:
            import lvgym.baselines  # noqa: F401  (registers the classical designs)
            from lvgym.benchmark.registry import resolve_policy

            out.append(resolve_policy(name))
        elif isinstance(v[1], tuple):
            out.append(PolicySpec(name, v[0], v[1]))
        else:
            base, ki_scale, leak_s = v
            path = released_schedule(base, MAXQ_ROWS, ki_scale, leak_s, RESULTS / f"{name}.npz")
            out.append(PolicySpec(name, "lvgym.baselines.lqg:smile_lqg", (("name", name), ("schedule", str(path.resolve())))))
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.gust_relief.sweep --help``)."""

    seeds: int = arg(100, lo=1, hi=10_000)
    """validation seeds per variant and condition"""
    variants: list[str] = arg(default_factory=lambda: list(VARIANTS), metavar="NAME")
    """the variants to fly (default: all)"""
    suites: list[str] = arg(default_factory=lambda: ["smile-v2-maxq-gust", "smile-v2-faults"], metavar="SUITE")
    """v2 suites to fly"""


def main(argv: Sequence[str] | None = None) -> None:
    args = parse(Args, argv, "python -m experiments.gust_relief.sweep", __doc__)
    try:
        policies = specs(args.variants)
    except ConfigError as exc:
        raise SystemExit(f"python -m experiments.gust_relief.sweep: {exc}") from None
    records = evaluate(policies, [get_suite(s) for s in args.suites], args.seeds, "validation", progress=False)
    score: dict[tuple, list[float]] = defaultdict(list)
    failed: dict[tuple, int] = defaultdict(int)
    for r in records:
        key = (r["suite"], r["policy"], r["condition"].rsplit("/", 1)[1])
        score[key].append(r["score_v2"])
        failed[key] += int(r["failed"] or not r["flyable"])
    for suite in args.suites:
        print(f"\n{suite}, validation seeds 0-{args.seeds - 1}: mean score_v2 [rad] (failed or unflyable)\n")
        print("| variant | rigid | non-rigid |\n|---|---|---|")
        for p in policies:
            cells = [f"{np.mean(score[(suite, p.name, m)]):.3f} ({failed[(suite, p.name, m)]})" for m in ("rigid", "nonrigid")]
            print(f"| {p.name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
