"""The default reward of a frozen protocol's fingerprint episodes, digested: what the envs must go on rewarding.

A protocol's fingerprint (:mod:`.fingerprint`) holds each episode's score, not its rewards, and a change of
the env's reward would leave it as it is. The digest holds, for every fingerprint episode (every suite,
condition, policy and seed of the fingerprint, flown in the same run), its number of steps and, for the
reward and for each of its terms (``info["reward_terms"]``: docs/rl.md, "Reward"), the sums over
:data:`BLOCKS` consecutive stretches of the episode's steps (as equal as the steps divide). A term is
digested on its own, so a change of a small one (the gimbal effort's is some 1e-3 of the rate error's)
shows at the fingerprint's tolerance.

    lvgym fingerprint --version v2 --check     # compares the digest too, where one is stored

The stored file is ``data/<version>-rewards.json`` beside the fingerprint. As there, the numbers are the same
to the bit on one machine and one set of library versions and compared to a relative ``RTOL`` (1e-3) across
them; the step counts exactly.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from .fingerprint import FINGERPRINTS, RTOL, episode_key, fingerprint, paired

__all__ = ["BLOCKS", "compare_digests", "digest", "digests", "path", "stored_digests", "write_digests"]

#: the stretches of an episode whose sums the digest holds, per series
BLOCKS = 8
_KEY = ("suite", "condition", "seed", "policy")


def digest(record: dict[str, Any], series: dict[str, np.ndarray]) -> dict[str, Any]:
    """The digest of one episode: its fingerprint ``record``'s key, its steps and, per entry of ``series``
    (the per-step ``reward`` and each term's), the sums over :data:`BLOCKS` consecutive stretches."""
    steps = {len(v) for v in series.values()}
    if len(steps) != 1:
        raise ValueError(f"series of lengths {sorted(steps)}: one length per episode")
    return {**{k: record[k] for k in _KEY}, "steps": steps.pop(),
            "blocks": {name: [float(np.sum(part)) for part in np.array_split(np.asarray(v, dtype=float), BLOCKS)]
                       for name, v in series.items()}}


def digests(version: str, seeds: int = 1) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The fingerprint records of protocol ``version`` and their episodes' reward digests, from one run."""
    series: list[dict[str, np.ndarray]] = []
    records = fingerprint(version, seeds, rewards=series)
    return records, [digest(r, s) for r, s in zip(records, series)]


def path(version: str) -> Any:
    """Where the digest of ``version`` is stored."""
    return FINGERPRINTS / f"{version}-rewards.json"


def stored_digests(version: str) -> list[dict[str, Any]]:
    """The stored digest of ``version`` (``FileNotFoundError`` if it has none)."""
    return json.loads(path(version).read_text(encoding="utf-8"))["episodes"]


def write_digests(version: str, episodes: list[dict[str, Any]], seeds: int = 1) -> None:
    """Store the digest ``episodes`` of ``version`` (when freezing, or when a protocol first gets one)."""
    path(version).write_text(json.dumps({"version": version, "blocks": BLOCKS, "seeds": seeds, "episodes": episodes},
                                        indent=1) + "\n", encoding="utf-8")


def compare_digests(fresh: list[dict[str, Any]], reference: list[dict[str, Any]], rtol: float = RTOL) -> list[str]:
    """The differences between two digests, one line each (empty: the same)."""
    key = episode_key
    out, pairs = paired(fresh, reference, "digest")
    for r, old in pairs:
        if r["steps"] != old["steps"]:
            out.append(f"{key(r)} steps: {r['steps']} against {old['steps']}")
            continue
        if set(r["blocks"]) != set(old["blocks"]):
            out.append(f"{key(r)} terms: {sorted(r['blocks'])} against {sorted(old['blocks'])}")
            continue
        for name, sums in r["blocks"].items():
            a, b = np.asarray(sums, float), np.asarray(old["blocks"][name], float)
            if not np.allclose(a, b, rtol=rtol, atol=0.0):
                i = int(np.argmax(~np.isclose(a, b, rtol=rtol, atol=0.0)))
                out.append(f"{key(r)} {name}: stretch {i} sums to {float(a[i])!r} against {float(b[i])!r}")
    return out
