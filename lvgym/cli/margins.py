"""``python -m lvgym.cli.margins``: the command line of :mod:`lvgym.benchmark.margins` (time-domain gain and
delay margins of any policy) with every built-in policy registered (:mod:`lvgym.cli.policies`)."""

from __future__ import annotations

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.margins import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
