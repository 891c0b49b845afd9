"""Print the verification table: ``python -m lvgym.verify``. Exits 1 when a checked row fails."""

import sys
import time

from . import ALL_CASES, table


def main() -> int:
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
