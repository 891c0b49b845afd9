"""The search that raises what the time-domain margins (:mod:`.margins`) insert between a policy and the
actuator until the flight fails.

The perturbations themselves are the flight's own (:func:`~.rows.fly_rows`): a gain ``k`` on each row's action
(:func:`~.rows.scaled`; ``20 log10 k`` dB) and a pure extra delay of whole physics steps (:class:`~.rows.RowDelay`).

- :func:`find_threshold`: the largest value that passes, searched outwards from one known to pass
  (doubling steps), then bisected; :func:`threshold_search` is the same search as a generator, so that
  many go on side by side.
- :func:`fly`: one episode of a policy spec on a condition with a gain and a delay, summarised.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator
from typing import Any

from .runner import PolicySpec, episode_objects, play_episode
from .suites import Condition

__all__ = ["SUMMARY", "db_to_gain", "find_threshold", "fly", "gain_to_db",
           "summary", "threshold_search"]


def db_to_gain(db: float) -> float:
    """``10 ** (db / 20)``: the gain of ``db`` decibels [-]."""
    return 10.0 ** (float(db) / 20.0)


def gain_to_db(gain: float) -> float:
    """``20 log10 gain`` [dB] (``-inf`` for a gain of 0)."""
    return 20.0 * math.log10(gain) if gain > 0.0 else -math.inf


def threshold_search(safe: float, limit: float, tol: float, first_step: float,
                     integer: bool = False) -> Generator[float, bool, tuple[float, float | None, list[tuple[float, bool]]]]:
    """:func:`find_threshold` as a generator: it yields each value to try and is sent whether it passed;
    its return value (``StopIteration.value``) is ``(passed, failed, trials)``. Many searches can so go on
    side by side, their trials flown together (the margins' seeds, :mod:`.margins`)."""
    a, lim = float(safe), float(limit)
    if integer:
        a, lim, tol, first_step = float(round(a)), float(round(lim)), 1.0, max(1.0, float(round(abs(first_step))))
    direction = 1.0 if lim >= a else -1.0
    step = abs(float(first_step))
    trials: list[tuple[float, bool]] = []
    failed = None
    while a != lim:                                   # outwards
        x = a + direction * step
        x = lim if (x - lim) * direction >= 0.0 else x
        ok = bool((yield x))
        trials.append((x, ok))
        if not ok:
            failed = x
            break
        a, step = x, 2.0 * step
    if failed is None:
        return a, None, trials
    b = failed
    while abs(b - a) > tol + 1e-12:                   # then bisection of the bracket [a, b]
        m = a + (math.trunc((b - a) / 2.0) if integer else (b - a) / 2.0)
        ok = bool((yield m))
        trials.append((m, ok))
        if ok:
            a = m
        else:
            b = m
    return a, b, trials


def find_threshold(passes: Callable[[float], bool], safe: float, limit: float, tol: float, first_step: float,
                   integer: bool = False) -> tuple[float, float | None, list[tuple[float, bool]]]:
    """The largest value that passes, searched outwards from ``safe`` (known to pass, not tried) towards
    ``limit`` (either side of it): steps of ``first_step``, doubling (``safe + first_step``, ``+ 2 first_step``,
    ``+ 4 first_step``, ..., the last one at ``limit``) until one fails, then bisection between the last
    that passed and the first that failed until the bracket is at most ``tol`` wide (``integer``: whole
    values, the bracket ends 1 wide). It assumes one crossing in that bracket; searching outwards from the
    nominal, it finds the first failure on that grid and not a wider pass region further out. Returns
    ``(passed, failed, trials)``: the value that passed closest to the failure, the first value that
    failed (None: ``limit`` passed, the threshold lies beyond it) and every ``(value, passed)`` in the
    order tried (:func:`threshold_search` is the same search as a generator).

    >>> find_threshold(lambda x: x < 7.3, 0.0, 20.0, 0.25, 1.0)[:2]
    (7.25, 7.5)
    """
    search = threshold_search(safe, limit, tol, first_step, integer)
    try:
        x = next(search)
        while True:
            x = search.send(bool(passes(x)))
    except StopIteration as stop:
        return stop.value


#: the fields of an episode's record a margin search reads and keeps (:func:`fly`)
SUMMARY = ("failed", "failure_reason", "rate_error_rad", "score", "gimbal_rate_limit_s", "effort_rad_s", "duration_s")


def summary(record: dict[str, Any]) -> dict[str, Any]:
    """The :data:`SUMMARY` fields of an episode's record."""
    return {key: record[key] for key in SUMMARY}


def fly(policy_spec: PolicySpec, condition: Condition, seed: int, gain: float = 1.0,
        delay_steps: int = 0) -> dict[str, Any]:
    """One episode of ``policy_spec`` on ``condition`` reset with ``seed``, its actions times ``gain`` [-]
    and delayed by ``delay_steps`` physics steps (neither when 1 and 0: the episode of
    :func:`~.runner.run_episode`); returns ``failed``, ``failure_reason``, ``rate_error_rad``, ``score``
    [rad], ``gimbal_rate_limit_s`` [s], ``effort_rad_s`` [rad s] and ``duration_s`` [s] of its record. Envs and
    policies are cached per process."""
    if not (math.isfinite(gain) and gain >= 0.0):
        raise ValueError(f"gain = {gain!r}: a finite number >= 0")
    env, policy = episode_objects(policy_spec, condition)
    return summary(play_episode(policy, env, seed, gain=gain, delay_steps=delay_steps))
