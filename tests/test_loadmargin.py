"""The load-margin training charge (lvgym/agents/wrappers/loadmargin.py): hand numbers on a stub VecEnv, its checks,
and train.py's option that records it and flies it."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv

from lvgym.errors import ConfigError


class _Stub(VecEnv):
    """Two rows whose step infos hold the given loads and limits; reward 1 each."""

    def __init__(self, loads, limits):
        super().__init__(2, spaces.Box(-1, 1, (1,), np.float32), spaces.Box(-1, 1, (2,), np.float32))
        self.loads, self.limits = loads, limits

    def reset(self):
        return np.zeros((2, 1), np.float32)

    def step_async(self, actions):
        pass

    def step_wait(self):
        infos = [{"qalpha_pa_deg": q, "qalpha_limit_pa_deg": lim} for q, lim in zip(self.loads, self.limits)]
        return np.zeros((2, 1), np.float32), np.ones(2, np.float32), np.zeros(2, bool), infos

    def close(self):
        pass

    def get_attr(self, attr_name, indices=None):
        return [None, None]

    def set_attr(self, attr_name, value, indices=None):
        pass

    def env_method(self, method_name, *args, indices=None, **kwargs):
        return [None, None]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False, False]


def test_the_charge_is_the_weight_times_the_ratio_above_the_threshold_times_the_period():
    from lvgym.agents.wrappers.loadmargin import load_margin_venv

    venv = load_margin_venv(_Stub([237_500.0, 150_000.0], [250_000.0, 250_000.0]),
                            {"weight": 2.0, "threshold": 0.8}, 0.02)
    venv.reset()
    _, rewards, _, infos = venv.step(np.zeros((2, 2), np.float32))
    # row 0: ratio 0.95, 2.0 * 0.15 * 0.02 = 0.006; row 1: ratio 0.6, below the threshold
    assert rewards[0] == pytest.approx(1.0 - 0.006, abs=1e-7) and rewards[1] == 1.0
    assert infos[0]["load_margin_charge"] == pytest.approx(0.006) and infos[1]["load_margin_charge"] == 0.0


def test_no_limit_no_charge_and_off_is_the_env_itself():
    from lvgym.agents.wrappers.loadmargin import load_margin_options, load_margin_venv

    stub = _Stub([1e9, 1e9], [0.0, float("inf")])
    venv = load_margin_venv(stub, {"weight": 1.0, "threshold": 0.5}, 0.02)
    venv.reset()
    assert (venv.step(np.zeros((2, 2), np.float32))[1] == 1.0).all()
    assert load_margin_options(0.0) is None and load_margin_venv(stub, None, 0.02) is stub
    assert load_margin_options(1.5, 0.7) == {"weight": 1.5, "threshold": 0.7}


@pytest.mark.parametrize("weight, threshold, key", [(-1.0, 0.8, "load_margin"), (1.0, 1.5, "load_margin_threshold")])
def test_a_bad_value_names_its_key(weight, threshold, key):
    from lvgym.agents.wrappers.loadmargin import load_margin_options

    with pytest.raises(ConfigError, match=key):
        load_margin_options(weight, threshold)


def test_train_records_the_charge_and_trains_with_it(tmp_path):
    import yaml

    from lvgym.agents.training.train import main

    main(["--suite", "smile-v2-faults", "--residual", "lqg-front", "--residual-scale", "0.1", "--load-margin", "1.0",
          "--total-timesteps", "256", "--n-envs", "2", "--hp", "algo.n_steps=128", "algo.batch_size=64",
          "--eval-freq", "0", "--env-kwargs", "mission_time_s=3", "--runs-dir", str(tmp_path), "--name", "lm",
          "--no-progress"])
    config = yaml.safe_load((tmp_path / "lm" / "config.yaml").read_text())
    assert config["load_margin"] == {"weight": 1.0, "threshold": 0.8}
    assert (tmp_path / "lm" / "final_model.zip").is_file()
    with pytest.raises(SystemExit, match="load_margin"):
        main(["--load-margin", "-2", "--total-timesteps", "256", "--runs-dir", str(tmp_path), "--name", "bad"])
