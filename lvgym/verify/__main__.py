"""Print the verification table: ``lvgym verify`` (``python -m lvgym.verify``). Exits 1 when a checked row fails.

``lvgym verify rocketpy`` and ``lvgym verify rocketpy-timing`` are the side-by-side validation against
RocketPy (:mod:`.rocketpy_case`, :mod:`.rocketpy_timing`).
"""

import sys
import time
from dataclasses import dataclass

from lvgym.commandline import parse

from . import ALL_CASES, table


@dataclass
class Args:
    """No options."""


def main(argv: list[str] | None = None) -> int:
    """Print the table of every case of the thesis's chapter 4; 1 when a checked row fails."""
    parse(Args, argv, "python -m lvgym.verify", __doc__, epilog=True)
    rows = []
    start = time.perf_counter()
    for case in ALL_CASES:
        rows += case()
    print("# lvgym: verification against the thesis (chapter 4)\n")
    print(table(rows))
    failed = [r for r in rows if not r.passed]
    print(f"\n{len(rows) - len(failed)} of {len(rows)} rows pass or are reported "
          f"({sum(r.status == 'INFO' for r in rows)} reported only), "
          f"{len(failed)} failed, {time.perf_counter() - start:.1f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
