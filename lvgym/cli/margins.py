"""``lvgym margins``: time-domain margins of policies in the
nonlinear simulation, gain up and down [dB] and delay [ms] (:mod:`lvgym.benchmark.margins`).

    lvgym margins                                          # the default policies on smile-v1, 5 validation seeds
    lvgym margins --policies zero pid gs-pid ppo --seeds 10 --models rigid
    lvgym margins --policies runs/ppo_smile --physics-dt-s 0.005   # 5 ms delay resolution
    lvgym margins --policies zero pid --vehicle my_rocket.yaml     # the suite's conditions, your vehicle

Seeds: the ``validation`` seeds by default (margins are what designs are tuned by); ``--seed-set test``
measures on the test seeds on purpose: it says so in one line, and the call is logged in the ledger of test
flights (``lvgym ledger``; ``--purpose`` says why). Policies are registered names, SB3 ``.zip`` paths or ``train.py`` run folders, as
``lvgym evaluate`` takes them. docs/benchmark.md ("Time-domain margins") defines the bound and the search.
"""

from __future__ import annotations

import datetime as dt
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from lvgym.benchmark.margins import (DEFAULT_POLICIES, DEFAULT_SEEDS, DEFAULT_SUITE, EXPERIMENTS, MarginOptions,
                                     margins_table, run_margins, write_margins)
from lvgym.benchmark.suites import SEED_SETS, SUITES, Condition
from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError
from lvgym.parallel import TaskFailed, exit_on_sigterm

from .flights import FlightArgs, check_vehicle, resolve_flights
from .ledger import announce

__all__ = ["Args", "main", "parse_args"]

PROG = "lvgym margins"
_D = MarginOptions()
_OPTIONS = ("error_ratio", "rate_limit_ratio", "gain_max_db", "gain_min_db", "gain_tol_db", "gain_step_db",
            "delay_max_s")


@dataclass
class Args(FlightArgs):
    """Command-line arguments (``lvgym margins --help``)."""

    policies: list[str] = arg(default_factory=lambda: list(DEFAULT_POLICIES), metavar="POLICY")
    suite: str = arg(DEFAULT_SUITE, metavar="SUITE", choices=lambda: sorted(SUITES))
    out: str = "results/margins"
    models: list[str] | None = arg(None, metavar="MODEL")
    """only the suite's conditions of these flight models (default: all, e.g. rigid and nonrigid)"""
    seeds: int = arg(DEFAULT_SEEDS, lo=1, hi=10_000)
    """seeds per condition"""
    seed_set: str = arg("validation", choices=SEED_SETS)
    """validation (design and tuning) or test (a deliberate measurement, logged in the ledger of test flights)"""
    purpose: str | None = arg(None, metavar="TEXT")
    """why test seeds are flown, for the ledger of test flights (default: the command's name)"""
    experiments: list[str] = arg(default_factory=lambda: list(EXPERIMENTS), choices=EXPERIMENTS)
    """what is injected: the gain raised, the gain lowered, a delay"""
    error_ratio: float = _D.error_ratio
    """bound: rate_error_rad above this times the seed's nominal fails"""
    rate_limit_ratio: float = _D.rate_limit_ratio
    """bound: time at the gimbal rate limit above this times the seed's nominal (counted as at least
    RATE_LIMIT_FLOOR_S, 1 s) fails; inf: no such bound"""
    gain_max_db: float = _D.gain_max_db
    """gain searched up to [dB]"""
    gain_min_db: float = _D.gain_min_db
    """gain searched down to [dB]"""
    gain_tol_db: float = _D.gain_tol_db
    """gain bracket [dB]"""
    gain_step_db: float = _D.gain_step_db
    """first step of the outward gain search [dB], doubling"""
    delay_max_s: float = _D.delay_max_s
    """delay searched up to [s]"""
    vehicle: str | None = arg(None, check=check_vehicle, metavar="NAME|PATH")
    """fly every condition with this vehicle in place of the suite's: a shipped vehicle or the path of a
    vehicle YAML file (docs/vehicles.md); the results are then not protocol numbers (version +override)"""
    physics_dt_s: float | None = arg(None, lo=0.0, lo_open=True, hi=0.05)
    """physics step [s], the delay's resolution (default: the env's, 0.01; it also changes the integration
    step and the servo_delay dispersion's quantum)"""
    options: MarginOptions = field(init=False, repr=False)

    def __post_init__(self) -> None:
        try:
            self.options = MarginOptions(**{k: getattr(self, k) for k in _OPTIONS})
        except ConfigError as exc:                    # named as the option
            raise ConfigError(f"--{exc.key.replace('_', '-')}", exc.value, exc.allowed) from None


def parse_args(argv: list[str] | None = None) -> Args:
    """The command line, every value checked before any worker starts."""
    return parse(Args, argv, PROG, __doc__, epilog=True)


def _control_dt_s(condition: Condition) -> float:
    """The control period of ``condition``'s env [s], from its registered class's preset."""
    import lvgym
    from lvgym.envs.options import TimingOptions

    preset = lvgym.env_class(condition.env_id).PRESET
    default = preset.control_dt_s if preset is not None else TimingOptions().control_dt_s
    return float(dict(condition.options).get("control_dt_s", default))


def main(argv: list[str] | None = None) -> list[dict[str, Any]]:
    """Measure, print the table, write the result files; returns the results."""
    args = parse_args(argv)
    prog = command_name(PROG)
    exit_on_sigterm()
    policies, suite, conds = resolve_flights(prog, args.policies, args.suite, args.models,
                                             mission_time_s=args.mission_time_s, physics_dt_s=args.physics_dt_s,
                                             vehicle=args.vehicle)
    if args.physics_dt_s is not None:
        for c in conds:
            n = _control_dt_s(c) / args.physics_dt_s
            if abs(n - round(n)) > 1e-6:
                fail(prog, f"--physics-dt-s = {args.physics_dt_s}: the control period {_control_dt_s(c)} s of "
                           f"{c.env_id} must be a whole multiple of it")
    seeds = suite.seeds(args.seed_set, args.seeds)
    announce(prog, seeds, "on purpose (--seed-set test): a measurement, not a design loop")
    t0 = time.perf_counter()
    try:
        results = run_margins(policies, conds, seeds, seed_set=args.seed_set, options=args.options,
                              experiments=args.experiments, executor=args.executor, workers=args.workers,
                              progress=args.progress, purpose=args.purpose)
    except TaskFailed as exc:
        if isinstance(exc.__cause__, ConfigError):
            fail(prog, exc)
        raise
    wall = time.perf_counter() - t0
    meta = {"suite": suite.name, "version": suite.version, "overrides": dict(suite.overrides),
            "args": {k: v for k, v in vars(args).items() if k != "options"}, "options": asdict(args.options),
            "wall_time_s": round(wall, 3), "episodes": sum(r["episodes"] for r in results),
            "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}
    paths = write_margins(args.out, results, meta)
    print(margins_table(results))
    print(f"{meta['episodes']} episodes in {wall:.1f} s ({args.executor}); results in {Path(args.out)}/: "
          f"{', '.join(p.name for p in paths)}", file=sys.stderr)
    return results


if __name__ == "__main__":
    main()
