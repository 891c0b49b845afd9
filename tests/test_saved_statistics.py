"""A saved stable-baselines3 model carries its VecNormalize statistics and flies with them; a model trained under
VecNormalize that has none is refused in one line saying what to pass; a run folder's policy is named when a
command resolves it (:mod:`lvgym.agents.policies.saved`). The model is tiny (8 units, 64 env steps of 0.5 s
episodes); its statistics are set to values far from the identity, so that flying without them would differ."""

from __future__ import annotations

import json
import shutil
import zipfile

import numpy as np
import pytest

import lvgym
from lvgym.agents.policies.saved import (VECNORM_MEMBER, copy_policy, describe_saved, export_main, save_model,
                                         statistics, trained_normalised)
from lvgym.agents.policies.sb3 import SB3Policy

pytest.importorskip("stable_baselines3")

MISSION = {"mission_time_s": 0.5}


@pytest.fixture(scope="module")
def foreign(tmp_path_factory):
    """A PPO trained under VecNormalize by a pipeline of its own (lvgym's SB3 face of smile-v2's rigid condition),
    saved as such a pipeline saves: ``model.save`` and ``VecNormalize.save`` under names of its own choosing."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    folder = tmp_path_factory.mktemp("foreign")
    venv = VecNormalize(lvgym.make_vec_env("smile-v2", "rigid", 2, api="sb3", seed=123, **MISSION))
    model = PPO("MlpPolicy", venv, n_steps=32, batch_size=32, n_epochs=1, policy_kwargs={"net_arch": [8]},
                device="cpu", seed=0)
    model.learn(64)
    import torch

    with torch.no_grad():                           # actions of order one (a fresh PPO's are of order 0.01)
        model.policy.action_net.weight.mul_(50.0)
    rng = np.random.default_rng(5)                  # statistics far from the identity
    n = venv.observation_space.shape[0]
    venv.obs_rms.mean = rng.normal(0.0, 0.5, n)
    venv.obs_rms.var = rng.uniform(0.01, 4.0, n)
    model.save(folder / "agent.zip")
    venv.save(str(folder / "vec_normalize.pkl"))
    return folder, model, venv


def _by_hand(model, venv, obs: np.ndarray) -> np.ndarray:
    """The model's deterministic action with the statistics applied by hand: (obs - mean) / sqrt(var + eps),
    clipped to +-clip_obs."""
    rms = venv.obs_rms
    normed = np.clip((obs - rms.mean) / np.sqrt(rms.var + venv.epsilon), -venv.clip_obs, venv.clip_obs)
    return model.predict(normed.astype(np.float32), deterministic=True)[0]


def _flown(policy, model, venv) -> int:
    """Fly one short episode of smile-v2 (rigid) with ``policy``; every action against :func:`_by_hand`."""
    env = lvgym.make_env("smile-v2", "rigid", **MISSION)
    obs, info = env.reset(seed=7)
    policy.reset()
    steps, differs = 0, False
    while True:
        action = policy.act(obs, info)
        np.testing.assert_allclose(action, _by_hand(model, venv, obs), rtol=1e-5, atol=1e-6)
        differs |= not np.allclose(action, model.predict(obs, deterministic=True)[0], atol=1e-2)
        obs, _, terminated, truncated, info = env.step(action)
        steps += 1
        if terminated or truncated:
            break
    assert differs, "the statistics changed no action: the test would not see them missing"
    assert steps == round(MISSION["mission_time_s"] / env.unwrapped.task.control_dt_s)     # the whole mission
    return steps


def test_a_foreign_model_without_its_statistics_is_refused_in_one_line(foreign):
    folder, _, _ = foreign
    agent = folder / "agent.zip"
    assert trained_normalised(agent)
    with pytest.raises(ValueError) as err:
        SB3Policy(agent)
    text = str(err.value)
    assert "\n" not in text and "was trained under VecNormalize and carries no statistics" in text
    assert f"lvgym export-policy {agent} STEM --vecnormalize FILE.pkl" in text
    from lvgym.cli.policies import resolve_policy

    with pytest.raises(SystemExit, match=r"^evaluate\.py: policy '.*agent\.zip': .*--vecnormalize FILE\.pkl, and fly "
                                         r"STEM\.zip$"):
        resolve_policy(str(agent))


def test_its_statistics_given_or_carried_fly_as_applied_by_hand(foreign, tmp_path, capsys):
    folder, model, venv = foreign
    given = SB3Policy(folder / "agent.zip", vecnormalize=folder / "vec_normalize.pkl")
    assert _flown(given, model, venv) > 10
    export_main([str(folder / "agent.zip"), str(tmp_path / "mine"), "--vecnormalize",
                 str(folder / "vec_normalize.pkl")])
    with zipfile.ZipFile(tmp_path / "mine.zip") as z:
        assert VECNORM_MEMBER in z.namelist()
    (tmp_path / "mine_vecnormalize.pkl").unlink()               # the .zip alone carries them
    carried = SB3Policy(tmp_path / "mine.zip")
    np.testing.assert_array_equal(carried.normalizer.obs_rms.mean, venv.obs_rms.mean)
    np.testing.assert_array_equal(carried.normalizer.obs_rms.var, venv.obs_rms.var)
    assert _flown(carried, model, venv) > 10
    from lvgym.cli.policies import resolve_policy

    capsys.readouterr()
    spec = resolve_policy(str(tmp_path / "mine.zip"))
    assert spec.name == "mine" and capsys.readouterr().err == ""   # a .zip given itself: nothing to name


def test_lvgym_saves_the_statistics_inside_the_zip_and_beside_it(foreign, tmp_path):
    _, model, venv = foreign
    zip_path = save_model(model, venv, tmp_path / "saved")
    assert zip_path == tmp_path / "saved.zip" and (tmp_path / "saved_vecnormalize.pkl").is_file()
    with zipfile.ZipFile(zip_path) as z:
        assert {"data", "policy.pth", VECNORM_MEMBER} <= set(z.namelist())
    inside = statistics(zip_path)
    (tmp_path / "saved_vecnormalize.pkl").unlink()
    alone = statistics(zip_path)
    for vn in (inside, alone):
        np.testing.assert_array_equal(vn.obs_rms.var, venv.obs_rms.var)
        assert not vn.training and not vn.norm_reward
    copy = copy_policy(zip_path, tmp_path / "copy")                 # a copy carries them too
    np.testing.assert_array_equal(statistics(copy).obs_rms.mean, venv.obs_rms.mean)


def test_a_run_folder_names_what_it_flies(foreign, tmp_path, capsys):
    """``evaluate.py --policies runs/x`` says which model of the run flies: the best by validation, else the
    final model, else the newest checkpoint, with its step."""
    _, model, venv = foreign
    run = tmp_path / "run"
    for stem, step in (("checkpoints/step_000000000128", 128), ("checkpoints/step_000000000256", 256),
                       ("final_model", 256), ("best_model", 128)):
        (run / stem).parent.mkdir(parents=True, exist_ok=True)
        save_model(model, venv, run / stem)
        (run / f"{stem}.json").write_text(json.dumps({"algo": "PPO", "num_timesteps": step}))
    assert describe_saved(run) == f"{run / 'best_model.zip'}: its best model by validation (step 128)"
    from lvgym.cli.policies import resolve_policy

    resolve_policy(str(run))
    assert capsys.readouterr().err == (f"evaluate.py: policy {str(run)!r} flies {run.resolve() / 'best_model.zip'}: "
                                       "its best model by validation (step 128)\n")
    (run / "best_model.json").unlink()
    assert describe_saved(run) == f"{run / 'final_model.zip'}: its final model (step 256)"
    (run / "final_model.json").unlink()
    assert describe_saved(run) == (f"{run / 'checkpoints' / 'step_000000000256.zip'}: its newest checkpoint "
                                   "step_000000000256 (step 256; no best or final model)")
    shutil.rmtree(run / "checkpoints")
    with pytest.raises(FileNotFoundError, match="a run folder without best_model.zip"):
        describe_saved(run)
