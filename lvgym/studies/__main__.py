"""``lvgym studies doe|ld-sweep|tw-sweep`` (``python -m lvgym.studies``): run a study of thesis 6.1-6.2 and
write its results.

    lvgym studies doe                         # 32 runs, local process pool
    lvgym studies doe --fraction --executor serial
    lvgym studies ld-sweep --step 0.005 --workers 2
    lvgym studies tw-sweep --executor ray

Finished runs are cached under ``<out>/cache``: an interrupted study, run again, runs only what is missing.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Literal

from lvgym.commandline import arg, command_name, fail, option_number, parse
from lvgym.errors import ConfigError
from lvgym.parallel import EXECUTORS

from .responses import AERO_MODES, MACH_MAX, RunSetup
from .sweeps import LD_RANGE, TW_RANGE

PROG = "python -m lvgym.studies"
#: the sweep steps' defaults: diameter [m] (ld-sweep) and mass flow [kg/s] (tw-sweep)
DEFAULT_STEP = {"ld-sweep": 0.001, "tw-sweep": 0.1}


@dataclass
class Args:
    """Command-line arguments (``lvgym studies --help``)."""

    study: Literal["doe", "ld-sweep", "tw-sweep"] = arg(positional=True)
    """the study: the 2^5 design of experiments, or a sweep of L/D or of thrust-to-weight"""
    executor: str = arg("local", choices=EXECUTORS)
    """local (process pool), serial or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000)
    """processes / Ray CPUs (default: the CPUs available)"""
    out: str | None = None
    """output directory (default results/studies/<study>)"""
    fraction: bool = False
    """doe: the 4-run fraction (length x diameter)"""
    step: float | None = None
    """sweep step: diameter [m] (ld-sweep, default 0.001) or mass flow [kg/s] (tw-sweep, 0.1)"""
    aero: str = arg("reference", choices=AERO_MODES)
    """aerodynamics (lvgym.studies.responses)"""
    aero_mach: float = arg(2.0, lo=0.0, hi=MACH_MAX)
    """Mach at which the tables are frozen"""
    progress: bool = True
    """show a progress bar"""

    def __post_init__(self) -> None:
        if self.study != "doe":
            lo, hi = LD_RANGE if self.study == "ld-sweep" else TW_RANGE
            option_number("--step", self.step, 0.0, hi - lo, lo_open=True)
        elif self.step is not None:
            raise ConfigError("--step", self.step, "only for ld-sweep and tw-sweep (doe runs the 2^5 design)")


def main(argv: list[str] | None = None) -> int:
    """Run the study, print its summary; every value checked before a worker starts."""
    from .study import doe_study, ld_sweep_study, tw_sweep_study

    a = parse(Args, argv, PROG, __doc__, epilog=True)
    try:
        setup = RunSetup(aero=a.aero, aero_mach=a.aero_mach)
    except ConfigError as exc:
        fail(command_name(PROG), exc)
    step = DEFAULT_STEP.get(a.study) if a.step is None else a.step
    suffix = "" if a.aero == "reference" else f"-{a.aero}"
    out = a.out or f"results/studies/{a.study}{'-fraction' if a.fraction else ''}{suffix}"
    common = {"executor": a.executor, "workers": a.workers, "progress": a.progress, "setup": setup}
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
