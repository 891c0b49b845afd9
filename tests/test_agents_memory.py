"""Issue 18's agent infrastructure: residual policies on a classical baseline (the wrapper and the adapter),
recurrent PPO (the LSTM state through the adapter), policies trained with an observation history and
evaluated on the plain protocol observation. Runs are tiny: a few hundred env steps of 2 s episodes."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import gymnasium
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.agents.policies.residual import ResidualConfig, ResidualPolicy, combine
from lvgym.agents.policies.sb3 import SB3Policy, load_policy
from lvgym.agents.wrappers.residual import ResidualEnv, ResidualVecEnv
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import ZeroPolicy, build_policy, play_episode
from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
ENV = "lvgym/SmileAscent-v1"
SHORT = dict(mission_time_s=4.0, wind="turbulence", randomize=True)
ENV_KW = ["mission_time_s=2", "controller_on_after_s=0.2"]
TINY = ["algo.n_steps=32", "algo.batch_size=64", "algo.n_epochs=2", "policy.net_arch=[8,8]"]


def _train_module():
    spec = importlib.util.spec_from_file_location("lvgym_train_script_memory", ROOT / "train.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


TRAIN = _train_module()


def _argv(tmp: Path, name: str, *extra: str, algo: str = "ppo", steps: int = 256) -> list[str]:
    hp = TINY + (["policy.lstm_hidden_size=8"] if algo == "recurrent-ppo" else [])
    return ["--env-id", ENV, "--observation", "flight", "--residual", "none", "--history", "0", "--algo", algo,
            "--name", name, "--runs-dir", str(tmp),
            "--total-timesteps", str(steps), "--seed", "0", "--n-envs", "4", "--hp", *hp, "--env-kwargs", *ENV_KW,
            "--checkpoint-freq", "128", "--eval-suite", "smile-v1", "--eval-freq", "128", "--eval-episodes", "1",
            "--eval-mission-time-s", "0.5", "--no-progress", *extra]


# ------------------------------------------------------------------------------------------ residual
def test_a_zero_residual_flies_the_baselines_episode_bit_for_bit():
    env = gymnasium.make(ENV, **SHORT)
    base = play_episode(build_policy(POLICIES["gs-pid-flex"], env), env, seed=3)
    wrapped = ResidualEnv(gymnasium.make(ENV, **SHORT), ResidualConfig())
    res = play_episode(ZeroPolicy(), wrapped, seed=3)
    assert res["rate_error_rad"] == base["rate_error_rad"] and res["score"] == base["score"]   # bit for bit
    assert res["effort_rad_s"] == base["effort_rad_s"] and res["failed"] == base["failed"]


def test_the_batched_residual_env_flies_each_row_as_the_single_one():
    from lvgym.envs import make_sb3_vec_env
    rows, seed, steps = 2, 5, 120               # 60 steps per episode: each row resets once on the way
    opts = dict(SHORT, mission_time_s=1.2)
    venv = ResidualVecEnv(make_sb3_vec_env(ENV, num_envs=rows, seed=seed, **opts), ResidualConfig(scale=0.3))
    singles = [ResidualEnv(gymnasium.make(ENV, **opts), ResidualConfig(scale=0.3)) for _ in range(rows)]
    vo = venv.reset()
    so = [e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]
    assert np.array_equal(vo, np.stack(so))
    learned = np.random.default_rng(0).uniform(-1, 1, (steps, rows, 2)).astype(np.float32)
    for u in learned:
        vo, vr, done, infos = venv.step(u)
        for i, e in enumerate(singles):
            o, r, term, trunc, _ = e.step(u[i])
            assert np.float32(r) == vr[i]
            if term or trunc:
                assert done[i] and np.array_equal(infos[i]["terminal_observation"], o)
                o, _ = e.reset()
            assert np.array_equal(vo[i], o)


def test_residual_options_are_checked():
    with pytest.raises(ConfigError, match="residual.baseline = 'ppo'"):
        ResidualConfig("ppo")
    with pytest.raises(ConfigError, match=r"residual.scale = 0: a number in \(0.0, 2.0\]"):
        ResidualConfig(scale=0)
    assert np.array_equal(combine(np.array([0.9, -0.2]), np.array([1.0, 1.0]), 0.5), np.float32([1.0, 0.3]))


def test_a_residual_run_records_its_baseline_and_the_adapter_rebuilds_it(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "res", "--residual", "gs-pid-flex", "--residual-scale", "0.25"))
    meta = json.loads((run / "final_model.json").read_text())
    assert meta["residual"] == {"baseline": "gs-pid-flex", "scale": 0.25}
    assert "residual:" in (run / "config.yaml").read_text()
    env = gymnasium.make(ENV, **SHORT)
    with pytest.raises(ValueError, match="needs the env"):
        load_policy(run)
    policy = load_policy(run, env=env)
    assert isinstance(policy, ResidualPolicy) and policy.config == ResidualConfig("gs-pid-flex", 0.25)
    learned, baseline = SB3Policy(run), build_policy(POLICIES["gs-pid-flex"], env)
    obs, info = env.reset(seed=1)
    policy.reset(), learned.reset(), baseline.reset()
    for _ in range(30):                          # the adapter's action: baseline + 0.25 * learned, clipped
        a = policy.act(obs, info)
        assert np.array_equal(a, combine(baseline.act(obs, info), learned.act(obs, info), 0.25))
        obs, _, term, trunc, info = env.step(a)
    r1, r2 = play_episode(policy, env, 2), play_episode(policy, env, 2)
    assert r1["score"] == r2["score"]
    from lvgym.benchmark.registry import resolve_policy    # what evaluate.py does with a run folder
    flown = build_policy(resolve_policy(str(run)), env)
    assert isinstance(flown, ResidualPolicy) and play_episode(flown, env, 2)["score"] == r1["score"]


def test_residual_and_history_combine_in_training_and_in_the_adapter(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "res-h", "--residual", "gs-pid-flex", "--history", "2"))
    opts = dict(SHORT, observation="flight")
    stacked, plain = gymnasium.make(ENV, history=2, **opts), gymnasium.make(ENV, **opts)
    p_stacked, p_plain = load_policy(run, env=stacked), load_policy(run, env=plain)
    hs, info_s = stacked.reset(seed=8)
    ps, info_p = plain.reset(seed=8)
    p_stacked.reset(), p_plain.reset()
    for _ in range(60):        # the history records the applied (baseline + residual) action in both
        a, b = p_stacked.act(hs, info_s), p_plain.act(ps, info_p)
        assert np.array_equal(a, b) and np.array_equal(p_plain.learned._buf[0], hs)
        hs, _, _, _, info_s = stacked.step(a)
        ps, _, _, _, info_p = plain.step(b)


# ------------------------------------------------------------------------------------------ recurrent PPO
def test_recurrent_ppo_trains_saves_and_flies_through_the_adapter(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "lstm", algo="recurrent-ppo", steps=256))
    assert json.loads((run / "final_model.json").read_text())["algo"] == "RecurrentPPO"
    policy = SB3Policy(run)
    assert policy.recurrent and type(policy.model).__name__ == "RecurrentPPO"
    env = gymnasium.make(ENV, **SHORT)
    r1 = play_episode(policy, env, 4)
    r2 = play_episode(policy, env, 4)
    assert r1["score"] == r2["score"] and r1["rate_error_rad"] == r2["rate_error_rad"]   # reset restarts the LSTM
    # the state is carried: the same observation twice gives what predict gives with the state passed on
    obs, info = env.reset(seed=0)
    policy.reset()
    a = [policy.act(obs, info) for _ in range(3)]
    o = np.asarray(policy.normalizer.normalize_obs(obs), dtype=np.float32)[None]
    state, want = None, []
    for i in range(3):
        act, state = policy.model.predict(o, state=state, episode_start=np.array([i == 0]), deterministic=True)
        want.append(act[0])
    assert all(np.array_equal(x, y) for x, y in zip(a, want))
    # the law of two rows, the second starting its episode one step later: each row's LSTM state its own, its
    # actions those of a policy of one row to float32 rounding (SB3's batched LSTM sums in another order)
    rng = np.random.default_rng(1)
    seq = rng.normal(size=(4, 2, 14)).astype(np.float32)
    rows = SB3Policy(run).batch(2)
    rows.reset(np.arange(2))
    got = []
    for t in range(4):
        if t == 1:
            rows.reset([1])
        got.append(rows.act(np.arange(2), seq[t], {}))
    for row, starts in ((0, (0,)), (1, (0, 1))):
        single = SB3Policy(run)
        for t in range(4):
            if t in starts:
                single.reset()
            np.testing.assert_allclose(single.act(seq[t, row], {}), got[t][row], atol=1e-6)
    # a row restarted alone restarts alone: row 0 goes on with its own state
    again = SB3Policy(run).batch(2)
    again.reset(np.arange(2))
    first = [again.act(np.arange(2), seq[t], {}) for t in range(2)]
    assert np.allclose(first[1][0], got[1][0], atol=1e-6)


def test_recurrent_ppo_hyperparameters_are_validated():
    from lvgym.agents.training.config import load_config
    cfg = load_config("recurrent-ppo", ENV)
    assert cfg.sb3_kwargs()["policy_kwargs"]["lstm_hidden_size"] == 64
    with pytest.raises(ConfigError, match="policy.lstm_hidden_size = 0"):
        load_config("recurrent-ppo", ENV, {"policy.lstm_hidden_size": 0})
    with pytest.raises(ConfigError, match="only with --algo recurrent-ppo"):
        load_config("ppo", "lvgym/SmileAscent-v0", {"policy.lstm_hidden_size": 8})
    assert "lstm_hidden_size" not in load_config("ppo", "lvgym/SmileAscent-v0").to_dict()["policy"]


# ------------------------------------------------------------------------------------------ history
def test_a_history_policy_stacks_the_plain_protocol_observation_itself(tmp_path):
    run = TRAIN.train(_argv(tmp_path, "hist", "--history", "3"))
    assert json.loads((run / "final_model.json").read_text())["env_kwargs"]["history"] == 3
    opts = dict(SHORT, observation="flight")
    stacked, plain = gymnasium.make(ENV, history=3, **opts), gymnasium.make(ENV, **opts)
    p_stacked, p_plain = SB3Policy(run), SB3Policy(run)
    hs, info_s = stacked.reset(seed=6)
    ps, info_p = plain.reset(seed=6)
    p_stacked.reset(), p_plain.reset()
    for _ in range(60):                          # the adapter's own stack is the env's, entry for entry
        a, b = p_stacked.act(hs, info_s), p_plain.act(ps, info_p)
        assert np.array_equal(a, b) and np.array_equal(p_plain._buf[0], hs)
        hs, _, _, _, info_s = stacked.step(a)
        ps, _, _, _, info_p = plain.step(b)
