"""One kind of fault at a time: policies flown on **validation** seeds of the fault suite's condition with every
flight's fault drawn from one kind (``fault_kinds=(kind,)``; onset, size, axis and sign as the suite draws
them), so that a failure that strikes one flight in a few hundred of the suite can be counted and studied
without the test seeds.

    python -m experiments.fault_id.one_kind --kind gyro_bias --first 100 --last 1100 --policies inversion-id \\
        inversion-id-avg6-lead3=experiments.fault_id.inversion:shipped_avg6_lead3

Prints per policy the mean ``score_v2``, the median commanded-rate RMS and every failed or unflyable flight
(seed, fault, why). The flights are the rows of one batched env per 100 seeds (the benchmark's
:func:`lvgym.benchmark.runner.fly_block`: each row its single env's flight, to the bit).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lvgym.commandline import arg, parse
from lvgym.envs.faults import FAULT_NAMES

from .train import condition, lost


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.one_kind --help``)."""

    kind: str = arg("gyro_bias", choices=FAULT_NAMES)
    """the kind of fault every flight draws"""
    policies: list[str] = arg(default_factory=lambda: ["inversion-id"], metavar="POLICY")
    """policies as evaluate.py takes them (a registered name, ``label=module:factory``)"""
    model: str = arg("nonrigid", choices=("rigid", "nonrigid"))
    """the flight model"""
    first: int = arg(0, lo=0, hi=9_999)
    """the first validation seed"""
    last: int = arg(100, lo=1, hi=10_000)
    """one past the last validation seed (validation seeds end at 9,999: the test seeds are never flown)"""


def main(argv: Sequence[str] | None = None) -> dict[str, list[dict]]:
    import lvgym.cli.policies  # noqa: F401  (registers the classical designs)
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import fly_block
    from lvgym.errors import ConfigError

    a = parse(Args, argv, "python -m experiments.fault_id.one_kind", __doc__)
    if a.last <= a.first:
        raise ConfigError("--last", a.last, f"above --first ({a.first})")
    c = condition(a.model, fault_kinds=(a.kind,))
    seeds = list(range(a.first, a.last))
    out = {}
    for text in a.policies:
        spec, t0 = resolve_policy(text, "python -m experiments.fault_id.one_kind"), time.time()
        records = [r for k in range(0, len(seeds), 100)
                   for r in fly_block(c, [(spec, s) for s in seeds[k:k + 100]], flyability=True)]
        bad = [(s, r["fault"], r["failure_reason"] or "unflyable") for s, r in zip(seeds, records) if lost(r)]
        print(f"{spec.name} {a.model} {a.kind}, seeds {a.first}-{a.last - 1}: mean score_v2 "
              f"{np.mean([r['score_v2'] for r in records]):.3f}, commanded-rate RMS (median) "
              f"{np.median([r['cmd_rate_rms'] for r in records]):.3f}, failed or unflyable {len(bad)} "
              f"({time.time() - t0:.0f} s)", flush=True)
        for seed, fault, why in bad:
            print(f"  seed {seed}: {fault}, {why}", flush=True)
        out[spec.name] = records
    return out


if __name__ == "__main__":
    main()
