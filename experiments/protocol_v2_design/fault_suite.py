"""What each in-flight fault of the env does to each design: smile-v1 with one kind of fault per condition.

    python -m experiments.protocol_v2_design.fault_suite --seeds 20                      # every kind, both models
    python -m experiments.protocol_v2_design.fault_suite --kinds stuck thrust --models nonrigid --seeds 10

Each condition is one of ``smile-v1``'s (every v1 dispersion, its wind) with ``fault`` added to what each reset
draws (:mod:`lvgym.envs.faults`) and the kinds narrowed to one (``none``: v1 itself), the onset drawn over
``--onset`` (default 5-40 s: through the boost and max q). It is flown by the benchmark's runner under the
label ``v2-draft`` (so the records carry protocol v2's flyability fields and ``score_v2``), on validation
seeds only. The table gives, per model, kind and policy: failures and unflyable flights of the seeds, and the
mean ``score_v2`` with its 95 % bootstrap interval; failed or unflyable flights are charged as v1 charges a
failure.
"""

from __future__ import annotations

import csv
import sys
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.benchmark.metrics import normalise, summarize
from lvgym.benchmark.runner import PolicySpec, evaluate
from lvgym.benchmark.suites import SEED_SETS, Suite, get_suite
from lvgym.commandline import arg, command_name, parse
from lvgym.envs.faults import FAULT_NAMES
from lvgym.parallel import EXECUTORS, exit_on_sigterm

__all__ = ["fault_suites", "fault_table"]

PROG = "python -m experiments.protocol_v2_design.fault_suite"
DEFAULT_POLICIES = ["zero", "lqg", "lqg-front", "lqg-aw", "gs-pid-flex-quiet", "aac-quiet", "ppo-res-lqg"]
LABEL = "v2-draft"


def fault_suites(kinds: Sequence[str], onset: tuple[float, float] = (5.0, 40.0), models: Sequence[str] | None = None,
                 base: str = "smile-v1") -> list[Suite]:
    """One suite per kind (``none``: ``base`` itself), each ``base``'s conditions (``models``: all when None)
    with the fault drawn, under the label ``v2-draft``."""
    out = []
    for kind in kinds:
        s = get_suite(base)
        conds = []
        for c in s.conditions:
            if models is not None and c.model not in models:
                continue
            if kind != "none":
                c = replace(c, randomize=tuple(sorted((*c.randomize, "fault")))).with_options(
                    fault_kinds=(kind,), fault_onset_s=tuple(onset))
            conds.append(replace(c, name=f"{base}+{kind}/{c.model}", group=f"{base}+{kind}"))
        out.append(replace(s, name=f"{base}+{kind}", conditions=tuple(conds), version=LABEL))
    return out


def fault_table(records: Sequence[dict[str, Any]], reference: str = "lqg") -> str:
    """Markdown: one row per model and policy, one column per kind: ``failed / unflyable of n, score_v2 mean
    [95 % interval]`` and, where ``zero`` and ``reference`` flew too, the normalised score_v2 (zero 0,
    ``reference`` 1: :func:`lvgym.benchmark.metrics.normalise`)."""
    rows = summarize(records)
    kinds = list(dict.fromkeys(r["suite"] for r in rows))
    normalise(rows, records, {k: reference for k in kinds})
    cells: dict[tuple[str, str], dict[str, str]] = {}
    for r in rows:
        text = (f"{round(r['failure_rate'] * r['n'])} / {round(r['unflyable_rate'] * r['n'])} of {r['n']}, "
                f"{r['score_v2_mean']:.2f} [{r['score_v2_ci_low']:.2f}, {r['score_v2_ci_high']:.2f}]")
        if "score_v2_norm" in r:
            text += f"; {r['score_v2_norm']:.2f} [{r['score_v2_norm_ci_low']:.2f}, {r['score_v2_norm_ci_high']:.2f}]"
        cells.setdefault((r["model"], r["policy"]), {})[r["suite"]] = text
    head = "| model | policy | " + " | ".join(k.split("+", 1)[1] for k in kinds) + " |"
    lines = [head, "|---|---|" + "---|" * len(kinds)]
    for (model, policy), by_kind in cells.items():
        lines.append(f"| {model} | {policy} | " + " | ".join(by_kind.get(k, "") for k in kinds) + " |")
    return "\n".join(lines) + ("\n\nEach cell: failed / unflyable of the seeds, mean score_v2 [rad] and its 95 % "
                               f"bootstrap interval; then score_v2 normalised (zero 0, {reference} 1; higher is "
                               "better) and its paired bootstrap interval.\n")


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.protocol_v2_design.fault_suite --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    """registered names, SB3 .zip files or train.py run folders"""
    kinds: list[str] = arg(default_factory=lambda: ["none", *FAULT_NAMES], choices=("none", *FAULT_NAMES),
                           metavar="KIND")
    """the kinds of fault, one condition each (none: smile-v1 itself)"""
    onset: list[float] = arg(default_factory=lambda: [5.0, 40.0], metavar="S")
    """the window the onset is drawn in [s] (two numbers)"""
    seeds: int = arg(20, lo=1, hi=10_000)
    """validation seeds per policy and condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """validation (a design study never flies the test seeds)"""
    models: list[str] | None = arg(None, metavar="MODEL")
    """the flight models (default: rigid and nonrigid)"""
    reference: str = "lqg"
    """the policy at 1 of the normalised score (the zero policy is at 0)"""
    csv_out: Path | None = None
    """write every record to this CSV file"""
    executor: str = arg("local", choices=EXECUTORS)
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
    if len(a.onset) != 2 or not 0.0 <= a.onset[0] <= a.onset[1]:
        raise SystemExit(f"{command_name(PROG)}: --onset {a.onset}: two times 0 <= low <= high [s]")
    specs: list[PolicySpec] = [resolve_policy(p, command_name(PROG)) for p in a.policies]
    suites = fault_suites(a.kinds, (a.onset[0], a.onset[1]), a.models)
    records = evaluate(specs, suites, a.seeds, a.seed_set, a.executor, a.workers, a.progress)
    if a.csv_out is not None:
        a.csv_out.parent.mkdir(parents=True, exist_ok=True)
        keys = list(dict.fromkeys(k for r in records for k in r))
        with a.csv_out.open("w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=keys)
            w.writeheader()
            w.writerows(records)
    sys.stdout.write(fault_table(records, a.reference))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
