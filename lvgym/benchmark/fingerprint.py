"""A protocol's fingerprint: what a frozen protocol must go on giving.

A protocol version, once frozen, never changes: the same suite, seed and policy fly the same episode.
The fingerprint is that promise made checkable. For every suite of a protocol version, both conditions,
the first ``seeds`` test seeds, it flies two policies that no design work can change: the zero policy (the
gimbal at zero: the plant, the winds, the dispersions and the sensors alone) and an open-loop gimbal probe
(:class:`ProbePolicy`: the servo, the delay and the bending it excites), and records per episode the score,
the rate error, the failure and its reason, the flight time, the largest q-alpha and the first
observation. ``tests/test_protocol_fingerprint.py`` compares a fresh run with the stored file.

    lvgym fingerprint --version v1 --check     # compare with the stored file
    lvgym fingerprint --version v1 --write     # (re)write it: only when freezing


Reproducibility: on one machine and one set of library versions the episodes are the same to the bit;
across CPUs and BLAS builds the floating-point sums can round differently, so the numbers are compared to
a relative ``RTOL`` (1e-3) and the failure and its reason exactly.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .batch import as_batch
from .flyability import applies
from .rows import fly_rows
from .runner import zero_policy
from .suites import SUITES, Suite

__all__ = ["FINGERPRINTS", "POLICIES", "RTOL", "ProbePolicy", "compare", "episode_key", "fingerprint", "paired", "stored"]

#: where the stored fingerprints live, per protocol version
FINGERPRINTS = Path(__file__).resolve().parent / "data"
#: relative tolerance on the numbers across machines (exact on one machine). Another CPU moved a 50-seed
#: mean of a policy that fails 14 % of its episodes by 1e-3 (README, reproducibility), and a failing
#: episode's end can move by a control step; a protocol change moves these episodes by more
RTOL = 1e-3
NUMBERS = ("score", "rate_error_rad", "max_qalpha_pa_deg", "duration_s")
EXACT = ("failed", "failure_reason")
#: what a protocol that charges flyability (v2 on) adds to each episode, compared where the stored file has it
V2_NUMBERS = ("score_v2", "cmd_rate_rms", "cmd_rate_peak")
V2_EXACT = ("flyable", "fault")


def _suites(version: str) -> list[Suite]:
    out = [s for s in SUITES.values() if s.version == version]
    if not out:
        raise ValueError(f"version = {version!r}: no suite carries it; known: {sorted({s.version for s in SUITES.values()})}")
    return out


def _first(obs: np.ndarray) -> list[float]:
    """The first observation as plain floats (compared to ``RTOL``, not digested: a digest would turn a
    last-bit difference across CPUs into a mismatch)."""
    return [float(x) for x in np.asarray(obs, dtype=np.float64).ravel()]


class ProbePolicy:
    """An open-loop gimbal probe of the action path (servo, delay, the bending it excites): pitch
    ``0.05 sin(2 pi 0.5 t)``, yaw ``0.04 cos(2 pi 1.3 t)`` of the gimbal limit, ``t`` = ``info["time"]`` [s]
    (a roll-only RCS task gets the middle action)."""

    name = "probe"

    def __init__(self, env: Any) -> None:
        self.space = env.action_space

    def reset(self) -> None:
        """Nothing to reset: the probe is a function of time."""

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if not hasattr(self.space, "low"):
            return np.asarray(self.space.nvec, dtype=np.int64) // 2
        t = float(info["time"])
        return np.array([0.05 * np.sin(2 * np.pi * 0.5 * t), 0.04 * np.cos(2 * np.pi * 1.3 * t)], dtype=np.float32)


#: the fingerprint's policies: the plant alone, and the action path
POLICIES = {"zero": zero_policy, "probe": ProbePolicy}


def _record(suite: Suite, condition: Any, seed: int, policy: str, first: np.ndarray, m: dict[str, Any]) -> dict[str, Any]:
    reason = m.get("failure_reason") or ""
    out = {"suite": suite.name, "condition": condition.name, "seed": int(seed), "policy": policy, "first_obs": _first(first),
           "score": float(m["score"]), "rate_error_rad": float(m["rate_error_rad"]),
           "max_qalpha_pa_deg": float(m["max_qalpha_pa_deg"]), "failed": bool(m["failed"]),
           "failure_reason": str(reason), "duration_s": float(m["duration_s"])}
    if applies(suite.version):                  # v2 on: the flyability fields and the fault drawn
        out.update({f: float(m[f]) for f in V2_NUMBERS})
        out.update({"flyable": bool(m["flyable"]), "fault": str(m.get("fault") or "")})
    return out


def _condition_records(suite: Suite, condition: Any, seeds: list[int],
                       rewards: list[dict[str, np.ndarray]] | None = None) -> list[dict[str, Any]]:
    """The fingerprint records of one condition: every seed with every policy, flown together as the rows of
    its batched env (:func:`~.rows.fly_rows`: each row the single env's episode, to the bit); ``rewards``, if
    given, receives each episode's per-step rewards and reward terms, in the records' order."""
    rows = [(seed, name) for seed in seeds for name in POLICIES]
    env = condition.make_env()
    groups = []
    for name, make in POLICIES.items():
        mine = [i for i, (_, n) in enumerate(rows) if n == name]
        groups.append((as_batch(make(env), len(rows), lambda make=make: make(env)), mine))
    first: list[np.ndarray] = []
    records = fly_rows(condition.make_vec_env(len(rows)), [seed for seed, _ in rows], groups, first_observations=first,
                       flyability=applies(suite.version), rewards=rewards)
    return [_record(suite, condition, seed, name, obs0, m) for (seed, name), obs0, m in zip(rows, first, records)]


def fingerprint(version: str, seeds: int = 1, rewards: list[dict[str, np.ndarray]] | None = None) -> list[dict[str, Any]]:
    """The fingerprint records of protocol ``version``: every suite, condition and first ``seeds`` test seeds
    (each condition's episodes flown together); ``rewards``, if given, receives each episode's per-step rewards
    and reward terms, in the records' order (what :mod:`.rewarddigest` digests)."""
    return [r for suite in _suites(version) for cond in suite.conditions
            for r in _condition_records(suite, cond, suite.seeds("test", seeds), rewards)]


def stored(version: str) -> list[dict[str, Any]]:
    """The stored fingerprint of ``version`` (``FileNotFoundError`` if it has none)."""
    return json.loads((FINGERPRINTS / f"{version}.json").read_text(encoding="utf-8"))["episodes"]


def episode_key(r: dict[str, Any]) -> tuple[Any, ...]:
    """A fingerprint episode's key: its suite, condition, seed and policy."""
    return r["suite"], r["condition"], r["seed"], r["policy"]


def paired(fresh: list[dict[str, Any]], reference: list[dict[str, Any]],
           stored: str) -> tuple[list[str], list[tuple[dict[str, Any], dict[str, Any]]]]:
    """The episodes of a fresh run and of a stored file (``stored`` names it in the lines) matched by
    :func:`episode_key`: a line for each episode on one side only, and the pairs (fresh, stored)."""
    ref = {episode_key(r): r for r in reference}
    keys = {episode_key(r) for r in fresh}
    out = [f"{k}: not in the fresh run" for k in ref if k not in keys]
    pairs = []
    for r in fresh:
        old = ref.get(episode_key(r))
        if old is None:
            out.append(f"{episode_key(r)}: not in the stored {stored}")
        else:
            pairs.append((r, old))
    return out, pairs


def compare(fresh: list[dict[str, Any]], reference: list[dict[str, Any]], rtol: float = RTOL) -> list[str]:
    """The differences between two fingerprints, one line each (empty: the same)."""
    key = episode_key
    out, pairs = paired(fresh, reference, "fingerprint")
    for r, old in pairs:
        exact = EXACT + tuple(f for f in V2_EXACT if f in old)
        numbers = NUMBERS + tuple(f for f in V2_NUMBERS if f in old)
        out += [f"{key(r)} {f}: {r.get(f)!r} against {old[f]!r}" for f in exact if r.get(f) != old[f]]
        a, b = np.asarray(r["first_obs"], float), np.asarray(old["first_obs"], float)
        if a.shape != b.shape or not np.allclose(a, b, rtol=rtol, atol=1e-9):
            out.append(f"{key(r)} first_obs: differs (largest difference "
                       f"{np.max(np.abs(a - b)) if a.shape == b.shape else 'in shape'})")
        out += [f"{key(r)} {f}: {r.get(f)!r} against {old[f]!r}" for f in numbers
                if f not in r or not np.isclose(r[f], old[f], rtol=rtol, atol=0.0)]
    return out
