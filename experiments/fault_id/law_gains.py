"""The causal teacher's law over its gains: the privileged reference's law on the flight computer's errors,
without the wind ahead, with the true aerodynamic moment carried ``lead`` control steps along its slope over
``span`` (what ``train.py --lead`` teaches), at other bandwidths, dampings and load reliefs than the
reference's, on **validation** seeds of one flight model.

    python -m experiments.fault_id.law_gains --suite smile-v2 --seeds 50   # about a minute per variant

Each variant is ``W,Z,ONSET,FULL,LEAD,SPAN`` (bandwidth [rad/s], damping, the relief's onset and full shares of
the q-alpha limit, lead and span [control steps]); the first default is the teacher of ``inversion-id-smile``'s
first training (the reference's gains, lead 5 over 5). Prints the mean ``score_v2`` with the failed or
unflyable flights per variant. A study: it flies no test seed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lvgym.commandline import arg, parse

from .privileges import Withheld
from .train import condition, scored

#: the variants flown by default: the reference's gains, then one change at a time, then combinations
DEFAULT = ("1,1,0.5,0.9,5,5", "1.25,1,0.5,0.9,5,5", "1.5,1,0.5,0.9,5,5", "1,0.8,0.5,0.9,5,5", "1,1.3,0.5,0.9,5,5",
           "1,1,0.6,1,5,5", "1,1,0.7,1,5,5", "1,1,0.8,1,5,5", "1,1,0.4,0.8,5,5", "1,1,0.5,0.9,4,5",
           "1,1,0.5,0.9,6,5", "1,1,0.5,0.9,5,3", "1,1,0.5,0.9,5,8", "1.25,1,0.6,1,5,5", "1.25,1,0.7,1,5,5",
           "1.25,1,0.5,0.9,6,5", "1,1,0.7,1,6,5")


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.law_gains --help``)."""

    suite: str = arg("smile-v2", choices=("smile-v2", "smile-v2-faults", "stratos-tvc-v2"))
    """the v2 suite"""
    model: str = arg("nonrigid", choices=("rigid", "nonrigid"))
    """the flight model"""
    seeds: int = arg(50, lo=1, hi=300)
    """validation seeds"""
    variants: list[str] = arg(default_factory=lambda: list(DEFAULT), metavar="W,Z,ONSET,FULL,LEAD,SPAN")
    """the law's variants"""


def variant(text: str) -> tuple[float, float, tuple[float, float], int, int]:
    """``W,Z,ONSET,FULL,LEAD,SPAN`` as (bandwidth, damping, relief, lead, span); refused by name."""
    from lvgym.errors import ConfigError

    parts = text.split(",")
    try:
        w, z, onset, full = (float(v) for v in parts[:4])
        lead, span = (int(v) for v in parts[4:])
    except ValueError:
        parts = []
    if len(parts) != 6 or lead < 0 or span < 1:
        raise ConfigError("--variants", text, "W,Z,ONSET,FULL,LEAD,SPAN: four numbers, then a lead >= 0 and a span "
                          ">= 1 [control steps]")
    return w, z, (onset, full), lead, span


def flights(suite: str, model: str, seeds: int, text: str, **options: Any) -> list[dict]:
    """The records of the law of ``text`` (:func:`variant`) on ``suite``'s first ``seeds`` validation seeds
    (``options``: env keywords; tests shorten the mission)."""
    from lvgym.baselines.privileged import privileged
    from lvgym.benchmark.runner import play_episode
    from lvgym.benchmark.suites import get_suite

    w, z, relief, lead, span = variant(text)
    env = condition(model, suite, privileged_info=True, **options).make_env()
    law = Withheld(privileged(env, w, z, relief=relief, preview_periods=0), env, True, True, 0, lead, span)
    return [play_episode(law, env, int(k), flyability=True) for k in get_suite(suite).seeds("validation", seeds)]


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.law_gains", __doc__)
    for text in a.variants:                            # refuse a bad variant before any flight
        variant(text)
    print(f"{a.suite} {a.model}, validation seeds 0-{a.seeds - 1}")
    print("| bandwidth [rad/s] | damping | relief | lead, span | mean score_v2 | failed or unflyable |\n"
          "|---|---|---|---|---|---|")
    for text in a.variants:
        w, z, relief, lead, span = variant(text)
        mean, bad = scored(flights(a.suite, a.model, a.seeds, text))
        print(f"| {w:g} | {z:g} | {relief[0]:g}, {relief[1]:g} | {lead}, {span} | {mean:.3f} | {bad} |", flush=True)


if __name__ == "__main__":
    main()
