"""A frozen protocol goes on giving the same episodes: its stored fingerprint against a fresh run
(:mod:`lvgym.benchmark.fingerprint`), and the comparison itself against hand-made records; the same run's
default rewards against their stored digest (:mod:`lvgym.benchmark.rewarddigest`)."""

from __future__ import annotations

import numpy as np
import pytest

from lvgym.benchmark import fingerprint as fp
from lvgym.benchmark import rewarddigest as rd


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


def test_the_reward_digest_sums_each_term_by_stretches_and_names_a_change_of_a_small_one():
    series = {"reward": -np.arange(1.0, 17.0), "effort": np.full(16, -1e-6)}
    d = rd.digest(_record(), series)
    assert d["steps"] == 16 and d["blocks"]["reward"] == [-3.0, -7.0, -11.0, -15.0, -19.0, -23.0, -27.0, -31.0]
    assert d["blocks"]["effort"] == pytest.approx([-2e-6] * 8, rel=1e-12)
    assert rd.compare_digests([d], [d]) == []
    changed = rd.digest(_record(), {**series, "effort": np.full(16, -1.01e-6)})      # 1 % of a 1e-6 term
    assert rd.compare_digests([changed], [d]) == \
        ["('s', 's/rigid', 10000, 'zero') effort: stretch 0 sums to -2.02e-06 against -2e-06"]
    shorter = rd.digest(_record(), {k: v[:15] for k, v in series.items()})
    assert rd.compare_digests([shorter], [d]) == ["('s', 's/rigid', 10000, 'zero') steps: 15 against 16"]
    with pytest.raises(ValueError, match="one length per episode"):
        rd.digest(_record(), {"reward": np.zeros(3), "effort": np.zeros(2)})


@pytest.mark.parametrize("version", ["v0", "v1", "v2", "v2-family"])
def test_a_frozen_protocol_flies_its_stored_episodes_and_rewards(version):
    stored = fp.stored(version)
    suites = fp._suites(version)
    assert {r["suite"] for r in stored} == {s.name for s in suites}
    # every condition (a family suite has a rigid and a non-rigid one per vehicle) x 2 policies, 1 seed
    assert len(stored) == 2 * sum(len(s.conditions) for s in suites)
    records, rewards = rd.digests(version)
    assert fp.compare(records, stored) == []
    if version == "v2-family" and not rd.path(version).is_file():
        return                  # its digest is not written yet (rd.write_digests; the fingerprint stays as it is)
    digest = rd.stored_digests(version)
    assert len(digest) == len(stored) and all(len(d["blocks"]) == 7 for d in digest)    # the reward and 6 terms
    assert all(d["steps"] > 0 for d in digest)
    assert rd.compare_digests(rewards, digest) == []
