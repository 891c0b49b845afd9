"""The privileged reference's gains and load relief, chosen on validation seeds (part 6 of README.md).

    python -m experiments.protocol_v2_design.privileged_sweep --seeds 20

Flies ``privileged`` (lvgym/baselines/privileged.py) at each attitude-loop bandwidth of ``--bandwidths``
(damping equal to it, as :data:`~lvgym.baselines.privileged.GAINS` has them) with each load relief of
``--reliefs`` (onset and full share of the q-alpha limit; ``off``: none) and each preview of ``--previews``
(control periods ahead at which it reads the aerodynamic moment) on protocol v2's SMILE suites,
rigid and non-rigid, validation seeds ``0 .. seeds - 1``, and prints per flight model the mean ``score_v2``
of every variant on every suite and over the three, with its failures. A study: it flies no test seed.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lvgym.benchmark import evaluate, get_suite
from lvgym.benchmark.runner import PolicySpec
from lvgym.commandline import arg, parse
from lvgym.errors import ConfigError

SUITES = ("smile-v2", "smile-v2-maxq-gust", "smile-v2-faults")
FACTORY = "lvgym.baselines.privileged:privileged"
OFF = (10.0, 11.0)          # onset beyond the limit: no relief (a flight above the limit has failed)


def _variants(bandwidths: list[float], reliefs: list[str], previews: list[int]) -> list[PolicySpec]:
    out = []
    for w, r, k in ((w, r, k) for w in bandwidths for r in reliefs for k in previews):
        try:
            relief = OFF if r == "off" else tuple(float(x) for x in r.split(","))
        except ValueError:
            relief = ()
        if len(relief) != 2:
            raise ConfigError("reliefs", r, "off, or ONSET,FULL: two shares of the q-alpha limit")
        out.append(PolicySpec(f"priv-w{w:g}-r{r.replace(',', '-')}-p{k}", FACTORY,
                              (("bandwidth_radps", w), ("damping", w), ("relief", relief), ("preview_periods", k))))
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.privileged_sweep --help``)."""

    seeds: int = arg(20, lo=1, hi=10_000)
    """validation seeds per variant and condition"""
    bandwidths: list[float] = arg(default_factory=lambda: [1.0, 1.5, 2.0], lo=0.0, lo_open=True, hi=100.0,
                                  metavar="RADPS")
    """attitude-loop bandwidths [rad/s] (the damping equal to each)"""
    reliefs: list[str] = arg(default_factory=lambda: ["off", "0.5,0.9", "0.3,0.7"], metavar="ONSET,FULL")
    """load reliefs: onset and full share of the q-alpha limit, or off"""
    suites: list[str] = arg(default_factory=lambda: list(SUITES), metavar="SUITE")
    """v2 suites to fly (default: the three SMILE ones)"""
    previews: list[int] = arg(default_factory=lambda: [0], lo=0, hi=10, metavar="PERIODS")
    """how many control periods ahead the law reads the aerodynamic moment (0: as it acts)"""


def main(argv: Sequence[str] | None = None) -> None:
    args = parse(Args, argv, "python -m experiments.protocol_v2_design.privileged_sweep", __doc__)
    specs = _variants(args.bandwidths, args.reliefs, args.previews)
    suites = args.suites
    records = evaluate(specs, [get_suite(s) for s in suites], args.seeds, "validation", progress=False)
    score: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    failed: dict[tuple[str, str, str], int] = defaultdict(int)
    for r in records:
        key = (r["condition"].rsplit("/", 1)[1], r["policy"], r["suite"])
        score[key].append(r["score_v2"])
        failed[key] += int(r["failed"] or not r["flyable"])
    for model in ("rigid", "nonrigid"):
        print(f"\n{model}, validation seeds 0-{args.seeds - 1}: mean score_v2 [rad] (failed or unflyable)\n")
        print("| variant | " + " | ".join(suites) + " | mean of the suites |")
        print("|---|" + "---:|" * (len(suites) + 1))
        for spec in specs:
            cells = [f"{np.mean(score[(model, spec.name, s)]):.3f} ({failed[(model, spec.name, s)]})" for s in suites]
            mean = np.mean([np.mean(score[(model, spec.name, s)]) for s in suites])
            print(f"| {spec.name} | " + " | ".join(cells) + f" | {mean:.3f} |")


if __name__ == "__main__":
    main()
