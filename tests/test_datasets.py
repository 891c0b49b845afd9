"""Minari datasets of the benchmark's policies (agents/training/datasets.py) and behaviour cloning from them
(agents/training/clone.py, the cloned policy agents/policies/bc.py): written, loaded by Minari's own API, the same
steps as a single env's flight to the bit, with their provenance; the cloned policy trains, flies and refuses an
env it was not cloned on."""

from __future__ import annotations

import numpy as np
import pytest

import lvgym
from lvgym.errors import ConfigError

minari = pytest.importorskip("minari")


@pytest.fixture
def datasets(tmp_path, monkeypatch):
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    return tmp_path


def test_a_dataset_holds_the_flights_as_a_single_env_flies_them(datasets):
    from lvgym.agents.training.datasets import collect, dataset_id
    from lvgym.benchmark.registry import resolve_policy

    collect("lqg", "smile-v2", "rigid", episodes=2, mission_time_s=3.0)
    data = minari.load_dataset(dataset_id("lqg", "smile-v2", "rigid"))
    assert data.total_episodes == 2
    meta = data.storage.metadata
    assert meta["algorithm_name"] == "lqg" and "validation seeds 0-1" in meta["description"]
    assert "protocol v2" in meta["description"]
    env = lvgym.make_env("smile-v2", "rigid", mission_time_s=3.0)
    spec = resolve_policy("lqg")
    pol = spec.resolve()(env, **dict(spec.kwargs))
    for seed, ep in zip((0, 1), data.iterate_episodes()):
        obs, info = env.reset(seed=seed)
        pol.reset()
        observations, actions = [obs], []
        done = False
        while not done:
            action = pol.act(obs, info)
            obs, _, terminated, truncated, info = env.step(action)
            observations.append(obs)
            actions.append(action)
            done = terminated or truncated
        np.testing.assert_array_equal(ep.observations, np.array(observations))
        np.testing.assert_array_equal(ep.actions, np.array(actions))
        assert ep.truncations[-1] and not ep.terminations.any()
    assert data.recover_environment().spec.id == "lvgym/SmileAscent-v1"


def test_the_reference_and_a_bad_seed_set_are_refused(datasets):
    from lvgym.agents.training.datasets import collect

    with pytest.raises(ConfigError, match="privileged"):
        collect("privileged", "smile-v2", "rigid", episodes=1)
    with pytest.raises(ConfigError, match="seed_set = 'test'"):
        collect("lqg", "smile-v2", "rigid", episodes=1, seed_set="test")


def test_behaviour_cloning_trains_and_flies_and_knows_its_observation(datasets):
    pytest.importorskip("torch")
    from lvgym.agents.policies.bc import policy
    from lvgym.agents.training.clone import features, train
    from lvgym.agents.training.datasets import collect

    np.testing.assert_array_equal(features(np.array([[1.0, 2.0], [3.0, 4.0]]), 2),
                                  [[0.0, 0.0, 1.0, 2.0], [1.0, 2.0, 3.0, 4.0]])
    collect("lqg", "smile-v2", "rigid", episodes=2, mission_time_s=3.0)
    out = datasets / "bc.pt"
    content = train("lvgym/smile-v2-rigid/lqg-v0", out, history=4, hidden=16, epochs=3)
    assert content["steps"] == 300 and len(content["loss"]) == 3 and content["loss"][-1] < content["loss"][0]
    env = lvgym.make_env("smile-v2", "rigid", mission_time_s=1.0)
    pol = policy(env, out)
    obs, info = env.reset(seed=10_000)
    pol.reset()
    assert pol.act(obs, info).shape == (2,)
    with pytest.raises(ConfigError, match="bc path"):
        policy(lvgym.make_env("smile-v2", "rigid", history=2), out)          # a stacked observation: 32 entries
    # evaluate.py takes the file itself, labelled by its stem, and flies it as the benchmark flies any policy
    from lvgym import agents  # noqa: F401  (registers the .pt loader)
    from lvgym.benchmark import evaluate
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.suites import get_suite

    spec = resolve_policy(str(out))
    assert spec.name == "bc" and spec.factory == "lvgym.agents.policies.bc:policy"
    records = evaluate([spec], [get_suite("smile-v2").with_options(mission_time_s=1.0)], episodes=1,
                       seed_set="validation", workers=1, progress=False)
    assert [r["policy"] for r in records] == ["bc", "bc"]


def test_a_noise_injected_dataset_flies_the_noise_and_labels_with_the_policy(datasets):
    """DART's data: the env flew the policy's action plus seeded noise; the labels are the policy's own, so a
    clone trains on them."""
    pytest.importorskip("torch")
    from lvgym.agents.training.clone import train
    from lvgym.agents.training.datasets import NOISE_STREAM, collect, dataset_id

    assert dataset_id("lqg", "smile-v2", "rigid", 0.05) == "lvgym/smile-v2-rigid/lqg-noise0p05-v0"
    with pytest.raises(ConfigError, match="action_noise = 2"):
        collect("lqg", "smile-v2", "rigid", episodes=1, action_noise=2)
    collect("lqg", "smile-v2", "rigid", episodes=1, action_noise=0.05, mission_time_s=2.0)
    ep = next(minari.load_dataset(dataset_id("lqg", "smile-v2", "rigid", 0.05)).iterate_episodes())
    expert = np.asarray(ep.infos["expert_action"])
    assert expert.shape == (len(ep.actions) + 1, 2) and not expert[0].any()
    noise = np.random.default_rng([0, NOISE_STREAM])
    flown = np.clip(expert[1:3] + noise.normal(0.0, 0.05, (2, 2)), -1.0, 1.0).astype(np.float32)
    np.testing.assert_array_equal(ep.actions[:2], flown)               # the first two steps, drawn in order
    assert np.abs(ep.actions - expert[1:]).max() > 0.01
    content = train(dataset_id("lqg", "smile-v2", "rigid", 0.05), datasets / "dart.pt", history=2, hidden=8, epochs=2)
    assert content["steps"] == len(ep.actions)


@pytest.mark.parametrize(("policy", "suite"), [("ppo-res-lqg", "smile-v2-faults"), ("inversion-id", "smile-v2-faults"),
                                               ("inversion-id-stratos", "stratos-tvc-v2"), ("inversion-id-smile", "smile-v2")])
def test_the_shipped_learned_policies_are_recorded_as_they_fly(datasets, policy, suite):
    from lvgym.agents.training.datasets import collect, dataset_id
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import build_policy

    collect(policy, suite, "nonrigid", episodes=1, mission_time_s=3.0)
    data = minari.load_dataset(dataset_id(policy, suite, "nonrigid"))
    assert data.storage.metadata["algorithm_name"] == policy
    env = lvgym.make_env(suite, "nonrigid", mission_time_s=3.0)
    pol = build_policy(resolve_policy(policy), env)
    (ep,) = data.iterate_episodes()
    obs, info = env.reset(seed=0)
    np.testing.assert_array_equal(obs, ep.observations[0])
    pol.reset()
    actions = []
    for recorded in ep.observations[1:]:
        action = pol.act(obs, info)
        obs, _, _, _, info = env.step(action)
        actions.append(action)
        np.testing.assert_array_equal(obs, recorded)
    np.testing.assert_array_equal(ep.actions, np.array(actions))
    assert np.abs(ep.actions).max() > 0                       # the policy acted in the flight recorded
