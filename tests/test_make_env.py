"""The benchmark's envs from Python (``lvgym.make_env``, ``lvgym.make_vec_env``): the env of a suite's
condition flies the protocol's episode of a seed (the stored v1 fingerprint, flown by the benchmark's own
``Condition.make_env``), the batched env's row ``i`` flies seed ``s + i`` (its Gymnasium face and its SB3
face alike), and a bad suite or model is refused in one line that names what is allowed."""

from __future__ import annotations

import numpy as np
import pytest

import lvgym
from lvgym.benchmark import SUITES, fingerprint as fp
from lvgym.benchmark.runner import play_episode
from lvgym.errors import ConfigError

V1 = sorted(name for name, s in SUITES.items() if s.version == "v1")


def _fingerprint_record(suite: str, model: str, seed: int, env) -> dict:
    """The fingerprint's record of the probe's episode on ``env`` (as :func:`fingerprint._episode` writes it)."""
    obs0, _ = env.reset(seed=seed)
    m = play_episode(fp.ProbePolicy(env), env, seed)
    return {"suite": suite, "condition": f"{suite}/{model}", "seed": seed, "policy": "probe",
            "first_obs": [float(x) for x in np.asarray(obs0, dtype=np.float64).ravel()],
            "score": float(m["score"]), "rate_error_rad": float(m["rate_error_rad"]),
            "max_qalpha_pa_deg": float(m["max_qalpha_pa_deg"]), "failed": bool(m["failed"]),
            "failure_reason": str(m.get("failure_reason") or ""), "duration_s": float(m["duration_s"])}


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
@pytest.mark.parametrize("suite", V1)
def test_make_env_flies_the_benchmarks_episode_of_a_seed(suite, model):
    assert len(V1) == 4
    seed = SUITES[suite].seeds("test", 1)[0]
    stored = [r for r in fp.stored("v1") if r["condition"] == f"{suite}/{model}" and r["policy"] == "probe"]
    assert len(stored) == 1 and stored[0]["seed"] == seed
    fresh = _fingerprint_record(suite, model, seed, lvgym.make_env(suite, model=model))
    assert fp.compare([fresh], stored) == []
    # on this machine the very numbers the benchmark's own Condition.make_env gives
    cond = next(c for c in SUITES[suite].conditions if c.model == model)
    assert lvgym.make_env(suite, model).unwrapped.task == cond.make_env().unwrapped.task


def test_vec_env_rows_are_the_benchmarks_seeds_and_overrides_apply():
    n, seed, steps = 2, 10_000, 40
    venv = lvgym.make_vec_env("smile-v1", "nonrigid", num_envs=n, mission_time_s=5.0)
    singles = [lvgym.make_env("smile-v1", "nonrigid", mission_time_s=5.0) for _ in range(n)]
    assert venv.unwrapped.task == singles[0].unwrapped.task
    assert venv.unwrapped.task.mission_time_s == 5.0 and venv.unwrapped.task.wind == "turbulence_gust"
    vobs, _ = venv.reset(seed=seed)
    sobs = [e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]
    np.testing.assert_array_equal(vobs, np.stack(sobs))
    rng = np.random.default_rng(1)
    for _ in range(steps):
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        vobs, vrew, _, _, _ = venv.step(actions)
        for i, e in enumerate(singles):
            obs, reward, *_ = e.step(actions[i])
            np.testing.assert_array_equal(vobs[i], obs)
            assert vrew[i] == reward


def test_the_sb3_face_is_make_env_row_by_row():
    """``make_vec_env(..., api="sb3", seed=s)``: row ``i`` is ``make_env`` of the same condition reset with seed
    ``s + i``, step for step with the same actions (observations, rewards, dones to the bit), through two
    episodes per row: a finished row restarts within the step, its last observation in the info, and its next
    episode is the single env's next reset (the same generator)."""
    n, seed, overrides = 3, 4_000, {"mission_time_s": 0.6}
    venv = lvgym.make_vec_env("smile-v2", "nonrigid", n, api="sb3", seed=seed, **overrides)
    singles = [lvgym.make_env("smile-v2", "nonrigid", **overrides) for _ in range(n)]
    assert venv.num_envs == n and venv.task == singles[0].unwrapped.task
    assert venv.observation_space == singles[0].observation_space and venv.action_space == singles[0].action_space
    np.testing.assert_array_equal(venv.reset(), np.stack([e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]))
    rng = np.random.default_rng(7)
    episodes, steps = np.zeros(n, dtype=int), 0
    while episodes.min() < 2:
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        obs, rewards, dones, infos = venv.step(actions)
        steps += 1
        for i, e in enumerate(singles):
            o, r, terminated, truncated, _ = e.step(actions[i])
            assert dones[i] == (terminated or truncated) and rewards[i] == np.float32(r)
            if dones[i]:
                np.testing.assert_array_equal(infos[i]["terminal_observation"], o)
                assert infos[i]["TimeLimit.truncated"] == (truncated and not terminated)
                o, _ = e.reset()
                episodes[i] += 1
            np.testing.assert_array_equal(obs[i], o)
    assert steps > 20


def test_make_vec_env_refuses_a_bad_api_or_a_seed_gymnasium_takes_at_reset():
    with pytest.raises(ConfigError, match=r"^api = 'sb4': one of \['gymnasium', 'sb3'\] \(did you mean 'sb3'\?\)$"):
        lvgym.make_vec_env("smile-v2", "rigid", 2, api="sb4")
    with pytest.raises(ConfigError, match=r"^seed = 3: None with api='gymnasium'"):
        lvgym.make_vec_env("smile-v2", "rigid", 2, seed=3)


def test_a_bad_suite_or_model_is_one_line_naming_what_is_allowed():
    with pytest.raises(ConfigError, match=r"^suite = 'smile-v1x': one of \[.*'smile-v1'.*\] \(did you mean 'smile-v1'\?\)$"):
        lvgym.make_env("smile-v1x")
    with pytest.raises(ConfigError, match=r"^model = 'nonrigd': one of \['rigid', 'nonrigid'\] \(the flight models of "
                                          r"suite 'slender-v1'\) \(did you mean 'nonrigid'\?\)$"):
        lvgym.make_vec_env("slender-v1", "nonrigd", num_envs=2)
    with pytest.raises(ConfigError, match=r"^wnd = 'none': unknown option \(did you mean 'wind'\?\)"):
        lvgym.make_env("smile-v1", wnd="none")
