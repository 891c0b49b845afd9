"""The benchmark flies a condition's seeds as the rows of its batched env: every record is the single env's
episode of its seed, to the bit (lvgym.benchmark.runner.run_block against run_task).

- every policy of evaluate.py's defaults, on both models of every v1 suite (short missions);
- rows that end early (failures) are masked out while the others fly on (the max-q gust suite, whole);
- the shipped v2 learned policies (``inversion-id`` on the fault suite, ``inversion-id-stratos`` on Stratos III);
- a user's policy with only a per-row ``act`` (no ``batch``) flies through the per-row adapter;
- the fingerprint's batched records are the single-env episodes.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies)
from lvgym.benchmark.registry import resolve_policy
from lvgym.benchmark.runner import Block, PolicyError, PolicySpec, Task, build_policy, run_block, run_task
from lvgym.benchmark.suites import SUITES
from lvgym.cli.evaluate import DEFAULT_POLICIES

V1_SUITES = sorted(name for name, s in SUITES.items() if s.version == "v1")
SHORT_S = 4.0       # mission time of the short episodes [s] (the controllers switch on at 2 s)


def same(a: Any, b: Any, path: str = "") -> list[str]:
    """Where two records differ (NaN equals NaN; floats to the bit)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return [f"{path}: keys {sorted(a.keys() ^ b.keys())}"]
        return [d for k in a for d in same(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            return [f"{path}: lengths {len(a)} and {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in same(x, y, f"{path}[{i}]")]
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return [] if np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True) else [f"{path}: arrays differ"]
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return []
    return [] if a == b and type(a) is type(b) else [f"{path}: {a!r} != {b!r}"]


def tasks(suite: str, model: str, specs: list[PolicySpec], seeds: list[int], **options: Any) -> list[Task]:
    s = SUITES[suite].with_options(**options) if options else SUITES[suite]
    cond = next(c for c in s.conditions if c.model == model)
    seed_list = s.seeds("test", max(seeds) + 1)
    return [Task(i, s.name, s.version, k, spec, cond, int(seed_list[k]))
            for i, (spec, k) in enumerate((spec, k) for spec in specs for k in seeds)]


def check_block(block_tasks: list[Task]) -> list[dict[str, Any]]:
    batched = run_block(Block(tuple(block_tasks)))
    single = [run_task(t) for t in block_tasks]
    for t, b, s in zip(block_tasks, batched, single):
        assert same(b, s) == [], (t.policy.name, t.condition.name, t.seed, same(b, s)[:5])
    return batched


def flies(spec: PolicySpec, suite: str, model: str) -> bool:
    """Whether the policy takes the suite's vehicle (the SMILE designs refuse the others by name)."""
    cond = next(c for c in SUITES[suite].conditions if c.model == model)
    try:
        build_policy(spec, cond.make_env())
    except PolicyError as exc:
        assert "designed for" in str(exc), str(exc)
        return False
    return True


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
@pytest.mark.parametrize("suite", V1_SUITES)
def test_every_default_policy_flies_the_single_env_episodes_as_rows(suite, model):
    specs = [spec for spec in map(resolve_policy, DEFAULT_POLICIES) if flies(spec, suite, model)]
    assert {"zero", "gs-pid-flex"} <= {s.name for s in specs}
    records = check_block(tasks(suite, model, specs, [0, 1], mission_time_s=SHORT_S))
    assert len(records) == 2 * len(specs)
    assert all(r["duration_s"] > 0 for r in records)


@pytest.mark.parametrize(("policy", "suite"), [("inversion-id", "smile-v2-faults"),
                                               ("inversion-id-stratos", "stratos-tvc-v2"),
                                               ("inversion-id-smile", "smile-v2")])
@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_the_shipped_v2_learned_policies_fly_the_single_env_episodes_as_rows(model, policy, suite):
    """``inversion-id`` (its own ``batch``: a window per row, the law on the rows at once) on the fault suite,
    and ``inversion-id-stratos`` (the same, with a lead per row) on Stratos III, long enough for the observer's
    window to fill and the controller to act."""
    records = check_block(tasks(suite, model, [resolve_policy(policy)], [0, 1, 2], mission_time_s=6.0))
    assert len({r["score_v2"] for r in records}) == 3


def test_rows_that_end_early_are_masked_out_while_the_others_fly_on():
    """The max-q gust suite, whole (35 s): some episodes fail on q-alpha or attitude before the others end."""
    specs = [resolve_policy(name) for name in ("zero", "lqg", "gs-pid-flex")]
    records = check_block(tasks("smile-v1-maxq-gust", "nonrigid", specs, [0, 1, 2, 3]))
    durations = {round(r["duration_s"], 6) for r in records}
    assert any(r["failed"] for r in records) and not all(r["failed"] for r in records)
    assert len(durations) > 1


class RateDamper:
    """A user's policy with a per-row ``act`` only: pitch and yaw rate fed back (the state observation's
    rates, indices 1 and 2), with an integrator of its own so that the rows' policy objects must stay apart."""

    name = "rate-damper"

    def __init__(self, env: Any = None, gain: float = 2.0) -> None:
        self.gain, self.integral = float(gain), np.zeros(2)

    def reset(self) -> None:
        self.integral[:] = 0.0

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        rates = np.asarray(observation[1:3], dtype=float)
        self.integral += 0.02 * rates
        return np.clip(-self.gain * rates - 0.5 * self.integral, -1, 1).astype(np.float32) * (info["time"] > 2.0)


def test_a_policy_with_only_a_per_row_act_gives_the_same_records_either_way():
    spec = PolicySpec("rate-damper", f"{Path(__file__).resolve()}:RateDamper", (("gain", 3.0),))
    assert not hasattr(RateDamper(), "batch")
    check_block(tasks("smile-v1", "nonrigid", [spec, resolve_policy("lqg")], [0, 1, 2], mission_time_s=8.0))


def test_the_fingerprint_flies_the_single_env_episodes():
    from lvgym.benchmark import fingerprint as fp
    from lvgym.benchmark.runner import play_episode

    suite = SUITES["smile-v1"].with_options(mission_time_s=SHORT_S)
    cond = suite.conditions[1]
    seeds = suite.seeds("test", 2)
    batched = fp._condition_records(suite, cond, list(seeds))
    for r in batched:
        env = cond.make_env()
        obs0, _ = env.reset(seed=r["seed"])
        m = play_episode(fp.POLICIES[r["policy"]](env), env, r["seed"])
        assert same(fp._record(suite, cond, r["seed"], r["policy"], obs0, m), r) == []
