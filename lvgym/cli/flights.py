"""The options the benchmark's flight commands share (``lvgym margins``, ``python -m
experiments.error_budget.budget``): :class:`FlightArgs`, which a command's own ``Args`` extends, and
:func:`resolve_flights`, which turns its policies and suite into what the runner flies.

A command re-declares a field to change its default (``out: str = "results/margins"``)::

    @dataclass
    class Args(FlightArgs):
        policies: list[str] = arg(default_factory=lambda: ["lqg"], metavar="POLICY")
        out: str = "results/budget"
        episodes: int = arg(10, lo=2, hi=10_000)
        \"\"\"seeds per variant\"\"\"
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lvgym.benchmark.runner import PolicySpec
from lvgym.benchmark.suites import SUITES, Condition, Suite, get_suite
from lvgym.commandline import arg, fail
from lvgym.parallel import EXECUTORS

from .policies import resolve_policy  # (registers the built-in policies)

__all__ = ["FlightArgs", "check_vehicle", "resolve_flights"]


def check_vehicle(option: str, value: str) -> str:
    """A ``--vehicle`` option's value: a shipped vehicle's name or a vehicle file that reads (a missing or
    invalid file stops the command in one line naming the option, or the file, line, key and value)."""
    from lvgym.errors import ConfigError
    from lvgym.vehicle.config import load_vehicle

    try:
        load_vehicle(value)
    except ConfigError as exc:
        if exc.key == "vehicle":
            raise ConfigError(option, exc.value, exc.allowed) from None
        raise
    return value


@dataclass
class FlightArgs:
    """Policies flown on a suite's conditions, where and how."""

    policies: list[str] = arg(default_factory=lambda: ["lqg"], metavar="POLICY")
    """registered policy names, SB3 .zip paths or train.py run folders"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the protocol's suite"""
    mission_time_s: float | None = arg(None, lo=0.0, lo_open=True, hi=3600.0)
    """shorten every episode to this many seconds (smoke tests only)"""
    executor: str = arg("local", choices=EXECUTORS)
    """local (process pool), serial or ray"""
    workers: int | None = arg(None, lo=1, hi=100_000)
    """parallel workers (default: the CPUs available)"""
    out: str = "results"
    """results folder"""
    progress: bool = True
    """show a progress bar"""


def resolve_flights(prog: str, policy_names: Sequence[str], suite_name: str, models: Sequence[str] | None = None,
                    **overrides: Any) -> tuple[list[PolicySpec], Suite, list[Condition]]:
    """A command line's policies (:func:`resolve_policy`, distinct labels), its suite with the env
    ``overrides`` that are not None (:meth:`~.suites.Suite.with_options`) and the suite's conditions of the
    flight ``models`` (None: all); a bad value exits with a one-line message starting ``prog:``."""
    policies = [resolve_policy(n, prog) for n in policy_names]
    if len({p.name for p in policies}) != len(policies):
        fail(prog, f"--policies {' '.join(policy_names)}: each label must be distinct")
    try:
        suite = get_suite(suite_name)
    except ValueError as exc:
        fail(prog, exc)
    suite = suite.with_options(**{k: v for k, v in overrides.items() if v is not None})
    conds = [c for c in suite.conditions if models is None or c.model in models]
    if not conds:
        fail(prog, f"--models {' '.join(models or ())}: suite {suite.name!r} has "
                   f"{sorted({c.model for c in suite.conditions})}")
    return policies, suite, conds
