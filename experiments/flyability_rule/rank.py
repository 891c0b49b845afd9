"""The shipped policies under protocol v2's flyability rule (lvgym.benchmark.flyability): the measures, who is
unflyable, and the ranks of v1 (failure rate, score) against v2's (failed or unflyable, score_v2).

    python -m experiments.flyability_rule.rank --seeds 3 --seed-set validation --executor serial
    python -m experiments.flyability_rule.rank --policies lqg gs-pid-flex --models nonrigid --seeds 2

The suite (``smile-v1`` by default) is flown by the benchmark's own runner (:func:`lvgym.benchmark.evaluate`,
the conditions' seeds as the rows of their batched env) under the version label ``v2-draft``, so that every
record carries the v2 fields; nothing else of the suite changes. The table gives, per condition and policy,
the means over the seeds (the range of ``cmd_rate_rms`` and the largest ``cmd_rate_peak`` in brackets).
"""

from __future__ import annotations

import csv
import sys
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.flyability import RMS_FRACTION, WINDOW_FRACTION, WINDOW_S
from lvgym.benchmark.metrics import summarize
from lvgym.benchmark.runner import PolicySpec, evaluate
from lvgym.benchmark.suites import SEED_SETS, SUITES, get_suite
from lvgym.commandline import arg, command_name, parse
from lvgym.parallel import EXECUTORS, exit_on_sigterm

__all__ = ["V2_LABEL", "fly", "rank_table"]

PROG = "python -m experiments.flyability_rule.rank"
DEFAULT_POLICIES = ["zero", "gs-pid", "gs-pid-flex", "lqg", "lqg-front", "aac", "ppo-res-lqg"]
#: the version label the suite is flown under (any v2 label turns the flyability fields on)
V2_LABEL = "v2-draft"
V2_KEYS = ("flyable", "unflyable_at_s", "score_v2", "cmd_rate_rms", "cmd_rate_peak", "cmd_reversal_hz")


def fly(policies: Sequence[PolicySpec], suite: str = "smile-v1", seeds: int = 3, seed_set: str = "validation",
        models: Sequence[str] | None = None, executor: str = "serial", workers: int | None = None,
        progress: bool = True, **options: Any) -> list[dict[str, Any]]:
    """The episode records (with the v2 fields) of ``policies`` on ``suite``'s conditions (``models``: all when
    None), the first ``seeds`` seeds of ``seed_set``; ``options``: env keywords for every condition (e.g. a
    short ``mission_time_s``)."""
    s = get_suite(suite).with_options(**options) if options else get_suite(suite)
    conds = tuple(c for c in s.conditions if models is None or c.model in models)
    s = replace(s, conditions=conds, version=V2_LABEL + ("+override" if "+" in s.version else ""))
    return evaluate(policies, [s], seeds, seed_set, executor, workers, progress)


def rank_table(records: Sequence[dict[str, Any]]) -> str:
    """A Markdown table per condition: the v2 measures (means over the seeds), the failures and unflyable
    flights, the mean score and score_v2, and the ranks of v1 (the records without their v2 fields) and v2."""
    v2 = {(r["condition"], r["policy"]): r for r in summarize(records)}
    v1 = {(r["condition"], r["policy"]): r for r in summarize([{k: x for k, x in rec.items() if k not in V2_KEYS}
                                                              for rec in records])}
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in records:
        groups.setdefault((r["condition"], r["policy"]), []).append(r)
    lines = ["| condition | policy | seeds | commanded rate RMS [% of limit] | 2 s peak [%] | reversals [1/s] "
             "| failed | unflyable | score [rad] | score_v2 [rad] | v1 rank | v2 rank |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for (cond, pol), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], v2[kv[0]]["rank"])):
        c = [100 * r["cmd_rate_rms"] for r in rs]
        p = [100 * r["cmd_rate_peak"] for r in rs]
        lines.append(f"| {cond} | {pol} | {len(rs)} | {np.mean(c):.1f} ({min(c):.1f}-{max(c):.1f}) "
                     f"| {np.mean(p):.1f} ({max(p):.1f}) | {np.mean([r['cmd_reversal_hz'] for r in rs]):.1f} "
                     f"| {sum(bool(r['failed']) for r in rs)} | {sum(not r['flyable'] for r in rs)} "
                     f"| {np.mean([r['score'] for r in rs]):.3f} | {np.mean([r['score_v2'] for r in rs]):.3f} "
                     f"| {v1[(cond, pol)]['rank']} | {v2[(cond, pol)]['rank']} |")
    rule = (f"Rule: unflyable when the commanded rate's RMS exceeds {100 * RMS_FRACTION:.1f} % of the rate limit "
            f"over the controlled flight, or {100 * WINDOW_FRACTION:.0f} % over any {WINDOW_S:g} s window.")
    return "\n".join(lines) + "\n\n" + rule + "\n"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.flyability_rule.rank --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(3, lo=1, hi=10_000)
    """seeds per policy and condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """validation (tuning the rule) or test"""
    models: list[str] | None = arg(None, metavar="MODEL")
    """the conditions' flight models (default: all of the suite)"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True)
    """a shorter mission [s] (default: the suite's)"""
    csv_out: Path | None = None
    """write every record to this CSV file"""
    executor: str = arg("serial", choices=EXECUTORS)
    """serial, local (process pool) or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000)
    """parallel workers (default: the CPUs available)"""
    progress: bool = True
    """show a progress bar"""


def main(argv: Sequence[str] | None = None) -> int:
    """Fly, print the table (and write the CSV)."""
    from lvgym.benchmark.registry import resolve_policy

    exit_on_sigterm()
    a = parse(Args, argv, PROG, __doc__)
    specs = [resolve_policy(p, command_name(PROG)) for p in a.policies]
    options = {} if a.mission_time_s is None else {"mission_time_s": a.mission_time_s}
    records = fly(specs, a.suite, a.seeds, a.seed_set, a.models, a.executor, a.workers, a.progress, **options)
    if a.csv_out is not None:
        a.csv_out.parent.mkdir(parents=True, exist_ok=True)
        with a.csv_out.open("w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=list(records[0]))
            w.writeheader()
            w.writerows(records)
    sys.stdout.write(rank_table(records))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
