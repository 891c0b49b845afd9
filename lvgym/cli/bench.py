"""``lvgym bench``: the speed tables of the dynamics core (RK4 steps per second, :mod:`lvgym.bench`) and of the
shipped control laws (microseconds per row-step at 1 and 1,024 rows, :mod:`.bench_laws`)."""

from __future__ import annotations

import os
import platform
from dataclasses import dataclass

from lvgym.commandline import arg, parse

ONLY = ("all", "core", "laws")


@dataclass
class Args:
    """Command-line arguments (``lvgym bench --help``)."""

    min_time: float = arg(1.0, lo=0.0, lo_open=True, hi=3600.0)
    """seconds per measurement of the dynamics core"""
    only: str = arg("all", choices=ONLY)
    """the tables to print: all, core (the dynamics core) or laws (the control laws)"""
    steps: int = arg(50, lo=1, hi=100_000)
    """control steps timed per law at 1,024 rows (ten times as many at one row)"""


def main(argv: list[str] | None = None) -> None:
    """Print the tables (Markdown)."""
    args = parse(Args, argv, "lvgym bench", __doc__)
    if args.only in ("all", "core"):
        from lvgym.bench import print_table, run

        print_table(run(args.min_time))
    if args.only in ("all", "laws"):
        from .bench_laws import WARMUP_S, run as run_laws

        cpu = platform.processor() or platform.machine()
        print(f"\n# Control laws: microseconds in act per row and control step ({cpu}, {os.cpu_count()} cores; each "
              f"on its suite's non-rigid condition, seeds from 0, timed after {WARMUP_S:g} s of flight)\n", flush=True)
        run_laws(steps={1: 10 * args.steps, 1024: args.steps}, log=lambda line: print(line, flush=True))


if __name__ == "__main__":
    main()
