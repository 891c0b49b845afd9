"""The teacher-student recipe's choices on validation seeds (:mod:`lvgym.agents.training.teacher_student`): which
training seed's observer ships, and which flight options it flies.

- **The seed** (:func:`choose_seed`): each candidate's record (:mod:`lvgym.agents.policies.inversion_record`) is flown
  by the benchmark (:func:`lvgym.benchmark.runner.evaluate`, as the shipped policy flies) on the suite's first
  validation seeds, both flight models; the seed with the fewest failed or unflyable non-rigid flights, then the lowest
  non-rigid mean ``score_v2``, ships.
- **The flight options** (:func:`choose_options`): candidates of the law's options (:class:`FlightOption`: the
  moment's ``average`` and ``lead``, :class:`lvgym.agents.policies.inversion.Lead`; the measured moment's ``ignition``
  seconds and ``ignition_share`` after the next stage's ignition, :class:`lvgym.agents.policies.inversion.Staging`) are
  tried in order against the options kept so far (at first the options as trained). A candidate replaces them
  if (:class:`Rule`) its non-rigid gain margin up is at least ``gain_db`` and its delay margin at least
  ``delay_ms`` on the margin suite's first validation seeds (:func:`lvgym.benchmark.margins.time_domain_margins`),
  and on the suite's validation seeds it loses at most ``losses`` more non-rigid flights and its non-rigid
  mean is at most ``worse`` (a share) above theirs. A candidate short of the margins is not flown on the
  validation seeds.

No test seed is flown.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError

from .teacher import scored

__all__ = ["FlightOption", "Rule", "choose_options", "choose_seed", "margins", "parse_option", "per_model",
           "validation"]

#: the flight options a candidate may set: (kind, lowest, highest)
RANGES = {"lead": (int, 0, 10), "average": (int, 1, 50), "ignition": (float, 0.0, 60.0),
          "ignition_share": (float, 0.01, 1.0)}


@dataclass(frozen=True)
class FlightOption:
    """A candidate of the law's flight options (its fields at None: as the options before it)."""

    lead: int | None = None
    average: int | None = None
    ignition: float | None = None
    ignition_share: float | None = None

    def given(self) -> dict[str, Any]:
        return {k: v for k, v in vars(self).items() if v is not None}

    def label(self) -> str:
        """``lead3-average6-ignition4-share0.5``: a file name and a label."""
        words = {"ignition_share": "share"}
        return "-".join(f"{words.get(k, k)}{v:g}" for k, v in self.given().items())


def parse_option(option: str, text: str) -> FlightOption:
    """A candidate from ``key=value`` pairs separated by commas (``lead=3,average=6``), refused by ``option``'s
    name with the value and what is allowed."""
    values: dict[str, Any] = {}
    for part in str(text).split(","):
        key, sep, raw = part.strip().partition("=")
        if not sep or key not in RANGES or key in values:
            raise ConfigError(option, text, f"comma-separated key=value pairs of {list(RANGES)}, each once "
                                            "(lead=3,average=6)")
        kind, lo, hi = RANGES[key]
        try:
            number = float(raw)
        except ValueError:
            number = float("nan")
        if not lo <= number <= hi or (kind is int and number != int(number)):
            raise ConfigError(option, text, f"{key} {'an integer' if kind is int else 'a number'} in [{lo}, {hi}]")
        values[key] = kind(number)
    return FlightOption(**values)


@dataclass(frozen=True)
class Rule:
    """When a candidate replaces the options kept (module docstring): the non-rigid gain margin up [dB] and
    delay margin [ms] it must reach, the non-rigid losses it may add and the share its non-rigid mean may be
    worse."""

    gain_db: float = 6.0
    delay_ms: float = 30.0
    losses: int = 2
    worse: float = 0.02

    def text(self, seeds: int, margin_suite: str, margin_seeds: int) -> str:
        return (f"in order, each candidate against the options kept (at first as trained): with a non-rigid gain "
                f"margin up of at least {self.gain_db:g} dB and a delay margin no less than {self.delay_ms:g} ms "
                f"on {margin_suite}'s validation seeds 0-{margin_seeds - 1}, at most {self.losses} more failed or "
                f"unflyable non-rigid flights of {seeds:,} validation seeds and a non-rigid mean score_v2 at most "
                f"{100 * self.worse:g} % worse")

    def margins_pass(self, m: dict[str, float | None]) -> bool:
        return (m["gain_up_db"] is not None and m["gain_up_db"] >= self.gain_db and m["delay_ms"] is not None
                and m["delay_ms"] >= self.delay_ms)

    def replaces(self, new: dict[str, dict[str, float]], old: dict[str, dict[str, float]]) -> bool:
        n, o = new["nonrigid"], old["nonrigid"]
        return (n["failed_or_unflyable"] <= o["failed_or_unflyable"] + self.losses
                and n["score_v2_mean"] <= o["score_v2_mean"] * (1.0 + self.worse))


def per_model(records: Sequence[dict[str, Any]]) -> dict[str, dict[str, float]]:
    """Per flight model (the last part of a record's ``condition``), the mean ``score_v2`` and the failed or
    unflyable flights of ``records``."""
    out = {}
    for model in ("rigid", "nonrigid"):
        mean, bad = scored([r for r in records if r["condition"].rsplit("/", 1)[-1] == model])
        out[model] = {"score_v2_mean": mean, "failed_or_unflyable": bad}
    return out


def _spec(record: Path, name: str) -> Any:
    from lvgym.benchmark.runner import PolicySpec

    return PolicySpec(name, "lvgym.agents.policies.inversion_record:from_record",
                      (("path", str(Path(record).resolve())),))


def _executor(workers: int) -> dict[str, Any]:
    return {"executor": "serial"} if workers <= 1 else {"executor": "local", "workers": workers}


def validation(record: Path, suite: Any, episodes: int, workers: int = 1) -> dict[str, dict[str, float]]:
    """:func:`per_model` of the policy of ``record`` on ``suite``'s (a :class:`~lvgym.benchmark.suites.Suite`)
    first ``episodes`` validation seeds, flown by the benchmark."""
    from lvgym.benchmark.runner import evaluate

    return per_model(evaluate([_spec(record, "candidate")], [suite], episodes, "validation", progress=False,
                              **_executor(workers)))


def margins(record: Path, suite: Any, seeds: int, workers: int = 1) -> dict[str, float | None]:
    """The non-rigid gain margin up [dB] and delay margin [ms] of the policy of ``record`` on ``suite``'s
    non-rigid condition, its first ``seeds`` validation seeds (None: every nominal flight failed)."""
    from lvgym.benchmark.margins import time_domain_margins

    conds = [c for c in suite.conditions if c.model == "nonrigid"]
    res = time_domain_margins(_spec(record, "candidate"), conds, seeds, seed_set="validation",
                              experiments=("gain_up", "delay"), **_executor(workers))
    c = res["conditions"][conds[0].name]
    return {"gain_up_db": c["gain_up_dB"].get("margin"), "delay_ms": c["delay_ms"].get("margin")}


def choose_seed(candidates: dict[int, Path], suite: Any, episodes: int, workers: int = 1,
                log: Callable[[str], None] = print) -> tuple[int, dict[str, dict[str, dict[str, float]]]]:
    """The training seed whose record ships (module docstring) and every candidate's validation."""
    scores = {}
    for k, record in candidates.items():
        scores[k] = validation(record, suite, episodes, workers)
        log(f"seed {k}: " + ", ".join(f"{m} {v['score_v2_mean']:.3f} ({v['failed_or_unflyable']})"
                                       for m, v in scores[k].items()))
    best = min(scores, key=lambda k: (scores[k]["nonrigid"]["failed_or_unflyable"],
                                      scores[k]["nonrigid"]["score_v2_mean"]))
    return best, {str(k): v for k, v in scores.items()}


def choose_options(base: dict[str, Any], candidates: Sequence[FlightOption], write: Callable[[str, dict], Path],
                   suite: Any, episodes: int, margin_suite: Any, margin_seeds: int, rule: Rule, workers: int = 1,
                   log: Callable[[str], None] = print) -> dict[str, Any]:
    """The flight options of the observer flown with the options ``base`` (as trained): the rule of the module
    docstring over ``candidates`` in order. ``write(label, options)`` writes a candidate's record and returns
    its path. Returns the options chosen (``options``), the label of each candidate's options (``labels``),
    the validation of those flown (``validation``, by label) and every candidate's margins (``margins``)."""
    kept, label = dict(base), "as trained"
    flown_ = {label: validation(write("as-trained", kept), suite, episodes, workers)}
    log(f"{label}: {_line(flown_[label])}")
    seen, labels = {}, {}
    for cand in candidates:
        options = {**kept, **cand.given()}
        name = cand.label()
        labels[name] = options
        record = write(name, options)
        seen[name] = margins(record, margin_suite, margin_seeds, workers)
        shown = f"gain up {seen[name]['gain_up_db']} dB, delay {seen[name]['delay_ms']} ms"
        if not rule.margins_pass(seen[name]):
            log(f"{name}: {shown}: short of the rule's margins, not flown")
            continue
        flown_[name] = validation(record, suite, episodes, workers)
        took = rule.replaces(flown_[name], flown_[label])
        log(f"{name}: {shown}; {_line(flown_[name])}: {'kept' if took else 'refused'} against {label}")
        if took:
            kept, label = options, name
    return {"options": kept, "label": label, "labels": labels, "validation": flown_, "margins": seen}


def _line(v: dict[str, dict[str, float]]) -> str:
    return ", ".join(f"{m} {x['score_v2_mean']:.3f} ({x['failed_or_unflyable']})" for m, x in v.items())
