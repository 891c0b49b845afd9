"""Compare TVC policies on the frozen benchmark protocol (``lvgym.benchmark``).

    lvgym evaluate                                       # protocol v2: every suite, each with its policies
    lvgym evaluate --suites smile-v1 --policies zero gs-pid lqg ppo-res-lqg   # v1's main suite
    lvgym evaluate --vehicle my_rocket.yaml --policies zero my_policy.py:make    # smile-v2's conditions, your vehicle
    lvgym evaluate --policies zero pid gs-pid runs/ppo_smile.zip --suites smile-windy --episodes 50   # v0
    lvgym evaluate --executor ray --workers 4            # Ray (pip install 'lvgym[ray]'): a local Ray
    RAY_ADDRESS=auto lvgym evaluate --executor ray        # ... or the running cluster (``ray start``)

(``python evaluate.py`` in a checkout is the same command.) Policies are names of :data:`POLICIES`
(``zero``, ``pid``, ``gs-pid``: our rigid tuning; ``pid-thesis``, ``gs-pid-thesis``: the thesis's gains
and Table 6.10; ``gs-pid-flex``, ``lqg``, ``aac``: designed for the flexible vehicle; ``lqg-front``:
``lqg`` traded to the learned policy's margins (``experiments.lqg_headroom.headroom``); ``ppo``: the
learned policy shipped for v0, ``ppo-res-lqg``: the one shipped for v1) or paths of saved
stable-baselines3 models (``.zip``; an optional ``<stem>_vecnormalize.pkl`` next to it normalises the
observations) or of ``train.py`` run folders, or your own policy: ``module:factory`` or
``path/to/my_policy.py:factory`` (a function of the env, or of nothing, that returns an object with
``name``, ``reset()`` and ``act(observation, info)``; the file is loaded by path in every worker and needs
no ``__main__`` guard); ``label=...`` in front names any of them in the tables. Without ``--policies`` each
suite flies the policies its protocol reports on it (``Suite.policies``; :data:`DEFAULT_POLICIES` for a v0
or v1 suite); with them, a suite that reports policies (protocol v2's) flies its reported classical designs
and its privileged reference beside them, so that the headline names its best classical design and gives
each of yours a row with its room against the reference (``--only``: the given policies alone; with
``--vehicle`` too, since the shipped designs are made for the shipped vehicles). Suites are names of
``lvgym.benchmark.SUITES``; the default is protocol v2's five (:data:`DEFAULT_SUITES`), or its main suite
``smile-v2`` when ``--policies`` is given. Episodes
run on a local process pool by default; the Markdown table is printed, and CSV, JSON, the table and PNG
plots go to ``--out`` (each file written atomically: an interrupted run leaves no half-written file).
``--seed-set validation`` evaluates on the training seeds; reported numbers use the ``test`` seeds (the
default), and every run on them is logged in the ledger of test flights (``lvgym ledger``; ``--purpose``
says why).

The tables (every mean with its 95 % bootstrap interval over the seeds, lower is better): for protocol v2,
first the headline over every suite (the best classical design the suite reports, the best learned policy
and the privileged ``score_v2`` and the room between them, never naming a policy failed or unflyable on
more than half its flights, :mod:`lvgym.benchmark.headline`) and a row for each other policy flown (yours)
with its room against the reference; then per suite:
  1. summary: condition x policy, ranked by failure rate, then by score (the rate error plus, for a failed
     episode, the env's failure penalty for the mission left), with the rate error, CVaR10, max rate,
     effort, max alpha and q-alpha;
  2. rate error per flight phase: policy x model x (boost, max q, coast, upper stage, total);
  3. rigid-to-non-rigid degradation: failure rates rigid and non-rigid, score and rate error of both
     with their ratio and paired difference (a failed episode is charged by its score, so the score's
     degradation counts the failures);
  4. paired comparison: each policy against the reference (``--reference``, else the best-ranked
     policy of the condition) on the same seeds: mean difference of the score with its interval,
     wins/ties/losses, Wilcoxon and t p-values, the IQM and the probability of improvement
     (:mod:`lvgym.benchmark.stats`);
  5. agents over training runs (policies labelled ``<agent>-s<seed>``): the IQM over the runs.
docs/metrics.md defines every metric.
"""

from __future__ import annotations

import datetime as dt
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from lvgym.benchmark import (DEFAULT_SUITE, EXECUTORS, SEED_SETS, SUITES, PolicySpec, Suite, compare,
                             degradation, evaluate, get_suite, markdown_table, normalise, protocol_metric,
                             run_groups, summarize, write_results)
from lvgym.benchmark.decide import by_fault
from lvgym.benchmark.family import family_room, family_rows, family_table
from lvgym.benchmark.headline import headline, others, policy_kind
from lvgym.benchmark.suites import SEED_BLOCKS
from lvgym.cli.policies import POLICIES, resolve_policy  # (registers the built-in policies)
from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError
from lvgym.parallel import TaskFailed, exit_on_sigterm

from .flights import check_vehicle
from .ledger import announce

__all__ = ["Args", "BESIDE_KINDS", "DEFAULT_EPISODES", "DEFAULT_POLICIES", "DEFAULT_SUITE", "DEFAULT_SUITES",
           "POLICIES", "main", "parse_args", "resolve_policy", "suite_policies"]

PROG = "evaluate.py"
#: the policies of a suite that names none (v0, v1): no control, the rigid-designed gs-pid (the thesis's
#: question), the designs for the flexible vehicle (gs-pid-flex, lqg, lqg-front, aac) and the shipped learned
#: policy. A v2 suite flies its own (``Suite.policies``)
DEFAULT_POLICIES = ["zero", "gs-pid", "gs-pid-flex", "lqg", "lqg-front", "aac", "ppo-res-lqg"]
#: protocol v2's suites (v1's main suite is ``smile-v1``, v0's ``smile-windy``)
DEFAULT_SUITES = ["smile-v2", "smile-v2-maxq-gust", "smile-v2-faults", "stratos-tvc-v2", "slender-v2"]
#: episodes per condition and policy of the default run
DEFAULT_EPISODES = 50
#: the kinds of a suite's reported policies flown beside a user's ``--policies`` (unless ``--only``)
BESIDE_KINDS = ("classical", "privileged")
#: the longest episode an env takes (``lvgym.envs.TaskSpec.mission_time_s``) [s]
MAX_MISSION_TIME_S = 3600.0


@dataclass
class Args:
    """Command-line arguments (``lvgym evaluate --help``)."""

    policies: list[str] | None = arg(None, metavar="POLICY")
    """registered policy names (zero, pid, gs-pid, gs-pid-flex, lqg, aac, ppo-res-lqg, ...), module:factory,
    path/to/file.py:factory, paths of stable-baselines3 .zip models or train.py run folders (runs/<name>: its
    best model); label=... in front names any of them (default: each suite's own, Suite.policies; given, a v2
    suite's reported classical designs and privileged reference fly beside them unless --only)"""
    only: bool = False
    """fly only the given --policies, not the suite's reported classical designs and privileged reference
    beside them"""
    suites: list[str] | None = arg(None, metavar="SUITE", choices=lambda: sorted(SUITES))
    """suite names of the protocol (default: protocol v2's suites; with --policies, its main suite smile-v2,
    since a policy made for one vehicle flies no other)"""
    episodes: int = arg(DEFAULT_EPISODES, lo=1, hi=10**6, allowed="an integer >= 1")
    """episodes (seeds) per condition and policy"""
    executor: str = arg("local", choices=EXECUTORS)
    """local (process pool), serial or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000, allowed="an integer >= 1")
    """parallel workers (default: the CPUs available)"""
    out: str = "results"
    """folder of the result files"""
    seed_set: str = arg("test", choices=SEED_SETS)
    """test (reported numbers; every such run is logged in the ledger of test flights, lvgym ledger) or
    validation (training and tuning)"""
    first: int = arg(0, lo=0, hi=9_999, allowed="an integer in [0, 9999]")
    """index of the first seed of the seed set flown (default 0: its first --episodes seeds)"""
    block: str | None = arg(None, choices=lambda: sorted(SEED_BLOCKS))
    """fly a named block of seeds in place of --seed-set, --first and --episodes (headline-200: the headline's
    test seeds 12,000-12,199, flown once per selection: docs/test-seeds.md; development-50: 10,000-10,049)"""
    purpose: str | None = arg(None, metavar="TEXT")
    """why the test seeds are flown, for the ledger of test flights (default: the command's name)"""
    reference: str | None = arg(None, metavar="POLICY")
    """policy label every policy is compared with (default: the best-ranked policy of each condition)"""
    vehicle: str | None = arg(None, check=check_vehicle, metavar="NAME|PATH")
    """fly every condition with this vehicle in place of the suite's: a shipped vehicle or the path of a
    vehicle YAML file (docs/vehicles.md), with your own --policies (the shipped designs are made for the
    shipped vehicles); the results are then not protocol numbers (version +override)"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=MAX_MISSION_TIME_S,
                                       allowed=f"a number of seconds in (0, {MAX_MISSION_TIME_S:g}]")
    """shorten every episode to this many seconds (smoke tests only; results are marked '+override')"""
    plots: bool = True
    """write PNG plots"""
    progress: bool = True
    """show a progress bar"""


def parse_args(argv: list[str] | None = None) -> Args:
    """The command line as :class:`Args`, every value checked before any worker starts (an env would
    refuse a bad one only in the worker)."""
    return parse(Args, argv, PROG, __doc__, epilog=True)


def _unique(specs: list[PolicySpec]) -> list[PolicySpec]:
    """Distinct labels: a repeated one gets ``-2``, ``-3``, ..."""
    seen: dict[str, int] = {}
    out = []
    for s in specs:
        seen[s.name] = seen.get(s.name, 0) + 1
        out.append(s if seen[s.name] == 1 else replace(s, name=f"{s.name}-{seen[s.name]}"))
    return out


def suite_policies(suite: Suite, given: list[PolicySpec] | None, only: bool = False,
                   vehicle: str | None = None, prog: str = PROG) -> tuple[list[PolicySpec], list[str]]:
    """The policies ``suite`` flies and the labels of those it reports (``Suite.policies``, each flown as
    registered under its own name). Without ``given``: its reported ones (:data:`DEFAULT_POLICIES` for a v0
    or v1 suite); with them: ``given``, then the reported policies of a kind of :data:`BESIDE_KINDS` whose
    label ``given`` lacks, unless ``only`` or ``vehicle`` (the shipped designs fly the shipped vehicles)."""
    reported = {n: resolve_policy(n, prog) for n in suite.policies}
    if given is None:
        specs = [reported[n] for n in suite.policies] or [resolve_policy(n, prog) for n in DEFAULT_POLICIES]
    else:
        specs = list(given)
        if not (only or vehicle is not None):
            labels = {p.name for p in specs}
            specs += [p for n, p in reported.items() if n not in labels and policy_kind(p) in BESIDE_KINDS]
    specs = _unique(specs)
    return specs, [p.name for p in specs if reported.get(p.name) == p]


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Run the comparison, print the Markdown table, write the result files; returns the results."""
    args = parse_args(argv)
    prog = command_name(PROG)
    exit_on_sigterm()                                # clean up temporary files on kill (SIGTERM)
    if args.vehicle is not None and args.policies is None:
        fail(prog, f"--vehicle {args.vehicle}: give --policies too: the shipped designs are made for the shipped "
                   "vehicles (yours: module:factory or path/to/file.py:factory; zero and privileged fly any vehicle)")
    if args.block is not None:
        b = SEED_BLOCKS[args.block]
        args.seed_set, args.first, args.episodes = b.seed_set, b.first, b.n
    if args.suites is None:
        args.suites = list(DEFAULT_SUITES) if args.policies is None else [DEFAULT_SUITE]
    try:
        suites = [get_suite(n) for n in args.suites]
    except ValueError as exc:
        fail(prog, exc)
    given = [resolve_policy(n, prog) for n in args.policies] if args.policies else None
    chosen = {s.name: suite_policies(s, given, args.only, args.vehicle, prog) for s in suites}
    per_suite = {s: v[0] for s, v in chosen.items()}
    reported = {s: v[1] for s, v in chosen.items() if get_suite(s).policies}
    policies = list({p.name: p for v in per_suite.values() for p in v}.values())
    if args.reference is not None and args.reference not in [p.name for p in policies]:
        raise SystemExit(f"{prog}: --reference = {args.reference!r}: one of the policy labels "
                         f"{[p.name for p in policies]}")
    overrides = {k: v for k, v in (("mission_time_s", args.mission_time_s), ("vehicle", args.vehicle)) if v is not None}
    if overrides:
        suites = [s.with_options(**overrides) for s in suites]
    try:
        seeds = suites[0].seeds(args.seed_set, args.episodes, args.first)
    except ValueError as exc:
        fail(prog, exc)
    announce(prog, seeds, "(reported numbers)")
    t0 = time.perf_counter()
    try:
        records = evaluate(per_suite, suites, args.episodes, args.seed_set, args.executor, args.workers,
                           args.progress, purpose=args.purpose, first=args.first)
    except TaskFailed as exc:                        # a bad value met in a worker: its message, in one line
        if isinstance(exc.__cause__, ConfigError):
            fail(prog, exc)
        raise
    wall = time.perf_counter() - t0
    summary = summarize(records)
    normalise(summary, records, {s.name: s.reference for s in suites if s.reference})
    deg = degradation(summary, "score", records=records) + degradation(summary, "rate_error_rad", records=records)
    comparison: list[dict[str, Any]] = []
    groups: list[dict[str, Any]] = []
    for name in dict.fromkeys(r["suite"] for r in records):     # each suite by its protocol's score
        of_suite = [r for r in records if r["suite"] == name]
        metric = protocol_metric(of_suite)
        comparison += compare(of_suite, [r for r in summary if r["suite"] == name], metric, args.reference)
        groups += run_groups(of_suite, metric)
    kinds = {p.name: policy_kind(p) for p in policies}
    rows = headline(summary, records, kinds, reported)
    beside = others(summary, records, kinds, reported)
    meta = {
        "protocol": ", ".join(sorted({s.version for s in suites})), "seed_set": args.seed_set,
        "episodes": args.episodes, "args": asdict(args),
        "suites": {s.name: {"version": s.version, "description": s.description, "overrides": dict(s.overrides),
                            "first_seed": seeds[0], "last_seed": seeds[-1],
                            "conditions": [c.to_dict() for c in s.conditions]} for s in suites},
        "policies": [{"name": p.name, "factory": p.factory, "kwargs": dict(p.kwargs)} for p in policies],
        "policies_per_suite": {s: [p.name for p in v] for s, v in per_suite.items()},
        "reported_joined": {s.name: s.policies_joined() for s in suites if s.policies},
        "wall_time_s": round(wall, 3), "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
    }
    family = family_rows(records)                   # a family suite: its vehicles gathered
    family_lines = family_table(family, family_room(records, kinds)) if family else []
    faults = by_fault(records, {s.name: s.reference for s in suites if s.reference})
    table = markdown_table(summary, deg, meta, comparison, groups, rows, family_lines, beside, faults)
    paths = write_results(args.out, records, summary, deg, meta, plots=args.plots, comparison=comparison,
                          groups=groups, headline=rows, family=family_lines, others=beside, faults=faults)
    print(table)
    print(f"{len(records)} episodes in {wall:.1f} s ({args.executor}); results in {Path(args.out)}/: "
          f"{', '.join(sorted(paths))}", file=sys.stderr)
    return {"records": records, "summary": summary, "degradation": deg, "comparison": comparison,
            "run_groups": groups, "headline": rows, "headline_others": beside, "meta": meta, "table": table,
            "family": family, "faults": faults}


if __name__ == "__main__":
    main()
