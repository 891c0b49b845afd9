"""The error budget of a policy: how much of its score each source of error causes.

    python -m experiments.error_budget.budget                                  # lqg and ppo-res-lqg, smile-v1 non-rigid
    python -m experiments.error_budget.budget --policies gs-pid-flex --models rigid nonrigid --episodes 20

A suite condition's errors come from its wind and from its dispersions. Its sources (:func:`sources`):
the wind tier's parts (``turbulence``: the steady wind and the Dryden turbulence of the ``turbulence``
tier; ``gust``: the random 1-cosine gust; a tier without parts listed in :data:`WIND_PARTS` is one
source, ``wind``), each disturbance dispersion of :data:`DISTURBANCES` (``thrust_misalignment``,
``sensor_noise``: the gyro bias, its drift, the angle random walk and the accelerometer noise) and
``plant``: every other dispersion (mass, aerodynamics, slosh, bending, servo, IMU station), which moves
the plant without pushing it. The condition is flown (:func:`variants`) as it is (``nominal``), with
nothing (``none``: no wind, nothing dispersed), and for every source once without it
(``without <source>``) and once with it alone (``only <source>``). The errors do not add: the score is
an integral of an absolute rate error, so two sources partly cancel and partly add, and removing one
is not the same as keeping it alone. Hence both columns: ``share removed`` is the paired mean of
``nominal - without`` over the seeds (with its bootstrap interval) over the nominal mean, ``share
alone`` is ``only`` over ``nominal``. The variants of a seed are not the same draws with a source taken out: the
env draws a dispersion from the seed's generator only when it is on, and the wind after the
dispersions (each part of the wind from its own seed, taken in turn), so a variant flies other
realisations of the sources it keeps. The seeds pair the variants loosely; a share is a difference of
means over the seeds, and its interval says how well the seeds pin it down.

Seeds: the validation seeds by default (a budget is a diagnosis; ``--seed-set test`` for a report
after the fact). From Python: :func:`variants`, :func:`budget_rows` and :func:`run_budget`.
"""

from __future__ import annotations

import datetime as dt
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies the command line names)
from lvgym.commandline import arg, command_name, parse
from lvgym.cli.flights import FlightArgs, resolve_flights
from lvgym.parallel import exit_on_sigterm

from lvgym.benchmark.results import atomic_write_text, csv_text, json_text
from lvgym.benchmark.runner import PolicySpec, evaluate
from lvgym.benchmark.scoring import PHASES
from lvgym.benchmark.stats import bootstrap_ci, paired
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition, Suite

__all__ = ["DISTURBANCES", "PHASES", "WIND_PARTS", "budget_rows", "budget_table", "run_budget", "sources",
           "variants"]

#: the parts of the wind tiers that have more than one (the others are one source, ``wind``)
WIND_PARTS: dict[str, tuple[str, ...]] = {"turbulence_gust": ("turbulence", "gust"), "turbulence": ("turbulence",),
                                          "random_gust": ("gust",), "none": ()}
_PART_TIERS = {frozenset(parts): tier for tier, parts in WIND_PARTS.items()}
#: dispersions that push the vehicle (each its own source); the others move the plant (one source, ``plant``)
DISTURBANCES = ("thrust_misalignment", "sensor_noise")
#: ``randomize`` names that are not a source: ``wind`` only says where the wind's draws come from
NOT_SOURCES = ("wind",)
DEFAULT_POLICIES = ["lqg", "ppo-res-lqg"]
DEFAULT_SUITE = "smile-v1"
DEFAULT_EPISODES = 10
PROG = "python -m experiments.error_budget.budget"


def _wind_parts(tier: str) -> tuple[str, ...]:
    return WIND_PARTS.get(tier, ("wind",))


def sources(cond: Condition) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
    """The sources of error of ``cond``: name -> (wind parts, ``randomize`` names) it consists of."""
    out: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {p: ((p,), ()) for p in _wind_parts(cond.wind)}
    out.update({d: ((), (d,)) for d in DISTURBANCES if d in cond.randomize})
    plant = tuple(r for r in cond.randomize if r not in DISTURBANCES and r not in NOT_SOURCES)
    if plant:
        out["plant"] = ((), plant)
    return out


def _with(cond: Condition, label: str, parts: Sequence[str], randomize: Sequence[str]) -> Condition:
    """``cond`` flown with only the wind ``parts`` and the ``randomize`` names given (``wind`` kept)."""
    all_parts = _wind_parts(cond.wind)
    if set(parts) == set(all_parts):
        tier = cond.wind
    elif not parts:
        tier = "none"
    else:
        tier = _PART_TIERS[frozenset(parts)]
    keep = tuple(r for r in cond.randomize if r in randomize or r in NOT_SOURCES)
    return replace(cond, name=f"{cond.name}|{label}", wind=tier, randomize=keep)


def variants(cond: Condition) -> dict[str, Condition]:
    """``nominal``, ``none`` and ``without <source>`` / ``only <source>`` for every source of ``cond``."""
    src = sources(cond)
    parts = _wind_parts(cond.wind)
    out = {"nominal": replace(cond, name=f"{cond.name}|nominal"), "none": _with(cond, "none", (), ())}
    for name, (p, r) in src.items():
        out[f"without {name}"] = _with(cond, f"without {name}", [x for x in parts if x not in p],
                                       [x for x in cond.randomize if x not in r])
        out[f"only {name}"] = _with(cond, f"only {name}", p, r)
    return out


def _phase_means(records: list[dict[str, Any]]) -> dict[str, float]:
    return {p: float(np.mean([r[f"rate_error_{p}_rad"] for r in records])) for p in PHASES}


def budget_rows(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per (policy, condition, variant) of the episode ``records`` of :func:`run_budget` (each with
    ``policy``, ``base``, ``variant``, ``seed``, ``score``, ``failed`` and the per-phase rate errors), in
    their order: the mean score with its bootstrap interval, the phase means, the failures, and the shares
    of the nominal mean (module docstring)."""
    groups: dict[tuple[str, str], dict[str, list[dict[str, Any]]]] = {}
    for r in records:
        groups.setdefault((r["policy"], r["base"]), {}).setdefault(r["variant"], []).append(r)
    rows: list[dict[str, Any]] = []
    for (policy, base), by_variant in groups.items():
        if "nominal" not in by_variant:
            raise ValueError(f"policy {policy!r} on {base!r}: no nominal episodes to share against")
        nominal = {r["seed"]: r["score"] for r in by_variant["nominal"]}
        nominal_mean = float(np.mean(list(nominal.values())))
        for variant, recs in by_variant.items():
            scores = [r["score"] for r in recs]
            mean = float(np.mean(scores))
            lo, hi = bootstrap_ci(scores)
            row = {"policy": policy, "condition": base, "variant": variant, "episodes": len(recs),
                   "score": mean, "score_low": lo, "score_high": hi, "failures": int(sum(r["failed"] for r in recs)),
                   **{f"{p}_rad": v for p, v in _phase_means(recs).items()},
                   "share_removed": np.nan, "share_removed_low": np.nan, "share_removed_high": np.nan,
                   "share_alone": np.nan}
            if variant.startswith("without "):
                seeds = [r["seed"] for r in recs if r["seed"] in nominal]
                mine = {r["seed"]: r["score"] for r in recs}
                pr = paired([nominal[s] for s in seeds], [mine[s] for s in seeds])
                row.update(share_removed=pr.mean_diff / nominal_mean, share_removed_low=pr.ci_low / nominal_mean,
                           share_removed_high=pr.ci_high / nominal_mean)
            elif variant.startswith("only "):
                row["share_alone"] = mean / nominal_mean
            rows.append(row)
    return rows


def _pct(x: float) -> str:
    return "" if not np.isfinite(x) else f"{100 * x:.0f} %"


def budget_table(rows: Sequence[dict[str, Any]]) -> str:
    """A Markdown table of :func:`budget_rows`."""
    head = ("| policy | condition | variant | score [rad] | boost | max q | coast | upper | failures | "
            "share removed [95 % CI] | share alone |")
    lines = [head, "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        removed = "" if not np.isfinite(r["share_removed"]) else (
            f"{_pct(r['share_removed'])} [{_pct(r['share_removed_low'])}, {_pct(r['share_removed_high'])}]")
        lines.append(f"| {r['policy']} | {r['condition']} | {r['variant']} | {r['score']:.4f} "
                     f"[{r['score_low']:.4f}, {r['score_high']:.4f}] | {r['boost_rad']:.4f} | {r['max_q_rad']:.4f} | "
                     f"{r['coast_rad']:.4f} | {r['upper_rad']:.4f} | {r['failures']}/{r['episodes']} | {removed} | "
                     f"{_pct(r['share_alone'])} |")
    return "\n".join(lines)


def run_budget(policies: Sequence[PolicySpec], conditions: Sequence[Condition], seeds_of: Suite, episodes: int,
               seed_set: str = "validation", executor: str = "local", workers: int | None = None,
               progress: bool = True) -> list[dict[str, Any]]:
    """Fly every variant of every condition with every policy on the first ``episodes`` seeds of
    ``seed_set`` of the suite ``seeds_of``; the episode records, each labelled with ``base`` (the
    condition's name) and ``variant``."""
    labels: dict[str, tuple[str, str]] = {}
    conds: list[Condition] = []
    for cond in conditions:
        for label, v in variants(cond).items():
            labels[v.name] = (cond.name, label)
            conds.append(v)
    suite = replace(seeds_of, name=f"{seeds_of.name}-budget", conditions=tuple(conds),
                    version=f"{seeds_of.version}+budget")
    records = evaluate(policies, [suite], episodes, seed_set, executor, workers, progress)
    for r in records:
        r["base"], r["variant"] = labels[r["condition"]]
    return records


@dataclass
class Args(FlightArgs):
    """Command-line arguments (``python -m experiments.error_budget.budget --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    suite: str = arg(DEFAULT_SUITE, metavar="SUITE", choices=lambda: sorted(SUITES))
    out: str = "results/budget"
    models: list[str] = arg(default_factory=lambda: ["nonrigid"], metavar="MODEL")
    """the suite's conditions of these flight models"""
    episodes: int = arg(DEFAULT_EPISODES, lo=2, hi=10_000)
    """seeds per variant"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """validation (a diagnosis) or test"""


def parse_args(argv: list[str] | None = None) -> Args:
    """The command line, every value checked before any worker starts."""
    return parse(Args, argv, PROG, __doc__, epilog=True)


def main(argv: list[str] | None = None) -> list[dict[str, Any]]:
    """Fly, print the table, write ``episodes.csv``, ``budget.csv`` and ``budget.json``; returns the rows."""
    args = parse_args(argv)
    exit_on_sigterm()
    policies, suite, conds = resolve_flights(command_name(PROG), args.policies, args.suite, args.models,
                                             mission_time_s=args.mission_time_s)
    t0 = time.perf_counter()
    records = run_budget(policies, conds, suite, args.episodes, args.seed_set, args.executor, args.workers,
                         args.progress)
    wall = time.perf_counter() - t0
    rows = budget_rows(records)
    meta = {"suite": suite.name, "version": suite.version, "seed_set": args.seed_set, "episodes": len(records),
            "args": asdict(args), "wall_time_s": round(wall, 3),
            "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "episodes.csv", csv_text(records))
    atomic_write_text(out / "budget.csv", csv_text(rows))
    atomic_write_text(out / "budget.json", json_text({"meta": meta, "rows": rows}))
    print(budget_table(rows))
    print(f"{len(records)} episodes in {wall:.1f} s ({args.executor}); results in {out}/: episodes.csv, "
          "budget.csv, budget.json", file=sys.stderr)
    return rows


if __name__ == "__main__":            # run as the imported module, so that the workers find its tasks by name
    from experiments.error_budget.budget import main as _main

    _main()
