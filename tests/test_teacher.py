"""The teacher's privileged observation (the env option ``fault_info``, lvgym/envs/faults.py ``fault_info``) and
what the tools do with a teacher: the benchmark flies it with its block and counts it privileged, a dataset of
its rollouts holds what a blind student sees (lvgym/agents/training/datasets.py), a campaign configuration may leave the
env keywords empty."""

from __future__ import annotations

import math

import numpy as np
import pytest

import lvgym
import lvgym.cli.policies  # noqa: F401  (registers the built-in policies by name)
from lvgym.envs.faults import FAULT, FAULT_NAMES, fault_info
from lvgym.envs.layouts import FAULT_INFO, OBS_FLIGHT, VEHICLE_INFO, informed_layout

SHORT = {"mission_time_s": 3.0, "fault_onset_s": (0.5, 1.0)}


def _fault(kind: str, size: float, axis: int, active: float = 1.0) -> np.ndarray:
    f = FAULT.zeros()
    f[FAULT.at.kind] = FAULT_NAMES.index(kind) + 1
    f[FAULT.at.size], f[FAULT.at.axis], f[FAULT.at.active] = size, axis, active
    return f


def test_the_fault_block_holds_each_kind_on_its_entry_in_hand_units():
    rows = np.array([_fault("misalignment", -math.radians(1.2), 1), _fault("gyro_bias", math.radians(0.1), 0),
                     _fault("thrust", 0.25, 0), _fault("bandwidth", 0.6, 0), _fault("effectiveness", 0.4, 1),
                     _fault("stuck", 0.0, 1), _fault("bandwidth", 0.6, 0, active=0.0), FAULT.zeros()])
    got = fault_info(rows)
    assert got.dtype == np.float32 and got.shape == (8, FAULT_INFO.size)
    want = {0: ("fault_misalignment_yaw", -1.2), 1: ("fault_gyro_bias_pitch", 0.1), 2: ("fault_thrust_loss", 0.25),
            3: ("fault_bandwidth_loss_pitch", 0.6), 4: ("fault_effectiveness_loss_yaw", 0.4),
            5: ("fault_stuck_yaw", 1.0)}
    for b, (name, value) in want.items():
        expected = FAULT_INFO.zeros(dtype=np.float32)
        expected[FAULT_INFO.at.fault_active] = 1.0
        expected[getattr(FAULT_INFO.at, name)] = value
        np.testing.assert_allclose(got[b], expected, rtol=1e-6)
    assert not got[6:].any()                               # before its onset, and no fault: zeros


def test_the_layouts_put_the_vehicle_block_then_the_fault_block_after_the_flight_signals():
    both = informed_layout(OBS_FLIGHT, True, True)
    names = [f.name for f in both.fields]
    assert names[:OBS_FLIGHT.size] == [f.name for f in OBS_FLIGHT.fields]
    assert names[OBS_FLIGHT.size:OBS_FLIGHT.size + VEHICLE_INFO.size] == [f.name for f in VEHICLE_INFO.fields]
    assert names[-FAULT_INFO.size:] == [f.name for f in FAULT_INFO.fields]
    assert informed_layout(OBS_FLIGHT, False, False) is OBS_FLIGHT
    assert informed_layout(OBS_FLIGHT).size == OBS_FLIGHT.size + VEHICLE_INFO.size     # the family's, unchanged


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_the_block_shows_the_struck_fault_and_changes_nothing_else(model):
    blind = lvgym.make_env("smile-v2-faults", model, **SHORT)
    teacher = lvgym.make_env("smile-v2-faults", model, fault_info=True, **SHORT)
    n = blind.observation_space.shape[0]
    assert teacher.observation_space.shape == (n + FAULT_INFO.size,)
    rng = np.random.default_rng(3)
    for seed in (0, 1, 2):
        a, _ = blind.reset(seed=seed)
        b, _ = teacher.reset(seed=seed)
        seen = []
        while True:
            np.testing.assert_array_equal(a, b[:n])
            seen.append(b[n:].copy())
            action = rng.uniform(-0.2, 0.2, 2).astype(np.float32)
            a, _, done_a, trunc_a, info = blind.step(action)
            b, _, done_b, trunc_b, _ = teacher.step(action)
            assert (done_a, trunc_a) == (done_b, trunc_b)
            if done_a or trunc_a:
                break
        seen = np.array(seen)
        struck = np.flatnonzero(seen[:, FAULT_INFO.at.fault_active])
        assert seen[0].sum() == 0.0 and struck.size and (struck == np.arange(struck[0], len(seen))).all()
        kind = info["fault"].split()[0]
        on_kind = [f.name for f in FAULT_INFO.fields if f.name.startswith(f"fault_{kind}")]
        assert np.count_nonzero(seen[-1]) == 2 and any(seen[-1][getattr(FAULT_INFO.at, e)] for e in on_kind)


@pytest.fixture
def saved_teacher(tmp_path):
    """An untrained PPO saved as a teacher: its sidecar's env keywords hold ``fault_info``."""
    from stable_baselines3 import PPO

    from lvgym.agents.policies.saved import save_policy

    env = lvgym.make_env("smile-v2-faults", "rigid", fault_info=True, **SHORT)
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu")
    return save_policy(model, None, tmp_path / "teacher", {"algo": "PPO", "env_id": "lvgym/SmileAscent-v1",
                                                             "env_kwargs": {"fault_info": True}})


def test_the_benchmark_flies_a_teacher_with_its_block_and_counts_it_privileged(saved_teacher):
    from lvgym.benchmark import evaluate
    from lvgym.benchmark.headline import policy_kind
    from lvgym.benchmark.registry import resolve_policy
    from lvgym.benchmark.runner import make_tasks, policy_options
    from lvgym.benchmark.suites import get_suite

    spec = resolve_policy(str(saved_teacher))
    assert policy_options(spec) == {"fault_info": True}
    assert policy_kind(spec) == "privileged" and policy_kind(resolve_policy("lqg")) == "classical"
    assert policy_options(resolve_policy("privileged")) == {"privileged_info": True}
    assert policy_options(resolve_policy("lqg")) == {}
    suite = get_suite("smile-v2-faults").with_options(**SHORT)
    tasks = make_tasks([spec, resolve_policy("lqg")], [suite], 1, "validation")
    assert [dict(t.condition.options).get("fault_info", False) for t in tasks] == [True, False, True, False]
    records = evaluate([spec], [suite], episodes=1, seed_set="validation", workers=1, progress=False)
    assert [r["condition"] for r in records] == ["smile-v2-faults/rigid", "smile-v2-faults/nonrigid"]


def test_a_teachers_dataset_holds_what_its_blind_student_sees(saved_teacher, tmp_path, monkeypatch):
    minari = pytest.importorskip("minari")
    from lvgym.agents.policies.sb3 import SB3Policy
    from lvgym.agents.training.datasets import collect

    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    data = collect(str(saved_teacher), "smile-v2-faults", "rigid", episodes=1, action_noise=0.1, **SHORT)
    blind = lvgym.make_env("smile-v2-faults", "rigid", **SHORT)
    ep = next(data.iterate_episodes())
    assert ep.observations.shape[1] == blind.observation_space.shape[0]
    assert data.observation_space.shape == blind.observation_space.shape
    assert "teacher" in data.storage.metadata["description"]
    # the labels are the teacher's actions on its full observation: fly it again on the teacher's env
    teacher_env = lvgym.make_env("smile-v2-faults", "rigid", fault_info=True, **SHORT)
    pol = SB3Policy(saved_teacher)
    obs, info = teacher_env.reset(seed=0)
    np.testing.assert_array_equal(ep.observations[0], obs[:blind.observation_space.shape[0]])
    np.testing.assert_array_equal(ep.infos["expert_action"][1], pol.act(obs, info))
    assert minari.load_dataset(data.spec.dataset_id).total_episodes == 1


def test_classical_names_every_classical_baseline_a_suite_lists():
    from lvgym.agents.training.datasets import suite_policies
    from lvgym.errors import ConfigError

    got = suite_policies(["classical", "lqg", "zero"], "smile-v2-faults")
    assert got[:6] == ["gs-pid-flex", "gs-pid-flex-quiet", "aac-quiet", "lqg", "lqg-front", "gs-pd-relief"]
    assert got[6:] == ["zero"]
    assert "privileged" not in got and "ppo-res-lqg" not in got and "inversion-id" not in got
    with pytest.raises(ConfigError, match="lists none"):
        suite_policies(["classical"], "smile-windy")


def test_learned_names_the_shipped_learned_policies_a_suite_lists():
    from lvgym.agents.training.datasets import suite_policies

    assert suite_policies(["learned"], "smile-v2-faults") == ["ppo-res-lqg", "inversion-id", "inversion-id-smile"]
    assert suite_policies(["classical", "learned"], "smile-v2")[-3:] == ["ppo-res-lqg", "inversion-id",
                                                                         "inversion-id-smile"]
    assert suite_policies(["learned"], "stratos-tvc-v2") == ["inversion-id-stratos"]   # its own observer
    assert suite_policies(["learned"], "slender-v2") == []              # no learned policy is made for it


def test_an_empty_env_keywords_mapping_adds_no_flag(tmp_path):
    from lvgym.agents.training.campaign_schema import load_campaign

    text = ("name: t\nseeds: [0]\ntrain: {total_timesteps: 1000, suite: smile-v2-faults}\n"
            "configurations:\n  blind: {env_kwargs: {}}\n  teacher: {env_kwargs: {fault_info: true}}\n"
            "evaluation: {suites: [smile-v2-faults], episodes: 1}\n")
    path = tmp_path / "c.yaml"
    path.write_text(text)
    runs = {r.name: r for r in load_campaign(path).runs()}
    assert "--env-kwargs" not in runs["blind-s0"].argv
    assert runs["teacher-s0"].argv[runs["teacher-s0"].argv.index("--env-kwargs") + 1] == "fault_info=true"


def test_the_docs_table_of_the_block_names_every_entry():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "training.md").read_text(encoding="utf-8")
    for f in FAULT_INFO.fields:
        pair = f.name.removesuffix("_yaw")
        shown = f"`{f.name}`" in text or (pair != f.name and f"`{pair}_pitch`, `_yaw`" in text)
        assert shown, f"docs/training.md: the fault block's table lacks {f.name}"
