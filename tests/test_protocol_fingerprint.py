"""A frozen protocol goes on giving the same episodes: its stored fingerprint against a fresh run
(:mod:`lvgym.benchmark.fingerprint`), and the comparison itself against hand-made records."""

from __future__ import annotations

import numpy as np
import pytest

from lvgym.benchmark import fingerprint as fp


def _record(**kw):
    base = {"suite": "s", "condition": "s/rigid", "seed": 10000, "policy": "zero", "first_obs": [1.0, 2.0], "score": 1.0,
            "rate_error_rad": 1.0, "max_qalpha_pa_deg": 1e5, "duration_s": 10.0, "failed": False, "failure_reason": ""}
    return {**base, **kw}


def test_compare_names_every_difference_and_tolerates_round_off():
    ref = [_record(), _record(policy="probe")]
    assert fp.compare([dict(r) for r in ref], ref) == []
    assert fp.compare([_record(score=1.0 + 5e-4), _record(policy="probe")], ref) == []     # within RTOL
    diffs = fp.compare([_record(score=1.01, failed=True), _record(policy="probe", first_obs=[1.0, 2.1])], ref)
    assert any("failed: True against False" in d for d in diffs)
    assert any("score: 1.01 against 1.0" in d for d in diffs)
    assert any("first_obs: differs (largest difference 0.1" in d for d in diffs)
    assert fp.compare([_record()], ref) == ["('s', 's/rigid', 10000, 'probe'): not in the fresh run"]


def test_the_probe_is_a_function_of_time_and_unknown_versions_are_refused():
    import gymnasium as gym

    import lvgym  # noqa: F401

    env = gym.make("lvgym/SmileAscent-v1", mission_time_s=1.0)
    probe = fp.ProbePolicy(env)
    a = probe.act(np.zeros(1), {"time": 0.5})
    np.testing.assert_allclose(a, [0.05 * np.sin(np.pi * 0.5), 0.04 * np.cos(2 * np.pi * 1.3 * 0.5)], rtol=1e-6)
    assert env.action_space.contains(a)
    with pytest.raises(ValueError, match="no suite carries it"):
        fp.fingerprint("v9")


@pytest.mark.parametrize("version", ["v0", "v1", "v2", "v2-family"])
def test_a_frozen_protocol_flies_its_stored_episodes(version):
    stored = fp.stored(version)
    suites = fp._suites(version)
    assert {r["suite"] for r in stored} == {s.name for s in suites}
    # every condition (a family suite has a rigid and a non-rigid one per vehicle) x 2 policies, 1 seed
    assert len(stored) == 2 * sum(len(s.conditions) for s in suites)
    assert fp.compare(fp.fingerprint(version), stored) == []
