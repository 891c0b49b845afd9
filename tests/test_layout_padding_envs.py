"""The whole stack with every internal layout padded flies the same episodes, bit for bit.

``LVGYM_LAYOUT_PADDING=1`` puts an unused entry in front of every field of every internal layout (the
dynamics state, parameters and loads, the simulator's context, flight conditions, rail, servo and
actuator, the task parameters): every offset moves. A kernel, accessor or controller that worked an
offset out by hand instead of taking it from its layout would then read the wrong entry. A subprocess
with padding (and a fresh numba cache, so that every kernel is compiled with the padded offsets) flies
the envs below and must give exactly what this process gives. The observation and the reward terms are
interfaces and are never padded.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def fly_all() -> dict[str, np.ndarray]:
    """Episodes of every env id through the public API (the same in both processes)."""
    import gymnasium as gym

    import lvgym  # noqa: F401
    from lvgym.baselines.pid import smile_scheduled_pid

    out: dict[str, np.ndarray] = {}

    def run(tag, env, policy, n):
        obs, info = env.reset(seed=4)
        policy.reset()
        rows = []
        for _ in range(n):
            obs, r, term, trunc, info = env.step(policy.act(obs, info))
            rows.append(np.concatenate([obs, [r, term, trunc], info["cumulative_rate_error"], info["rate_error"],
                                        [info["qbar"], info["mach"], info["qalpha_pa_deg"], info["mass"],
                                         info["effort_rad_s"]], info["gimbal"], np.ravel(info["eta"]),
                                        np.nan_to_num(np.ravel(info["slosh_angles"]), nan=-7.0)]))
            if term or trunc:
                obs, info = env.reset()
        out[tag] = np.array(rows)

    smile = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="turbulence", randomize=True,
                     observation="sensors", mission_time_s=3.0)
    run("smile", smile, smile_scheduled_pid(smile, "smile"), 200)
    v1 = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="turbulence", mission_time_s=3.0,
                  mode_interval_s=1.0, mode_basis="projected", slosh_frequency="specific_force")
    run("smile-modes", v1, smile_scheduled_pid(v1, "smile"), 150)        # changes of basis at 1 and 2 s
    flight = gym.make("lvgym/SmileAscent-v0", model="nonrigid", wind="turbulence", randomize=True,
                      observation="flight", mission_time_s=2.0)
    run("flight", flight, smile_scheduled_pid(flight, "smile"), 120)
    from lvgym.baselines.bangbang import BangBangRollPolicy
    run("stratos", gym.make("lvgym/StratosIII-v0", model="nonrigid", wind="profile", mission_time_s=2.0),
        BangBangRollPolicy(0.2), 120)
    slender = gym.make("lvgym/SlenderAscent-v0", model="nonrigid", wind="turbulence", randomize=True,
                       mission_time_s=1.5)
    run("slender", slender, smile_scheduled_pid(slender, "smile"), 100)
    flexible = gym.make("lvgym/SlenderAscent-v0", model="nonrigid", wind="turbulence", mission_time_s=1.0,
                        aeroelastic=True)
    run("slender_aeroelastic", flexible, smile_scheduled_pid(flexible, "smile"), 50)
    venv = gym.make_vec("lvgym/SmileAscent-v0", num_envs=3, vectorization_mode="vector_entry_point",
                        model="flex", wind="random", randomize=True, mission_time_s=1.0)
    obs, _ = venv.reset(seed=2)
    rows = []
    for k in range(80):
        obs, r, term, trunc, info = venv.step(np.full((3, 2), 0.4 * np.sin(0.1 * k), np.float32))
        rows.append(np.concatenate([obs.ravel(), r, info["cumulative_rate_error"].ravel()]))
    out["vector"] = np.array(rows)
    return out


def test_padded_layouts_fly_the_same_episodes(tmp_path):
    import lvgym.packing
    assert not lvgym.packing.PADDING, "run the test suite without LVGYM_LAYOUT_PADDING"
    ref = fly_all()
    script = (f"import sys, numpy as np; sys.path.insert(0, {str(HERE)!r}); import lvgym.packing as p; "
              "assert p.PADDING; from test_layout_padding_envs import fly_all; "
              f"np.savez({str(tmp_path / 'padded.npz')!r}, **fly_all())")
    env = {**os.environ, "LVGYM_LAYOUT_PADDING": "1", "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stderr[-4000:]
    padded = np.load(tmp_path / "padded.npz")
    assert set(padded) == set(ref)
    for key, value in ref.items():
        np.testing.assert_array_equal(padded[key], value, err_msg=key)
