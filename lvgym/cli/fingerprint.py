"""``lvgym fingerprint``: a frozen protocol's fingerprint and its episodes' reward digest, compared with the
stored files or (when freezing) written (:mod:`lvgym.benchmark.fingerprint`, :mod:`lvgym.benchmark.rewarddigest`).

    lvgym fingerprint --version v1 --check      # compare a fresh run with the stored file (exit 1: differs)
    lvgym fingerprint --version v1 --write      # (re)write it: only when freezing
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from typing import Literal

from lvgym.benchmark.fingerprint import FINGERPRINTS, POLICIES, compare, stored
from lvgym.benchmark.rewarddigest import compare_digests, digests, stored_digests, write_digests
from lvgym.benchmark.rewarddigest import path as digest_path
from lvgym.benchmark.suites import SUITES
from lvgym.commandline import arg, command_name, fail, parse

__all__ = ["Args", "main"]

PROG = "lvgym fingerprint"


@dataclass
class Args:
    """Command-line arguments (``lvgym fingerprint --help``)."""

    mode: Literal["check", "write"] = arg(switches={
        "check": "compare a fresh run with the stored fingerprint", "write": "write the stored fingerprint (when freezing)"})
    version: str = arg("v1", choices=lambda: sorted({s.version for s in SUITES.values()}))
    """protocol version"""
    seeds: int = arg(1, lo=1, hi=1000)
    """test seeds per condition"""


def main(argv: list[str] | None = None) -> None:
    """Check (exit 1 when the fresh run differs) or write the fingerprint and the reward digest."""
    args = parse(Args, argv, PROG, __doc__, epilog=True)
    prog = command_name(PROG)
    try:
        fresh, rewards = digests(args.version, args.seeds)
    except ValueError as exc:
        fail(prog, exc)
    path = FINGERPRINTS / f"{args.version}.json"
    if args.mode == "write":
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"version": args.version, "policies": list(POLICIES), "seeds": args.seeds,
                                    "episodes": fresh}, indent=1) + "\n", encoding="utf-8")
        write_digests(args.version, rewards, args.seeds)
        print(f"{len(fresh)} episodes written to {path} and their rewards' digest to {digest_path(args.version)}")
        return
    diffs = compare(fresh, stored(args.version))
    if digest_path(args.version).is_file():
        diffs += compare_digests(rewards, stored_digests(args.version))
    for line in diffs:
        print(line)
    print(f"{len(fresh)} episodes: " + ("the same" if not diffs else f"{len(diffs)} differences"))
    sys.exit(1 if diffs else 0)


if __name__ == "__main__":
    main()
