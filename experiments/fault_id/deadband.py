"""The students' correction shrunk by a dead band, on validation seeds: on the test seeds the estimate's noise
cost 2-3 % (median) on the flights without a thrust-direction step, where it gained 7-8 % on those with one.

    python -m experiments.fault_id.deadband --deadbands 0 0.03 0.06 0.1

Prints per training seed and dead band (over the gimbal limit; :func:`.estimator.corrected`) the mean
``score_v2`` and the failed or unflyable flights of validation seeds ``0 .. --validation - 1``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from lvgym.commandline import arg, parse

from .estimator import RESULTS, load
from .train import validate


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.deadband --help``)."""

    deadbands: list[float] = arg(default_factory=lambda: [0.0, 0.03, 0.06, 0.1], lo=0.0, hi=1.0)
    """dead bands to fly [over the gimbal limit]"""
    seeds: list[int] = arg(default_factory=lambda: [0, 1, 2], lo=0, hi=99)
    """training seeds (results/fault_id/estimator-s<seed>.pt)"""
    validation: int = arg(100, lo=1, hi=1000)
    """validation seeds per flight model"""


def main(argv: Sequence[str] | None = None) -> None:
    import torch

    a = parse(Args, argv, "python -m experiments.fault_id.deadband", __doc__)
    torch.set_num_threads(1)
    print("| training seed | dead band | rigid | non-rigid |\n|---|---|---|---|")
    for seed in a.seeds:
        est = load(RESULTS / f"estimator-s{seed}.pt")
        for d in a.deadbands:
            v = validate(est, a.validation, d)
            print(f"| {seed} | {d:g} | " + " | ".join(f"{s:.3f} ({b})" for s, b in v.values()) + " |", flush=True)


if __name__ == "__main__":
    main()
