"""Training with the loop gain and delay dispersed (lvgym.agents.wrappers.loop_dispersion, ``train.py --loop-gain-db
--loop-delay-periods``): the gain and the delay by hand on a recording env, the draws' ranges and
seeding, the options' errors, and a residual run on the v1 env that records and flies it."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv

from lvgym.agents.wrappers.loop_dispersion import (LoopDispersedVecEnv, LoopDispersion, loop_dispersion_options,
                                                   loop_venv)
from lvgym.errors import ConfigError

from test_agents import TRAIN, _argv


class Recorder(gym.Env):
    """A Box-action env that records the actions it gets; episodes of ``length`` steps."""

    def __init__(self, length: int = 5) -> None:
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (1,), np.float32)
        self.length, self.t, self.got = length, 0, []

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.zeros(1, np.float32), {}

    def step(self, action):
        self.got.append(np.array(action, copy=True))
        self.t += 1
        return np.zeros(1, np.float32), 0.0, self.t >= self.length, False, {}


def _venv(rows: int, dispersion: LoopDispersion, seed: int = 3, length: int = 5) -> LoopDispersedVecEnv:
    venv = LoopDispersedVecEnv(DummyVecEnv([lambda: Recorder(length) for _ in range(rows)]), dispersion, seed)
    venv.reset()
    return venv


def test_the_env_gets_the_gain_times_the_action_of_d_periods_before():
    venv = _venv(6, LoopDispersion(6.0, 2), length=50)
    gains, delays = venv.gain.copy(), venv.delay.copy()
    actions = [np.full((6, 2), 0.1 * (k + 1), np.float32) * np.array([1.0, -0.5], np.float32) for k in range(5)]
    for a in actions:
        venv.step(a)
    for b, env in enumerate(venv.venv.envs):
        for k, got in enumerate(env.got):
            sent = actions[k - delays[b]][b] if k >= delays[b] else np.zeros(2)
            np.testing.assert_allclose(got, gains[b] * sent, rtol=1e-6)


def test_each_episode_draws_again_within_the_ranges_and_the_seed_repeats_them():
    venv = _venv(4, LoopDispersion(4.0, 1), length=3)
    gains, delays = [venv.gain.copy()], [venv.delay.copy()]
    for _ in range(60):
        _, _, done, _ = venv.step(np.zeros((4, 2), np.float32))
        if done.any():
            gains.append(venv.gain.copy())
            delays.append(venv.delay.copy())
    g, d = np.concatenate(gains), np.concatenate(delays)
    assert len(g) == 4 * 21                            # the first draw and one per finished episode (3 steps)
    db = 20.0 * np.log10(g)
    assert db.min() >= -4.0 and db.max() <= 4.0 and db.min() < -3.0 and db.max() > 3.0
    assert set(d) == {0, 1}
    again = _venv(4, LoopDispersion(4.0, 1), length=3)
    np.testing.assert_array_equal(again.gain, gains[0])
    other = _venv(4, LoopDispersion(4.0, 1), seed=4, length=3)
    assert not np.array_equal(other.gain, gains[0])


def test_off_is_the_env_itself_and_bad_values_name_the_option():
    base = DummyVecEnv([Recorder])
    assert loop_venv(base, None, 0) is base
    assert loop_dispersion_options(0.0, 0) is None
    assert loop_dispersion_options(3.0, 1) == {"gain_db": 3.0, "delay_periods": 1}
    with pytest.raises(ConfigError, match=r"--loop-gain-db = -1\.0: a number in \[0\.0, 20\.0\]"):
        loop_dispersion_options(-1.0, 0)
    with pytest.raises(ConfigError, match=r"--loop-delay-periods = 11: an integer in \[0, 10\]"):
        loop_dispersion_options(0.0, 11)


def test_a_bad_loop_option_is_one_line_and_leaves_no_run_folder(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        TRAIN.train([*_argv(tmp_path, "loop-typo", steps=128), "--loop-delay-periods", "-1"])
    text = exit_.value.code if isinstance(exit_.value.code, str) else capsys.readouterr().err
    assert "--loop-delay-periods = -1: an integer in [0, 10]" in text and not list(tmp_path.iterdir())


def test_a_residual_run_records_and_flies_the_dispersion(tmp_path):
    extra = ("--env-id", "lvgym/SmileAscent-v1", "--residual", "lqg", "--residual-scale", "0.05", "--eval-freq", "0",
             "--loop-gain-db", "3", "--loop-delay-periods", "1")
    args, given = TRAIN.parse_args(_argv(tmp_path, "loop", steps=128, extra=extra))
    _, config, _, _ = TRAIN.prepare(args, given)
    assert config["loop_dispersion"] == {"gain_db": 3.0, "delay_periods": 1}
    from lvgym.agents.training.config import build_config

    norm = build_config(config["algo"], config["env_id"], config["hyperparams"], "-").normalize
    venv = TRAIN.make_venv(config["env_id"], 4, 0, {**config["env_kwargs"], "mission_time_s": 2.0}, norm, 0.99,
                           None, config["residual"], config["loop_dispersion"])
    inner = venv
    while not isinstance(inner, LoopDispersedVecEnv):
        inner = inner.venv
    venv.reset()
    for _ in range(5):
        venv.step(np.zeros((4, 2), np.float32))
    assert np.all(np.abs(20.0 * np.log10(inner.gain)) <= 3.0) and set(inner.delay) <= {0, 1}
