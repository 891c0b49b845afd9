"""``python -m lvgym.studies doe|ld-sweep|tw-sweep``: run a study of thesis 6.1-6.2 and write its results.

Examples::

    python -m lvgym.studies doe                         # 32 runs, local process pool
    python -m lvgym.studies doe --fraction --executor serial
    python -m lvgym.studies ld-sweep --step 0.005 --workers 2
    python -m lvgym.studies tw-sweep --executor ray

Finished runs are cached under ``<out>/cache``: an interrupted study, run again, runs only what is missing.
"""

from __future__ import annotations

import argparse
import sys

from lvgym.cli import fail, one_line_errors, option_number
from lvgym.errors import ConfigError
from lvgym.parallel import EXECUTORS, check_workers
from .responses import AERO_MODES, MACH_MAX, RunSetup
from .study import doe_study, ld_sweep_study, tw_sweep_study
from .sweeps import LD_RANGE, TW_RANGE

#: the sweep steps' defaults: diameter [m] (ld-sweep) and mass flow [kg/s] (tw-sweep)
DEFAULT_STEP = {"ld-sweep": 0.001, "tw-sweep": 0.1}


def main(argv: list[str] | None = None) -> int:
    ap = one_line_errors(argparse.ArgumentParser(prog="python -m lvgym.studies", description=__doc__.split("\n")[0]))
    ap.add_argument("study", choices=("doe", "ld-sweep", "tw-sweep"))
    ap.add_argument("--executor", choices=EXECUTORS, default="local", help="default: local process pool")
    ap.add_argument("--workers", type=int, default=None, help="processes / Ray CPUs (default: CPUs available)")
    ap.add_argument("--out", default=None, help="output directory (default results/studies/<study>)")
    ap.add_argument("--fraction", action="store_true", help="doe: the 4-run fraction (length x diameter)")
    ap.add_argument("--step", type=float, default=None,
                    help="sweep step: diameter [m] (ld-sweep, default 0.001) or mass flow [kg/s] (tw-sweep, 0.1)")
    ap.add_argument("--aero", choices=AERO_MODES, default="reference", help="aerodynamics (responses.py)")
    ap.add_argument("--aero-mach", type=float, default=2.0, help="Mach at which the tables are frozen")
    ap.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)
    try:                                 # every value checked here, before a worker starts
        check_workers(a.workers, "--workers")
        option_number("--aero-mach", a.aero_mach, 0.0, MACH_MAX)
        if a.study != "doe":
            lo, hi = LD_RANGE if a.study == "ld-sweep" else TW_RANGE
            option_number("--step", a.step, 0.0, hi - lo, lo_open=True)
        elif a.step is not None:
            raise ConfigError("--step", a.step, "only for ld-sweep and tw-sweep (doe runs the 2^5 design)")
        setup = RunSetup(aero=a.aero, aero_mach=a.aero_mach)
    except ConfigError as exc:
        fail(ap.prog, exc)
    step = DEFAULT_STEP.get(a.study) if a.step is None else a.step
    suffix = "" if a.aero == "reference" else f"-{a.aero}"
    out = a.out or f"results/studies/{a.study}{'-fraction' if a.fraction else ''}{suffix}"
    common = {"executor": a.executor, "workers": a.workers, "progress": not a.no_progress, "setup": setup}
    if a.study == "doe":
        res = doe_study(out, fraction=a.fraction, **common)
    elif a.study == "ld-sweep":
        res = ld_sweep_study(out, step=step, **common)
    else:
        res = tw_sweep_study(out, step=step, **common)
    print(f"{a.study}: {len(res.table)} runs ({res.ran} run, {res.cached} cached) in {res.wall_s:.1f} s -> {out}")
    for k, v in res.summary.items():
        print(f"  {k}: {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
