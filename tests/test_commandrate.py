"""The command-rate training charge (lvgym/agents/wrappers/commandrate.py): hand numbers on a real batched env, the
flyability rule's own measure over a whole flight, its checks, and train.py's option that records it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lvgym.errors import ConfigError

KW = {"mission_time_s": 2.0, "controller_on_after_s": 0.2, "model": "rigid"}


def _pair(weight: float, seed: int = 3):
    """The same two-row env, bare and charged."""
    from lvgym.agents.wrappers.commandrate import command_rate_venv
    from lvgym.envs import make_sb3_vec_env

    bare = make_sb3_vec_env("lvgym/SmileAscent-v1", num_envs=2, seed=seed, **KW)
    charged = command_rate_venv(make_sb3_vec_env("lvgym/SmileAscent-v1", num_envs=2, seed=seed, **KW),
                                {"weight": weight})
    return bare, charged


def test_an_alternating_command_is_charged_by_hand_and_a_steady_one_not():
    bare, charged = _pair(0.9)
    bare.reset(), charged.reset()
    limit, rate_limit, dt = math.radians(5.0), math.radians(30.0), 0.02        # SMILE's gimbal, servo, period
    assert (charged.limit_rad, charged.rate_limit_radps, charged.dt) == pytest.approx((limit, rate_limit, dt))
    seen, before = 0, False
    for k in range(60):
        sign = 1.0 if k % 2 else -1.0
        a = np.array([[0.5 * sign, -0.5 * sign], [0.2, 0.2]])
        _, r0, _, _ = bare.step(a)
        _, r1, _, i1 = charged.step(a)
        both, before = bool(i1[0]["controller_on"]) and before, bool(i1[0]["controller_on"])
        # row 0 swings by 1.0 of the limit each step on both axes: (1.0 * limit / dt / R)^2 = 69.44
        want = 0.9 * (limit / dt / rate_limit) ** 2 * dt if both else 0.0
        assert i1[0]["command_rate_charge"] == pytest.approx(want, rel=1e-12)
        assert r1[0] == pytest.approx(r0[0] - want, abs=1e-5) and i1[1]["command_rate_charge"] == 0.0
        assert r1[1] == r0[1]
        seen += both
    assert seen >= 40 and 0.9 * 69.44 * 0.02 == pytest.approx(1.25, rel=1e-3)


def test_over_a_flight_the_charges_add_up_to_the_rules_rms():
    """sum of charges = weight * dt * (controlled steps) * cmd_rate_rms^2, with cmd_rate_rms as
    lvgym.benchmark.flyability measures the flight's commands."""
    from lvgym.benchmark.flyability import command_metrics

    _, charged = _pair(2.0, seed=11)
    charged.reset()
    rng = np.random.default_rng(0)
    commands, on, times, total = [], [], [], 0.0
    for _ in range(1000):
        a = rng.uniform(-1.3, 1.3, (2, 2))
        _, _, done, infos = charged.step(a)
        commands.append(np.clip(a[0], -1, 1) * charged.limit_rad)
        on.append(infos[0]["controller_on"]), times.append(infos[0]["time"])
        total += infos[0]["command_rate_charge"]
        if done[0]:
            break
    assert done[0]
    m = command_metrics(np.array(commands), np.array(on), np.array(times), charged.dt, charged.rate_limit_radps)
    n = int(np.sum(np.array(on[1:]) & np.array(on[:-1])))
    assert n > 50 and total == pytest.approx(2.0 * charged.dt * n * m["cmd_rate_rms"] ** 2, rel=1e-9)


def test_off_is_the_env_itself_and_a_bad_weight_names_its_key():
    from lvgym.agents.wrappers.commandrate import command_rate_options, command_rate_venv

    assert command_rate_options(0.0) is None and command_rate_options(0.5) == {"weight": 0.5}
    stub = object()
    assert command_rate_venv(stub, None) is stub
    with pytest.raises(ConfigError, match=r"command_rate_charge = -1\.0"):
        command_rate_options(-1.0)


def test_train_records_the_charge_and_trains_with_it(tmp_path, capsys):
    import yaml

    from lvgym.agents.training.train import main

    main(["--suite", "smile-v2-faults", "--residual", "lqg-front", "--residual-scale", "0.1",
          "--command-rate-charge", "0.9", "--total-timesteps", "256", "--n-envs", "2", "--hp", "algo.n_steps=128",
          "algo.batch_size=64", "--eval-freq", "0", "--env-kwargs", "mission_time_s=3", "--runs-dir", str(tmp_path),
          "--name", "cr", "--no-progress"])
    config = yaml.safe_load((tmp_path / "cr" / "config.yaml").read_text())
    assert config["command_rate"] == {"weight": 0.9}
    assert (tmp_path / "cr" / "final_model.zip").is_file()
    with pytest.raises(SystemExit):
        main(["--command-rate-charge", "-2", "--total-timesteps", "256", "--runs-dir", str(tmp_path), "--name", "bad"])
    assert "--command-rate-charge = -2.0: a number in [0.0, 100.0]" in capsys.readouterr().err
