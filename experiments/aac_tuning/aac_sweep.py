"""Variants of ``aac`` (the adaptive augmenting gain on ``gs-pid-flex``) flown on a suite's validation seeds,
nominal and with the base loop's command scaled: the tuning table of docs/adaptive-control.md.

    python -m experiments.aac_tuning.aac_sweep "damper_deadzone_rad2=0" "damper_deadzone_rad2=3e-3" --scales 1 2 0.4

A variant is a set of :class:`.aac.AACParams` keywords (``none``: ``gs-pid-flex`` alone, no adaptive law).
A scale ``x`` multiplies the base loop's command before the adaptive gain (x2: an over-gained loop, +6 dB;
x0.4: lost control effectiveness), so that the law is tried where it is needed and where it is not.
Printed per variant and scale: the mean score [rad] and the failures, per flight model (``rigid /
non-rigid``), over the validation seeds ``0 .. seeds-1`` (never the test seeds).
"""

from __future__ import annotations

import ast
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.benchmark.runner import play_episode
from lvgym.benchmark.suites import SUITES, get_suite
from lvgym.commandline import arg, command_name, fail, parse
from lvgym.errors import ConfigError

from lvgym.baselines.aac import FLEX_AAC, AACParams, AdaptiveAugmentingPolicy, _check_keywords
from lvgym.baselines.pid import flex_pid

__all__ = ["ScaledBase", "ScaledLaw", "parse_variant", "sweep"]


class ScaledLaw(BatchLaw):
    """A base law whose commands are multiplied by ``scale`` [-]: its rows' ``gimbal`` [rad] (what the adaptive
    gain reads) and, alone, its actions (which the env clips to [-1, 1])."""

    def __init__(self, base: Any, scale: float) -> None:
        self.base, self.scale = getattr(base, "law", base), float(scale)
        self.name = f"{self.base.name}*{scale:g}"
        self.dt, self.limit = self.base.dt, self.base.limit
        self.allocate(self.base.n)

    def _rows(self, n: int) -> None:
        self.base = self.base.batch(n)

    @property
    def gimbal(self) -> np.ndarray:
        return np.asarray(self.base.gimbal, dtype=float) * self.scale

    def reset(self, rows: Any) -> None:
        self.base.reset(rows)

    def act(self, rows: Any, observations: np.ndarray, info: Any) -> np.ndarray:
        a = np.asarray(self.base.act(rows, observations, info))
        return (a * np.asarray(self.scale, dtype=a.dtype)).astype(a.dtype, copy=False)


class ScaledBase(RowFace):
    """:class:`ScaledLaw` for one row: a policy (a PID-family face or law) with its command scaled."""

    def __init__(self, base: Any, scale: float) -> None:
        self.law = ScaledLaw(base, scale)

    @property
    def last_gimbal(self) -> np.ndarray:
        return self.law.gimbal[0].copy()


def parse_variant(text: str) -> dict[str, Any] | None:
    """``"key=value, key=value"`` -> keywords of :class:`.aac.AACParams` (values as Python literals), checked
    by building the parameters; ``"none"`` -> None (the base loop alone)."""
    if text.strip() == "none":
        return None
    out: dict[str, Any] = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        key, sep, value = part.partition("=")
        if not sep:
            raise ConfigError("variant", part, "key=value pairs separated by commas, or 'none'")
        try:
            out[key.strip()] = ast.literal_eval(value.strip())
        except (ValueError, SyntaxError):
            raise ConfigError(f"variant {key.strip()}", value.strip(), "a number or a Python literal") from None
    _check_keywords(out)
    AACParams(**out)
    return out


def sweep(variants: list[dict[str, Any] | None], scales: list[float], suite: str = "smile-v1", seeds: int = 10,
          log=print) -> list[dict[str, Any]]:
    """Fly every variant (keywords over :data:`.aac.FLEX_AAC`'s defaults; None: the base alone) at every
    scale on every condition of ``suite`` and its validation seeds ``0 .. seeds-1``."""
    conds = get_suite(suite).conditions
    envs = {c.model: c.make_env() for c in conds}
    rows = []
    for v in variants:
        for x in scales:
            row: dict[str, Any] = {"variant": "none" if v is None else v, "scale": x}
            for model, env in envs.items():
                base = ScaledBase(flex_pid(env), x)
                policy = base if v is None else AdaptiveAugmentingPolicy(base, env=env,
                                                                         params=AACParams(**{**FLEX_AAC, **v}))
                recs = [play_episode(policy, env, s) for s in range(seeds)]
                row[model] = (float(np.mean([r["score"] for r in recs])), sum(bool(r["failed"]) for r in recs))
            rows.append(row)
            log(line(row))
    return rows


def line(row: dict[str, Any]) -> str:
    cells = " / ".join(f"{s:.3f}" + (f" ({f})" if f else "") for s, f in (row[m] for m in ("rigid", "nonrigid") if m in row))
    return f"{row['variant']!s:50s} x{row['scale']:<4g} {cells}"


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.aac_tuning.aac_sweep --help``)."""

    variants: list[str] = arg(positional=True, metavar="VARIANT")
    """"key=value, ..." of AACParams over aac's defaults, or none (gs-pid-flex alone)"""
    scales: list[float] = arg(default_factory=lambda: [1.0, 2.0, 0.4], lo=0.0, lo_open=True, hi=100.0)
    """multipliers of the base loop's command"""
    suite: str = arg("smile-v1", metavar="SUITE", choices=lambda: sorted(SUITES))
    """the suite flown"""
    seeds: int = arg(10, lo=1, hi=10_000)
    """validation seeds 0 .. SEEDS-1"""


def main(argv: list[str] | None = None) -> int:
    """Fly the variants, print the table."""
    prog = "python -m experiments.aac_tuning.aac_sweep"
    a = parse(Args, argv, prog, __doc__)
    try:
        variants = [parse_variant(v) for v in a.variants]
    except (ConfigError, KeyError, ValueError) as exc:
        fail(command_name(prog), exc)
    print(f"{a.suite}, validation seeds 0-{a.seeds - 1}: mean score rigid / non-rigid [rad] (failures)")
    sweep(variants, a.scales, a.suite, a.seeds)
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
