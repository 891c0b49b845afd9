"""``lvgym ledger``: how often each policy has flown on test seeds, and on which blocks (the ledger of test
flights, :mod:`lvgym.benchmark.ledger`).

    lvgym ledger                                   # every policy the ledger names
    lvgym ledger --policies lqg gs-pd-relief       # these, in this order
    lvgym ledger --headline                        # the policies of protocol v2's suites (docs/benchmark.md)

The ledger is the project's ``docs/data/test-flights.jsonl`` when run from the repository's checkout, else a
file of the user's; ``$LVGYM_TEST_FLIGHTS`` names another (``--file`` too).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass

from lvgym.benchmark.ledger import ledger_path, read, table, test_seeds
from lvgym.benchmark.suites import SUITES_V2
from lvgym.commandline import arg, parse

__all__ = ["Args", "announce", "headline_policies", "main"]

PROG = "lvgym ledger"


@dataclass
class Args:
    """Command-line arguments (``lvgym ledger --help``)."""

    policies: list[str] | None = arg(None, metavar="POLICY")
    """only these policy labels, in this order (default: every policy the ledger names)"""
    headline: bool = False
    """the policies protocol v2's suites report (Suite.policies), in their order"""
    file: str | None = arg(None, metavar="PATH")
    """the ledger file (default: $LVGYM_TEST_FLIGHTS, else the checkout's docs/data/test-flights.jsonl, else
    the user's)"""


def headline_policies() -> list[str]:
    """The policies protocol v2's suites report, each once, in order."""
    return list(dict.fromkeys(p for s in SUITES_V2.values() for p in s.policies))


def announce(prog: str, seeds: Iterable[int], why: str = "") -> None:
    """One line on stderr when a command flies test seeds: the count, the range and the ledger it is
    logged in (nothing for validation seeds)."""
    mine = sorted(test_seeds(seeds))
    if mine:
        print(f"{prog}: flying {len(mine)} test seeds ({mine[0]:,}-{mine[-1]:,}){' ' + why if why else ''}; "
              f"logged in {ledger_path()}", file=sys.stderr)


def main(argv: list[str] | None = None) -> str:
    """Print the per-policy table of the ledger; returns it."""
    args = parse(Args, argv, PROG, __doc__, epilog=True)
    only = args.policies if args.policies is not None else (headline_policies() if args.headline else None)
    text = table(read(args.file), only)
    print(text, end="")
    return text


if __name__ == "__main__":
    main()
