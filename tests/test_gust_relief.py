"""The gust-relief study (experiments.gust_relief): its laws against hand numbers and a short sweep."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.gust_relief.laws import SoftLaw, hold, released_schedule
from experiments.gust_relief.sweep import VARIANTS, main, specs
from lvgym.baselines.lqg import LQGSchedule
from lvgym.benchmark import get_suite
from lvgym.errors import ConfigError


def test_the_relief_factor_by_hand():
    assert hold(0.4, 0.5, 0.9) == 1.0 and hold(0.7, 0.5, 0.9) == pytest.approx(0.5)
    assert hold(0.95, 0.5, 0.9) == 0.0


def test_the_soft_law_by_hand():
    """On the flight computer's signals: delta = (J / (s T l)) (-2 zeta w e_rate - w^2 e_att - ki w^3 int e_att),
    the integral frozen above q_off."""
    cond = get_suite("smile-v2-maxq-gust").conditions[0].with_options(privileged_info=True)
    env = cond.make_env()
    law = SoftLaw(env, w=2.0, z=1.0, ki=0.5, q_off=5e4)
    obs, info = env.reset(seed=0)
    assert np.all(law.act(obs, info) == 0.0)                 # the reset's info holds no flight terms
    obs, _, _, _, info = env.step(np.zeros(2, np.float32))
    names = list(env.unwrapped.func.observation_layout.names)
    obs = obs.copy()
    obs[names.index("pitch_rate_error")], obs[names.index("pitch_attitude_error")] = 0.01, 0.02
    obs[names.index("yaw_rate_error")], obs[names.index("yaw_attitude_error")] = 0.0, -0.01
    lever = info["thrust"] * info.get("vectored_share", 1.0) * info["gimbal_arm"]
    J = np.asarray(info["J_b_diag"])[1:]
    dt, limit = law.dt, law.limit
    integral = dt * np.array([0.02, -0.01])
    want = J * (-4.0 * np.array([0.01, 0.0]) - 4.0 * np.array([0.02, -0.01]) - 0.5 * 8.0 * integral) / lever / limit
    np.testing.assert_allclose(law.act(obs, dict(info, qbar=1e4)), want, rtol=1e-5)
    np.testing.assert_allclose(law.act(obs, dict(info, qbar=1e5)),             # frozen: the same integral
                               J * (-4.0 * np.array([0.01, 0.0]) - 4.0 * np.array([0.02, -0.01])
                                    - 0.5 * 8.0 * integral) / lever / limit, rtol=1e-5)


def test_a_released_schedule_changes_its_rows_only(tmp_path):
    path = released_schedule("smile_lqg", (2, 3), 0.0, 1.0, tmp_path / "r.npz")
    base, mine = LQGSchedule.load("smile_lqg"), LQGSchedule.load(path)
    for plane in ("pitch", "yaw"):
        for i, (a, b) in enumerate(zip(base.rows[plane], mine.rows[plane])):
            if i in (2, 3):
                assert b.Ki == 0.0 and b.a == pytest.approx(np.exp(-0.02))
            else:
                assert (b.Ki, b.a) == (a.Ki, a.a)
            np.testing.assert_array_equal(a.Kx, b.Kx)


def test_a_short_sweep(capsys):
    with pytest.raises(ConfigError, match="variants"):
        specs(["no-such-law"])
    assert set(VARIANTS) >= {"gs-pd-relief", "lqg-front", "pd-w2-z1"}
    main(["--seeds", "1", "--variants", "pd-w2-z1", "lqg-front-faded-0.5-0.9", "--suites", "smile-v2-maxq-gust"])
    out = capsys.readouterr().out
    assert "| pd-w2-z1 | " in out and "| lqg-front-faded-0.5-0.9 | " in out
