"""Learning agents (issue 7): hyperparameter files, training runs that save, resume (also after a kill)
and reload into the Policy interface, determinism on CPU, and the shipped checkpoint (skipped until one
exists). Runs are tiny: a few hundred env steps of 2 s episodes with 8-unit networks."""

from __future__ import annotations

import importlib.util
import json
import os
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path

import gymnasium
import numpy as np
import pytest
import torch

import lvgym  # noqa: F401
from lvgym.agents.policies.algos import ALGOS
from lvgym.agents.policies.checkpoints import latest_checkpoint, list_checkpoints
from lvgym.agents.policies.saved import load_model
from lvgym.agents.policies.sb3 import SB3Policy
from lvgym.agents.training.config import load_config, read_entries
from lvgym.benchmark.policy import Policy
from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "agents" / "trained" / "ppo_smile_ascent.zip"
ENV_KW = ["mission_time_s=2", "controller_on_after_s=0.2"]
TINY = {"ppo": ["algo.n_steps=32", "algo.batch_size=64", "algo.n_epochs=2", "policy.net_arch=[8,8]"],
        "sac": ["algo.learning_starts=64", "algo.buffer_size=2000", "algo.batch_size=32", "policy.net_arch=[8,8]"],
        "td3": ["algo.learning_starts=64", "algo.buffer_size=2000", "algo.batch_size=32", "policy.net_arch=[8,8]"]}


def _train_module():
    spec = importlib.util.spec_from_file_location("lvgym_train_script", ROOT / "train.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


TRAIN = _train_module()


def _argv(tmp: Path, name: str, algo: str = "ppo", steps: int = 384, seed: int = 0, extra: tuple = ()) -> list[str]:
    return ["--env-id", "lvgym/SmileAscent-v0", "--algo", algo, "--name", name, "--runs-dir", str(tmp),
            "--total-timesteps", str(steps),
            "--seed", str(seed), "--n-envs", "4", "--hp", *TINY[algo], "--env-kwargs", *ENV_KW,
            "--checkpoint-freq", "128", "--eval-freq", "256", "--eval-episodes", "1", "--eval-mission-time-s", "0.5",
            "--no-progress", *extra]


def _vecnorm(stem: Path):
    with open(stem.with_name(stem.name + "_vecnormalize.pkl"), "rb") as f:
        return pickle.load(f)


def _params(zip_path: Path) -> dict[str, torch.Tensor]:
    return {k: v.clone() for k, v in load_model(zip_path).policy.state_dict().items()}


# ------------------------------------------------------------------------------------------ config
def test_every_hyperparameter_entry_loads():
    for algo in ALGOS:
        entries, _ = read_entries(algo)
        for env_id in entries:
            cfg = load_config(algo, env_id)
            assert cfg.algo == algo and cfg.n_envs >= 1
    ppo = load_config("ppo", "lvgym/SmileAscent-v0")
    assert 16 <= ppo.n_envs <= 64 and 0.99 <= ppo.hyper.gamma <= 0.995 and ppo.policy.net_arch == (64, 64)


@pytest.mark.parametrize("algo, overrides, key, text", [
    ("ppo", {"algo.n_stepz": 64}, "algo.n_stepz", "unknown key"),
    ("ppo", {"algo.gamma": 1.5}, "algo.gamma", "[0.0, 1.0]"),
    ("ppo", {"policy.net_arch": [0, 8]}, "policy.net_arch", "layer widths"),
    ("ppo", {"policy.activation": "swish"}, "policy.activation", "one of"),
    ("ppo", {"algo.batch_size": 10**6}, "algo.batch_size", "n_envs * algo.n_steps"),
    ("ppo", {"n_envs": 0}, "n_envs", "[1, 4096]"),
    ("ppo", {"learning_rate": 1e-3}, "learning_rate", "allowed: ['n_envs'"),
    ("td3", {"algo.ent_coef": 0.1}, "algo.ent_coef", "not a TD3 key"),
    ("sac", {"algo.ent_coef": "often"}, "algo.ent_coef", "a number"),
])
def test_config_errors_name_key_value_and_allowed(algo, overrides, key, text):
    with pytest.raises(ConfigError) as err:
        load_config(algo, "lvgym/SmileAscent-v0", overrides)
    msg = str(err.value)
    assert err.value.key == key and repr(next(iter(overrides.values()))) in msg and text in msg
    assert f"{algo}.yaml" in msg


def test_yaml_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "ppo.yaml"
    bad.write_text("lvgym/SmileAscent-v0:\n  normalize: {norm_obs: yes please}\n")
    with pytest.raises(ConfigError, match=r"ppo.yaml: normalize.norm_obs = 'yes please': true or false"):
        load_config("ppo", "lvgym/SmileAscent-v0", path=bad)


# ------------------------------------------------------------------------------------------ training
def test_train_saves_resumes_and_reloads_as_a_policy(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "r1", steps=384))
    config = (run / "config.yaml").read_text()
    for key in ("git_commit:", "lvgym_version:", "hyperparams:", "env_kwargs:", "mission_time_s: 2"):
        assert key in config
    assert list((run / "tb").glob("events.out.tfevents.*"))
    zip0, state0 = latest_checkpoint(run / "checkpoints")
    s0 = state0["num_timesteps"]
    assert s0 >= 384 and state0["algo"] == "PPO" and state0["evaluations"]
    # the best model is selected on the training model's condition only (default --eval-select trained)
    assert "eval_select: trained" in config
    for e in state0["evaluations"]:
        (name,) = e["selected_on"]
        assert name.endswith("/nonrigid")
        assert e["score"] == [e["conditions"][name]["failure_rate"], e["conditions"][name]["score_mean"]]
    assert load_model(zip0).num_timesteps == s0
    count0 = _vecnorm(zip0.with_suffix("")).obs_rms.count

    TRAIN.train(["--resume", str(run), "--total-timesteps", "768", "--no-progress"])
    segments = [json.loads(x) for x in (run / "segments.jsonl").read_text().splitlines()]
    assert [s["start_step"] for s in segments] == [0, s0] and segments[1]["resumed"]
    zip1, state1 = latest_checkpoint(run / "checkpoints")
    s1 = state1["num_timesteps"]
    assert s1 >= 768 and load_model(zip1).num_timesteps == s1
    # the statistics went on from the checkpoint's (a fresh VecNormalize would count only the new steps)
    assert _vecnorm(zip1.with_suffix("")).obs_rms.count >= count0 + (s1 - s0)
    # the evaluation history continued: earlier records kept, no step evaluated twice
    steps = [e["num_timesteps"] for e in state1["evaluations"]]
    assert steps[:len(state0["evaluations"])] == [e["num_timesteps"] for e in state0["evaluations"]]
    assert steps == sorted(set(steps))
    assert json.loads((run / "final_model.json").read_text())["num_timesteps"] == s1
    # where the wall time went (lvgym.agents.training.timing): the env's seconds within the run's, carried across
    # the resume
    for state in (state0, state1):
        assert 0.0 < state["env_wall_s"] < state["train_wall_s"]
    assert state1["env_wall_s"] > state0["env_wall_s"] and state1["train_wall_s"] > state0["train_wall_s"]
    walls = [(e["train_wall_s"], e["env_wall_s"]) for e in state1["evaluations"]]
    assert walls == sorted(walls) and all(0.0 < env_s < wall for wall, env_s in walls)
    import csv

    with open(next(run.glob("progress_000000000000.csv")), encoding="utf-8") as f:
        shares = [float(r["time/env_share"]) for r in csv.DictReader(f) if r.get("time/env_share")]
    assert shares and all(0.0 < x < 1.0 for x in shares)

    env = gymnasium.make("lvgym/SmileAscent-v0", mission_time_s=0.5)
    for source in (run, run / "final_model.zip", run / "best_model.zip"):
        policy = SB3Policy(source)
        assert isinstance(policy, Policy)
        obs, info = env.reset(seed=0)
        policy.reset()
        for _ in range(5):
            action = policy.act(obs, info)
            assert action.shape == (2,) and np.all(np.abs(action) <= 1.0)
            obs, _, terminated, truncated, info = env.step(action)



def test_a_killed_run_resumes_from_its_last_complete_checkpoint(tmp_path):
    argv = _argv(tmp_path, "killed", steps=10**7, extra=("--eval-freq", "0"))
    proc = subprocess.Popen([sys.executable, str(ROOT / "train.py"), *argv], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    folder = tmp_path / "killed" / "checkpoints"
    try:
        deadline = time.monotonic() + 60
        while len(list_checkpoints(folder)) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    assert len(list_checkpoints(folder)) >= 2, "the run wrote no checkpoints before the deadline"
    last = list_checkpoints(folder)[-1][0]
    orphan = folder / f"step_{last + 10**6:012d}.zip"          # a checkpoint cut off before its JSON
    orphan.write_bytes(b"partial")
    TRAIN.train(["--resume", str(tmp_path / "killed"), "--total-timesteps", str(last + 128), "--no-progress"])
    assert not orphan.exists()
    segments = [json.loads(x) for x in (tmp_path / "killed" / "segments.jsonl").read_text().splitlines()]
    assert segments[-1]["start_step"] == last
    assert list_checkpoints(folder)[-1][0] >= last + 128


def test_same_seed_same_training_result(tmp_path):
    runs = [TRAIN.train(_argv(tmp_path, name, steps=256, seed=seed, extra=("--eval-freq", "0")))
            for name, seed in (("a", 5), ("b", 5), ("c", 6))]
    params = [_params(r / "final_model.zip") for r in runs]
    assert params[0].keys() == params[1].keys()
    for k in params[0]:
        assert torch.equal(params[0][k], params[1][k]), k
    assert any(not torch.equal(params[0][k], params[2][k]) for k in params[0])
    norms = [_vecnorm(r / "final_model") for r in runs[:2]]
    np.testing.assert_array_equal(norms[0].obs_rms.mean, norms[1].obs_rms.mean)
    np.testing.assert_array_equal(norms[0].ret_rms.var, norms[1].ret_rms.var)


@pytest.mark.parametrize("algo", ["sac", "td3"])
def test_off_policy_runs_resume_with_their_replay_buffer(tmp_path, algo):
    run = TRAIN.train(_argv(tmp_path, algo, algo=algo, steps=256, extra=("--eval-freq", "0")))
    stem = list_checkpoints(run / "checkpoints")[-1][1]
    with open(stem.with_name(stem.name + "_replay_buffer.pkl"), "rb") as f:
        buffer = pickle.load(f)
    assert buffer.size() * 4 == 256        # 4 rows: every transition of the run is in the buffer
    TRAIN.train(["--resume", str(run), "--total-timesteps", "384", "--no-progress"])
    stem = list_checkpoints(run / "checkpoints")[-1][1]
    with open(stem.with_name(stem.name + "_replay_buffer.pkl"), "rb") as f:
        assert pickle.load(f).size() * 4 == 384
    assert SB3Policy(run).act(np.zeros(14, dtype=np.float32), {}).shape == (2,)


def _rename_schedules(zip_path: Path, module: str) -> None:
    """Rewrite a checkpoint's pickled learning rate and schedule to name the class as ``module`` defined it (a run
    saved when the schedule lived there: ``lvgym.agents.config`` before the agents' sub-packages)."""
    import base64
    import types
    import zipfile

    import cloudpickle

    from lvgym.agents.training.config import LinearSchedule

    with zipfile.ZipFile(zip_path) as z:
        files = {n: z.read(n) for n in z.namelist()}
    data = json.loads(files["data"])
    old = type("LinearSchedule", (LinearSchedule,), {"__module__": module})
    sys.modules[module] = types.ModuleType(module)
    sys.modules[module].LinearSchedule = old
    try:
        for key, obj in (("learning_rate", old(data["learning_rate"]["initial"])), ("lr_schedule", old(1.0))):
            data[key][":serialized:"] = base64.b64encode(cloudpickle.dumps(obj)).decode()
    finally:
        del sys.modules[module]
    files["data"] = json.dumps(data).encode()
    with zipfile.ZipFile(zip_path, "w") as z:
        for name, content in files.items():
            z.writestr(name, content)


def test_a_run_saved_before_its_schedule_moved_resumes(tmp_path):
    """A checkpoint pickles its learning rate schedule by reference to the module that defined it; a resumed run
    loads the schedules rebuilt from its config.yaml, so a run saved before they moved resumes (and a model's
    training is the same either way)."""
    run = TRAIN.train(_argv(tmp_path, "old", steps=128, extra=("--eval-freq", "0")))
    zip0, _ = latest_checkpoint(run / "checkpoints")
    _rename_schedules(zip0, "lvgym.agents.config")
    from stable_baselines3 import PPO

    with pytest.raises(ModuleNotFoundError, match="lvgym.agents.config"):
        PPO.load(str(zip0), device="cpu")                   # the schedules as pickled: their module is gone
    TRAIN.train(["--resume", str(run), "--total-timesteps", "256", "--no-progress"])
    zip1, state1 = latest_checkpoint(run / "checkpoints")
    assert state1["num_timesteps"] >= 256
    import zipfile

    with zipfile.ZipFile(zip1) as z:
        data = json.loads(z.read("data"))
    assert "lvgym.agents.training.config.LinearSchedule" in data["learning_rate"][":type:"]
    lr = load_config("ppo", "lvgym/SmileAscent-v0").hyper.learning_rate
    assert data["learning_rate"]["initial"] == lr and data["lr_schedule"]["value_schedule"] == f"LinearSchedule({lr})"


def test_resume_refuses_arguments_that_would_change_the_run(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "r", steps=128, extra=("--eval-freq", "0")))
    with pytest.raises(SystemExit, match="--seed"):
        TRAIN.train(["--resume", str(run), "--seed", "3"])
    with pytest.raises(SystemExit, match="exists"):
        TRAIN.train(_argv(tmp_path, "r", steps=128))


def test_shipped_checkpoint_loads_and_acts():
    from lvgym.agents.policies.sb3 import shipped_policy

    assert SHIPPED.is_file(), f"the shipped checkpoint {SHIPPED.relative_to(ROOT)} is missing"
    policy = shipped_policy()
    assert policy.name == "ppo" and policy.meta.get("env_id") == "lvgym/SmileAscent-v0"
    assert policy.meta["env_kwargs"]["model"] == "nonrigid" and policy.normalizer is not None
    env = gymnasium.make("lvgym/SmileAscent-v0", mission_time_s=1.0)
    obs, info = env.reset(seed=0)
    policy.reset()
    for _ in range(50):
        action = policy.act(obs, info)
        assert action.shape == (2,) and np.all(np.isfinite(action)) and np.all(np.abs(action) <= 1.0)
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break


def test_validation_selects_on_the_training_model_or_on_every_condition():
    from lvgym.agents.training.callbacks import ValidationEvaluator

    names = {m: ValidationEvaluator("smile-windy", 1, select_on=m).selected for m in ("rigid", "nonrigid", "flex", None)}
    assert names["rigid"] == ["smile-windy/rigid"] and names["nonrigid"] == ["smile-windy/nonrigid"]
    assert names["flex"] == names[None] == ["smile-windy/rigid", "smile-windy/nonrigid"]   # not flown: all


def test_validation_ranks_on_failure_rate_then_the_failure_charged_score():
    """Two policies with equal failure rates: the one whose failures come late has the smaller rate error
    (its integral stops at the failure) but the larger failure-charged score; selection takes the score."""
    from lvgym.agents.training.callbacks import ValidationEvaluator

    ev = ValidationEvaluator("smile-windy", 2, select_on="nonrigid")
    table = {"early": [(True, 0.5, 3.5), (False, 1.0, 1.0)], "late": [(True, 0.9, 1.4), (False, 1.0, 1.0)]}

    class Fake:
        def __init__(self, name):
            self.name = name

        def reset(self):
            pass

        def act(self, observation, info):
            return np.zeros(2, np.float32)

    def episode(policy, condition, seed):
        failed, err, score = table[policy.name][ev.seeds.index(seed)]
        return {"suite": ev.suite.name, "condition": condition.name, "group": condition.group, "policy": policy.name,
                "model": condition.model, "seed": seed, "failed": failed, "failure_reason": "x" if failed else "",
                "rate_error_rad": err, "score": score, "max_rate_radps": 0.0, "effort_rad_s": 0.0,
                "episode_return": -score}

    ev.episode = episode
    early, late = ev.evaluate(Fake("early")), ev.evaluate(Fake("late"))
    assert early["failure_rate"] == late["failure_rate"] == 0.5
    assert early["rate_error_rad"] < late["rate_error_rad"]                  # the old key would pick "early"
    assert early["score"] == [0.5, 2.25] and late["score"] == [0.5, 1.2] and late["score"] < early["score"]
    assert late["selection"] == "failure_rate, score"
    built = []
    ev.evaluate(lambda env: built.append(env) or Fake("late"))            # a factory: built once per condition
    assert len(built) == len(ev.suite.conditions)


def test_validation_flies_a_batched_policys_seeds_as_rows_to_the_bit():
    """A policy with ``batch(n)`` (or a factory of one) is validated on the rows of each condition's batched
    env: every record is the one-by-one episode's, to the bit."""
    from lvgym.agents.policies.sb3 import shipped_policy
    from lvgym.agents.training.callbacks import ValidationEvaluator

    ev = ValidationEvaluator("smile-v2-faults", 3, {"mission_time_s": 8.0})
    policy = shipped_policy()
    for given in (policy, lambda env: policy):
        rows = [r for c in ev.suite.conditions for r in ev._fly(given, c)]
        one = [ev.episode(policy, c, s) for c in ev.suite.conditions for s in ev.seeds]
        assert [r["seed"] for r in rows] == [r["seed"] for r in one] == list(ev.seeds) * 2
        for a, b in zip(rows, one):
            assert a.keys() == b.keys()
            for k in a:
                assert a[k] == b[k] or (isinstance(a[k], float) and np.isnan(a[k]) and np.isnan(b[k])), k
    assert ev.evaluate(policy)["episodes"] == 3


def test_the_compiled_actor_is_predict_to_float32_rounding_and_the_same_bits_in_any_batch():
    """SB3Policy flies an actor-critic MLP through its compiled forward (lvgym.agents.policies.mlp): each action agrees
    with model.predict's to float32 rounding, and a row's action is the same bits alone and in a batch."""
    from lvgym.agents.policies.sb3 import shipped_policy
    p = shipped_policy()
    assert p.net is not None
    rng = np.random.default_rng(3)
    obs = (rng.normal(size=(200, 14)) * rng.choice([0.01, 1.0, 10.0], size=(200, 1))).astype(np.float32)
    law = p.batch(200)
    law.reset(np.arange(200))
    many = law.act(np.arange(200), obs, {})
    for k in range(200):
        a = p.act(obs[k], {})
        o = np.asarray(p.normalizer.normalize_obs(obs[k]), dtype=np.float32)
        b, _ = p.model.predict(o, deterministic=True)
        assert a.dtype == b.dtype and np.array_equal(a, many[k])
        np.testing.assert_allclose(a, b, rtol=0, atol=2e-6)
