"""The linear headroom study (experiments.lqg_headroom.headroom): the Dryden filter against the specification's spectrum, the
delay margin against hand numbers, the shipped lqg row designed again, and the trade at the 10 s row."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from experiments.lqg_headroom import headroom as hr
from lvgym.environment.turbulence import dryden_psd


def discrete_psd(A, Q, C, dt, w):
    """One-sided PSD [(m/s)^2 per rad/s] of y = C x, x_{k+1} = A x_k + noise of covariance Q, sampled at dt
    (its integral over 0 .. pi / dt is the variance)."""
    out = []
    for wi in w:
        z = np.exp(1j * wi * dt)
        H = C @ np.linalg.inv(z * np.eye(A.shape[0]) - A)
        out.append(dt / math.pi * (H @ Q @ H.conj().T).real.item())
    return np.array(out)


def test_dryden_filter_has_the_specified_variance_and_spectrum():
    turb = hr.Turbulence(sigma=3.2, length=533.4, speed=286.0, altitude=1400.0)
    A, Q, C = hr.dryden_filter(turb, 0.02)
    import scipy.linalg as sla
    var = (C @ sla.solve_discrete_lyapunov(A, Q) @ C.T).item()
    assert var == pytest.approx(3.2 ** 2, rel=1e-9)
    w = np.array([0.05, 0.5, 3.0])                     # rad/s, far below the 157 rad/s Nyquist frequency
    spec = dryden_psd(w / turb.speed, turb.sigma, turb.length, "v") / turb.speed   # MIL-F-8785C, per rad/s
    np.testing.assert_allclose(discrete_psd(A, Q, C, 0.02, w), spec, rtol=0.01)


def test_delay_margin_of_a_hand_loop():
    """L = (wc / w) exp(-j (pi/2 + w tau0)): crossover at wc with phase margin pi/2 - wc tau0, so the delay
    margin is (pi/2) / wc - tau0; a crossover of negative phase margin counts the lag to -540 deg."""
    w = np.logspace(-2, 2, 20001)
    r = (2.0 / w) * np.exp(-1j * (math.pi / 2 + w * 0.1))
    assert hr.delay_margin_s(r, w) == pytest.approx(math.pi / 4 - 0.1, rel=1e-4)            # 0.685 s
    r2 = (2.0 / w) * np.exp(-1j * math.radians(200.0)) * np.ones_like(w)                    # PM -20 deg at 2 rad/s
    assert hr.delay_margin_s(r2, w) == pytest.approx(math.radians(340.0) / 2.0, rel=1e-4)
    assert hr.delay_margin_s(0.5 * np.ones_like(w, dtype=complex), w) == math.inf


def test_candidates_keep_the_weights_not_varied():
    row = hr.shipped_row(10.0)
    cands = hr.candidates({"q_int": (1.0, 2.0), "wind_noise": (0.0, 0.5)}, row.weights)
    assert [(c[0].q_int, c[1]) for c in cands] == [(1.0, 0.0), (1.0, 0.5), (2.0, 0.0), (2.0, 0.5)]
    assert all(c[0].r_gimbal == row.weights.r_gimbal and c[0].w_modes == row.weights.w_modes for c in cands)


def test_no_worse_counts_every_margin():
    base = {"gm_nonrigid": 6.0, "gm_rigid": 9.0, "grm_nonrigid": -10.0, "dm_nonrigid_ms": 150.0, "dm_rigid_ms": 150.0}
    assert hr.no_worse(dict(base), base)
    assert not hr.no_worse({**base, "grm_nonrigid": -9.0}, base)            # closer to 0 dB: worse
    assert hr.no_worse({**base, "grm_nonrigid": -12.0, "gm_rigid": 10.0}, base)
    assert not hr.no_worse({**base, "dm_rigid_ms": 149.0}, base)
    worse = {**base, "gm_nonrigid": 5.0, "grm_nonrigid": -9.0, "dm_nonrigid_ms": 90.0}
    assert hr.no_worse(worse, base, slack_db=1.0, dm_fraction=0.6)
    assert not hr.no_worse(worse, base, slack_db=0.9, dm_fraction=0.6)
    assert not hr.no_worse(worse, base, slack_db=1.0, dm_fraction=0.61)


@pytest.fixture(scope="module")
def row10():
    return hr.headroom(10.0, hr.GRIDS["small"], log=lambda s: None)


def test_shipped_weights_give_the_shipped_row(row10):
    """The shipped weights designed again on today's plant are the shipped row (the study compares like with like)."""
    w = hr.shipped_row(10.0).weights
    same = [d for d in row10["designs"] if d["wind_noise"] == 0.0 and d["q_int"] == w.q_int and d["r_gimbal"] == w.r_gimbal]
    assert len(same) == 1
    assert same[0]["ratio_nonrigid"] == pytest.approx(1.0, rel=1e-6)
    for k in hr.MARGINS:
        assert same[0][k] == pytest.approx(row10["base"][k], rel=1e-6)
    assert row10["base"]["shortfall"] == 0.0                                # the shipped row meets its targets


def test_the_10_s_row_trades_rate_error_for_margin(row10):
    """At the 10 s row (boost), under the v1 turbulence (3.2 m/s at 1.4 km): the shipped row's body-rate RMS is
    0.0145 rad/s; no design of the small grid lowers it without losing a margin, and with 2 dB of gain margin
    and 40 % of the delay margin given up it falls by 18 % (q_int 1000, r 30: 5.0 dB non-rigid gain margin
    against 6.2, 115 ms of delay margin against 152), no further at 3 dB and 60 %."""
    b = row10["base"]
    assert b["rate_rms_nonrigid"] == pytest.approx(0.0145, abs=5e-4)
    ratios = {(s["slack_db"], s["dm_fraction"]): s["design"]["ratio_nonrigid"] for s in row10["best"] if s["design"]}
    assert ratios[(0.0, 1.0)] == pytest.approx(1.0, rel=1e-6)
    assert min(r for (db, _), r in ratios.items() if db <= 2.0) > 0.7
    assert ratios[(3.0, 0.4)] == pytest.approx(0.815, abs=0.005)
    assert "| 10 | 0.0145; 6.2 / 9.0 / -10.6; 152 / 151 | 6 | 1.000 (q_int 100, r 10, wind 0) |" in hr.headroom_table([row10])


@pytest.mark.slow
def test_full_grid():
    """The study's grid at the rows of 10, 20 and 28.8 s (865 stable designs, about 12 minutes): with every
    margin no worse than the shipped row's, the turbulence's rate RMS falls by 5 % at 10 s and not at all at 20
    and 28.8 s; with 2 dB of gain margin and 40 % of the delay margin given up, by at most a fifth; at 20 and
    28.8 s not by 30 % even with 3 dB and 60 % given up (docs/training.md's table)."""
    best = {}
    for t in (10.0, 20.0, 28.8):
        r = hr.headroom(t, hr.GRIDS["full"], log=lambda s: None)
        best[t] = {(s["slack_db"], s["dm_fraction"]): s["design"]["ratio_nonrigid"] for s in r["best"]}
    assert best[10.0][(0.0, 1.0)] == pytest.approx(0.954, abs=0.005)
    assert best[20.0][(0.0, 1.0)] == pytest.approx(1.0, abs=1e-6) and best[28.8][(0.0, 1.0)] == pytest.approx(1.0, abs=1e-6)
    assert min(b[(2.0, 0.6)] for b in best.values()) > 0.8
    assert best[20.0][(3.0, 0.4)] > 0.8 and best[28.8][(3.0, 0.4)] > 0.75


def test_command_line_refuses_a_time_that_is_not_a_row():
    out = subprocess.run([sys.executable, "-m", "experiments.lqg_headroom.headroom", "--rows", "11"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode != 0
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "--rows = 11" in lines[0], out.stderr


def test_front_schedule_replaces_only_the_studied_row(row10, tmp_path):
    """The written schedule holds row 10's best design within -2 dB / 60 % in both planes and every other row
    as shipped; the lqg law flies it, and its boost differs from the shipped law's once the row is in use (6.5 s)."""
    from lvgym.baselines.lqg import LQGSchedule
    from lvgym.benchmark.runner import PolicySpec, run_episode
    from lvgym.benchmark.suites import get_suite

    path = tmp_path / "front.npz"
    chosen = hr.front_schedule([row10], 2.0, 0.6, path)
    assert (chosen[10.0]["q_int"], chosen[10.0]["r_gimbal"], chosen[10.0]["wind_noise"]) == (1000.0, 30.0, 0.0)
    new, old = LQGSchedule.load(path), LQGSchedule.load("smile_lqg")
    for plane in ("pitch", "yaw"):
        for i, (a, b) in enumerate(zip(new.rows[plane], old.rows[plane])):
            same = a.Kx.shape == b.Kx.shape and np.array_equal(a.Kx, b.Kx) and np.array_equal(a.M, b.M)
            assert same == (i != 1), (plane, i)                                 # row 1 is the 10 s row
            assert a.interval_s == b.interval_s
    cond = next(c for c in get_suite("smile-v1").conditions if c.model == "nonrigid").with_options(mission_time_s=8.0)
    front = PolicySpec("lqg-front", "lvgym.baselines.lqg:smile_lqg", (("name", "lqg-front"), ("schedule", str(path))))
    shipped = PolicySpec("lqg", "lvgym.baselines.lqg:smile_lqg", (("name", "lqg"),))
    a, b = run_episode(front, cond, 0), run_episode(shipped, cond, 0)
    assert a["rate_error_boost_rad"] != b["rate_error_boost_rad"] and not a["failed"]
