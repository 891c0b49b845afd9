"""``lvgym headline``: the headline that decides (:mod:`lvgym.benchmark.selection`; docs/test-seeds.md, "The
headline's test block").

    lvgym headline select                 # every reported policy of the v2 suites on 200 validation seeds
    lvgym headline fly                    # the selected policies on the test block 12,000-12,199 (once)
    lvgym headline page                   # docs/results.md from the headline's record

``select`` flies every policy each v2 suite reports on validation seeds (200 by default), chooses per suite the
best classical design, the best learned policy and the privileged reference by the headline's rule and writes
the selection file (``docs/data/headline-selection.json`` in the checkout: commit it). ``fly`` refuses a
selection made at a commit with uncommitted changes; it flies the selected policies on the named test block
(:data:`~lvgym.benchmark.suites.HEADLINE_BLOCK`) and on the 50 development seeds (the continuity column), logs
both in the ledger of test flights, writes each suite's result files as ``lvgym evaluate`` does and the
headline's record (``docs/data/headline.json``: its rows and the flights' scores). ``--seed-set validation``
rehearses ``fly`` on validation seeds (no ledger line, no continuity column).
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.benchmark import evaluate, get_suite
from lvgym.benchmark.headline import policy_kind
from lvgym.benchmark.ledger import checkout, source
from lvgym.benchmark.results import atomic_write_text, json_text
from lvgym.benchmark.selection import (SELECTION_IN_REPO, block_rows, block_table, check_selection, choose,
                                       selection_document)
from lvgym.benchmark.suites import HEADLINE_BLOCK, SEED_SETS, SUITES_V2
from lvgym.cli.policies import resolve_policy
from lvgym.commandline import arg, command_name, fail, parse

from .evaluate import MAX_MISSION_TIME_S
from .evaluate import main as evaluate_main
from .results_page import RECORD_IN_REPO, page_main

__all__ = ["EPISODE_FIELDS", "FlyArgs", "SelectArgs", "fly_main", "page_main", "select_main"]

#: the fields of a flight the headline's record keeps (enough for every statistic of the page and comparisons)
EPISODE_FIELDS = ("suite", "condition", "model", "policy", "seed", "score_v2", "failed", "flyable", "fault")
V2_SUITES = list(SUITES_V2)


def _in_repo(path: Path, fallback: str) -> str:
    root = checkout()
    return str(root / path) if root is not None else fallback


@dataclass
class SelectArgs:
    """Command-line arguments (``lvgym headline select --help``)."""

    suites: list[str] = arg(default_factory=lambda: list(V2_SUITES), metavar="SUITE", choices=lambda: V2_SUITES)
    episodes: int = arg(HEADLINE_BLOCK.n, lo=1, hi=10_000)
    """validation seeds per condition and policy (the protocol's selection: at least 200)"""
    out: str | None = arg(None, metavar="PATH")
    """the selection file (default: the checkout's docs/data/headline-selection.json, else
    headline-selection.json)"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=MAX_MISSION_TIME_S)
    """shorten every episode (smoke tests only: the selection is then marked with its overrides)"""
    executor: str = arg("local", choices=("local", "serial", "ray"))
    workers: int | None = arg(None, lo=1, hi=100_000)
    progress: bool = True


def select_main(argv: list[str] | None = None) -> dict[str, Any]:
    """Fly, choose, write the selection file; returns its content."""
    args = parse(SelectArgs, argv, "lvgym headline select", __doc__, epilog=True)
    prog = command_name("lvgym headline select")
    suites = [get_suite(s) for s in args.suites]
    specs = {s.name: [resolve_policy(p, prog) for p in s.policies] for s in suites}
    if args.mission_time_s is not None:
        suites = [s.with_options(mission_time_s=args.mission_time_s) for s in suites]
    kinds = {p.name: policy_kind(p) for v in specs.values() for p in v}
    t0 = time.perf_counter()
    records = evaluate(specs, suites, args.episodes, "validation", args.executor, args.workers, args.progress)
    chosen = choose(records, kinds, {s.name: s.policies for s in suites})
    overrides = {"mission_time_s": args.mission_time_s} if args.mission_time_s is not None else {}
    doc = selection_document(chosen, {s.name: s.policies_joined() for s in suites}, kinds, source(),
                             suites[0].seeds("validation", args.episodes), overrides)
    doc["wall_time_s"], doc["episodes_flown"] = round(time.perf_counter() - t0, 1), len(records)
    out = Path(args.out or _in_repo(SELECTION_IN_REPO, "headline-selection.json"))
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, json_text(doc))
    for name, c in doc["suites"].items():
        print(f"{name}: classical {c['classical']}, learned {c['learned']}, privileged {c['privileged']}")
    print(f"{len(records)} episodes in {doc['wall_time_s']} s; selection in {out}", file=sys.stderr)
    return doc


@dataclass
class FlyArgs:
    """Command-line arguments (``lvgym headline fly --help``)."""

    selection: str | None = arg(None, metavar="PATH")
    """the selection file (default: the checkout's docs/data/headline-selection.json)"""
    out: str = "results/headline"
    """folder of each suite's result files (OUT/<suite>/, OUT/<suite>/continuity/)"""
    record: str | None = arg(None, metavar="PATH")
    """the headline's record (default: the checkout's docs/data/headline.json, else OUT/headline.json)"""
    seed_set: str = arg("test", choices=SEED_SETS)
    """test (the named block, once per selection) or validation (a rehearsal)"""
    episodes: int = arg(HEADLINE_BLOCK.n, lo=1, hi=10_000)
    """seeds per condition of a validation rehearsal (the test block is flown whole)"""
    continuity: bool = True
    """fly the same policies on the 50 development seeds 10,000-10,049 (test only)"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=MAX_MISSION_TIME_S)
    """shorten every episode (validation rehearsals only)"""
    purpose: str = "the headline on the named test block"
    """what the ledger of test flights records"""
    executor: str = arg("local", choices=("local", "serial", "ray"))
    workers: int | None = arg(None, lo=1, hi=100_000)
    progress: bool = True


def _fly_suite(suite: str, names: list[str], seeds: list[str], out: Path, args: FlyArgs,
               why: str = "") -> list[dict[str, Any]]:
    argv = ["--policies", *names, "--only", "--suites", suite, "--out", str(out), "--purpose", args.purpose + why,
            "--executor", args.executor, "--no-plots", *seeds]
    argv += ["--workers", str(args.workers)] if args.workers else []
    argv += ["--mission-time-s", str(args.mission_time_s)] if args.mission_time_s is not None else []
    argv += [] if args.progress else ["--no-progress"]
    return [{k: r.get(k) for k in EPISODE_FIELDS if k in r} for r in evaluate_main(argv)["records"]]


def fly_main(argv: list[str] | None = None) -> dict[str, Any]:
    """Check the selection, fly the block (and the continuity seeds), write the record; returns it."""
    args = parse(FlyArgs, argv, "lvgym headline fly", __doc__, epilog=True)
    prog = command_name("lvgym headline fly")
    path = Path(args.selection or _in_repo(SELECTION_IN_REPO, "headline-selection.json"))
    selection = json.loads(path.read_text(encoding="utf-8")) if path.exists() else None
    why = check_selection(selection)
    if why:
        fail(prog, f"{path}: {why}")
    test = args.seed_set == "test"
    if test and (selection.get("overrides") or selection.get("n_seeds", 0) < HEADLINE_BLOCK.n or args.mission_time_s):
        fail(prog, f"{path}: the test block is flown only from a protocol selection (>= {HEADLINE_BLOCK.n} "
                   "validation seeds, no overrides) and without --mission-time-s")
    out = Path(args.record or (_in_repo(RECORD_IN_REPO, str(Path(args.out) / "headline.json")) if test
                               else Path(args.out) / "headline.json"))
    if test and out.exists():
        flown = json.loads(out.read_text(encoding="utf-8"))["meta"]
        if flown.get("seed_set") == "test" and flown["selection"].get("made_utc") == selection.get("made_utc"):
            fail(prog, f"{out}: the block was flown from this selection on {flown['made_utc'][:10]}: it is flown once "
                       "per selection (a new selection, or remove the record on purpose)")
    block = ["--block", HEADLINE_BLOCK.name] if test else ["--seed-set", "validation", "--episodes", str(args.episodes)]
    t0 = time.perf_counter()
    records: list[dict[str, Any]] = []
    continuity: list[dict[str, Any]] = []
    for suite, chosen in selection["suites"].items():
        names = [chosen[k] for k in ("classical", "learned", "privileged") if chosen.get(k)]
        records += _fly_suite(suite, names, block, Path(args.out) / suite, args)
        if test and args.continuity:
            continuity += _fly_suite(suite, names, ["--block", "development-50"], Path(args.out) / suite / "continuity",
                                     args, " (continuity: the development seeds)")
    rows = block_rows(records, continuity, selection)
    record = {"meta": {"made_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), **source(),
                       "seed_set": args.seed_set, "block": HEADLINE_BLOCK.label() if test else
                       f"validation seeds 0-{args.episodes - 1}", "selection": selection,
                       "wall_time_s": round(time.perf_counter() - t0, 1), "episodes_flown": len(records) + len(continuity)},
              "rows": rows, "episodes": records, "continuity": continuity}
    atomic_write_text(out, json_text(record))
    print("\n".join(block_table(rows)))
    print(f"{record['meta']['episodes_flown']} episodes in {record['meta']['wall_time_s']} s; record in {out}",
          file=sys.stderr)
    return record
