"""The ``flight`` observation: IMU filters, the gyro's view of bending, bias drift, strapdown attitude.

Filters against their continuous transfer functions; the lever arm against hand numbers; a flexible
flight's gyro against the same filters run in Python on the recorded physics steps; the bias random walk's
variance over many rows; the strapdown attitude against the true one; batch against single envs,
seeding, snapshots and the Gymnasium / SB3 checkers.
"""

import math
import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from scipy import signal

import lvgym  # noqa: F401  (registers the envs)
from lvgym.envs import TaskSpec
from lvgym.envs.ascent import SmileAscentEnv
from lvgym.envs.functional import AscentFuncEnv
from lvgym.envs.layouts import FLIGHT_DRAWS, NAV, OBS_FLIGHT, OBS_SENSORS, OBSERVATIONS
from lvgym.rotations import quat_mul
from lvgym.simulator import PhysicsSpec, Simulator, TimelineSpec
from lvgym.simulator.imu import Imu, imu_output_k, lti_step_k, specific_force_k

H = 0.01


def test_the_flight_layout_is_the_sensors_layout_by_name_and_index():
    assert OBSERVATIONS["flight"] is OBS_FLIGHT
    assert OBS_FLIGHT.names == OBS_SENSORS.names and OBS_FLIGHT.size == OBS_SENSORS.size
    assert all(OBS_FLIGHT.offset(n) == OBS_SENSORS.offset(n) for n in OBS_FLIGHT.names)


def test_discrete_filters_are_the_continuous_ones_sampled():
    imu = Imu(-3.0, gyro_bandwidth_hz=50.0, gyro_damping=0.6, antialias_hz=20.0)
    cont, disc = imu.continuous(), imu.discrete(H)
    n = 40
    t = np.arange(n + 1) * H
    for name in ("gyro", "accel"):
        a, b, c = cont[name]
        ad, bd, cd = disc[name]
        # DC gain 1, continuous and discrete
        assert (-c @ np.linalg.solve(a, b))[0, 0] == pytest.approx(1.0, rel=1e-12)
        assert cd @ np.linalg.solve(np.eye(ad.shape[0]) - ad, bd) == pytest.approx(1.0, rel=1e-12)
        # a step held over the steps: the discrete response is the continuous one at the samples
        _, y_c = signal.step((a, b, c, np.zeros((1, 1))), T=t)
        x, tmp, y_d = np.zeros(ad.shape[0]), np.zeros(4), [0.0]
        for _ in range(n):
            lti_step_k(ad, bd, x, 1.0, tmp)                # the compiled step
            y_d.append(cd @ x)
        np.testing.assert_allclose(y_d, y_c, atol=1e-9)
    # the anti-aliasing Butterworth is -3 dB at antialias_hz; the sensor's 2nd order has 1 / (2 zeta) at w_n
    a, b, c = cont["accel"]
    _, resp = signal.freqresp((a, b, c, np.zeros((1, 1))), [2 * math.pi * 20.0])
    assert abs(resp[0]) == pytest.approx(1 / math.sqrt(2), rel=1e-9)
    a, b, c = cont["gyro"]
    _, g = signal.freqresp((a, b, c, np.zeros((1, 1))), [2 * math.pi * 50.0])
    aa = 1.0 / (1.0 - (50.0 / 20.0) ** 2 + 1j * math.sqrt(2) * 50.0 / 20.0)
    assert abs(g[0]) == pytest.approx(abs(aa) / (2 * 0.6), rel=1e-9)


def test_discrete_filters_are_scipys_zero_order_hold_to_the_bit():
    imu = Imu(-3.0, gyro_bandwidth_hz=50.0, gyro_damping=0.6, antialias_hz=20.0)
    for h in (1e-3, H, 0.02):
        disc = imu.discrete(h)
        for name, (a, b, c) in imu.continuous().items():
            ad, bd, cd, _, _ = signal.cont2discrete((a, b, c, np.zeros((1, 1))), h, method="zoh")
            for mine, theirs in zip(disc[name], (ad, bd[:, 0], cd[0])):
                np.testing.assert_array_equal(mine, theirs)


def test_an_env_does_not_import_scipy_signal():
    import subprocess
    import sys

    code = ("import sys, gymnasium as gym, lvgym; e = gym.make('lvgym/SmileAscent-v1'); e.reset(seed=0); "
            "print('scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "False", out.stdout + out.stderr


def test_discrete_filters_stay_stable_whatever_the_step():
    for h in (1e-4, 0.01, 0.05):
        for ad, _, _ in Imu(-1.0, gyro_bandwidth_hz=500.0, antialias_hz=200.0).discrete(h).values():
            assert np.abs(np.linalg.eigvals(ad)).max() < 1.0


def test_specific_force_lever_arm_hand_numbers():
    I3, out = np.eye(3), np.zeros(3)
    w, r = np.array([0.2, 0.1, 0.3]), np.array([2.0, 0.0, 0.0])
    # a constant rate: omega x (omega x r) = (wx^2 l - l |w|^2, wx wy l, wx wz l) = (-0.2, 0.04, 0.12)
    specific_force_k(np.zeros(3), np.zeros(3), I3, I3, w, w, H, r, out)
    np.testing.assert_allclose(out, [-0.2, 0.04, 0.12], atol=1e-15)
    # an angular acceleration of 10 rad/s^2 about z: omega_dot x r = (0, 10 * 2, 0), plus the mean rate's terms
    specific_force_k(np.zeros(3), np.zeros(3), I3, I3, np.zeros(3), np.array([0.0, 0.0, 0.1]), H, r, out)
    np.testing.assert_allclose(out, [-2.0 * 0.05 ** 2, 20.0, 0.0], atol=1e-12)
    # the CG's acceleration less gravity, into the body frame (a body turned 90 deg about z)
    C = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])       # C_ib
    specific_force_k(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, -9.8]), C, C, np.zeros(3), np.zeros(3), H,
                     r, out)
    np.testing.assert_allclose(out, [2.0, -1.0, 12.8], atol=1e-12)


def _flex_flight(n_steps=250, station=-2.5):
    """A flexible SMILE excited by gimbal doublets, stepped one physics step at a time; per step the
    body rate, modal rates, slopes at the IMU and the IMU's outputs."""
    imu = Imu(station)
    sim = Simulator("smile", "flex", timeline=TimelineSpec(t_end=5.0, sensor_stations=[station]),
                    physics=PhysicsSpec(H), imu=imu)
    d = sim.reset(1)
    K = sim.dynamics.n_modes
    rec = {"omega": [], "eta_dot": [], "dphi": [], "gyro": []}
    rate, force = np.zeros(3), np.zeros(2)

    def keep():
        rec["omega"].append(sim.state(d, "omega_bi_b")[0].copy())
        rec["eta_dot"].append(sim.state(d, "eta_dot")[0].copy())
        rec["dphi"].append(sim.timeline.left("dphi_sensor", d.t)[0, 0].copy())
        imu_output_k(sim.setup.imu, d.imu[0], rate, force)
        rec["gyro"].append(rate.copy())

    keep()
    for k in range(n_steps):
        sim.step(d, [[0.03 * np.sign(np.sin(k * 0.7)), 0.02 * np.sign(np.cos(k * 0.45))]], H)
        keep()
    return imu, sim, K, {k: np.array(v) for k, v in rec.items()}


def test_the_gyro_sees_the_slope_rate_through_its_filters():
    imu, sim, K, rec = _flex_flight()
    assert K > 0
    ad, bd, cd = imu.discrete(H)["gyro"]
    om, ed, dphi = rec["omega"], rec["eta_dot"], rec["dphi"]
    mean = lambda v: 0.5 * (v[:-1] + v[1:])           # noqa: E731  the step means
    body_in = mean(om)
    ey, ez = mean(ed[:, 0]), mean(ed[:, 1])            # y-plane and z-plane modal rates
    slope_in = np.zeros_like(body_in)                  # slope rate at the IMU (the slopes at the step's end)
    slope_in[:, 1] = -np.einsum("nk,nk->n", dphi[1:], ez)
    slope_in[:, 2] = np.einsum("nk,nk->n", dphi[1:], ey)

    def filtered(u, x0):
        out = np.zeros((len(u) + 1, 3))
        for a in range(3):
            x = np.zeros(ad.shape[0])
            x[0::2] = x0[a]                            # at rest: every stage's output at the input
            out[0, a] = cd @ x
            for n in range(len(u)):
                x = ad @ x + bd * u[n, a]
                out[n + 1, a] = cd @ x
        return out

    body = filtered(body_in, om[0])
    through = filtered(slope_in, np.zeros(3))
    seen = rec["gyro"] - body                          # what the gyro sees beyond the filtered body rate
    np.testing.assert_allclose(seen, through, rtol=0, atol=1e-10 * np.abs(rec["gyro"]).max())
    assert np.abs(through[:, 1:]).max() > 0.01 * np.abs(body[:, 1:]).max()


def test_on_the_pad_the_accelerometers_read_no_lateral_force_and_the_gyros_the_earth_rate():
    sim = Simulator("smile", "rigid", timeline=TimelineSpec(t_end=2.0, sensor_stations=[-2.0]), imu=Imu(-2.0))
    d = sim.reset(1)
    rate, force = np.zeros(3), np.zeros(2)
    imu_output_k(sim.setup.imu, d.imu[0], rate, force)
    np.testing.assert_allclose(rate, sim.state(d, "omega_bi_b")[0], atol=1e-15)
    assert np.abs(force).max() < 1e-3
    with pytest.raises(ValueError, match="physics_dt"):
        sim.step(d, [[0.0, 0.0]], 0.015)


def _func(**kw):
    opts = {"model": "rigid", "observation": "flight", "mission_time_s": 1.0, **kw}
    return AscentFuncEnv(TaskSpec.build(SmileAscentEnv.PRESET, opts))


def test_the_gyro_bias_drifts_as_a_random_walk():
    sigma, B = 2e-3, 300
    f = _func(randomize={"sensor_noise"}, gyro_bias_radps=0.0, gyro_bias_rw_radps_per_sqrt_s=sigma)
    rngs = [np.random.default_rng(1000 + b) for b in range(B)]
    state = f.initial(rngs)
    dt = f.spec.control_dt_s
    seen = {}
    for k in range(1, 51):
        state = f.transition(state, np.zeros((B, 2)), rngs, inplace=True)
        if k in (10, 25, 50):
            seen[k] = state.task.gyro_bias.copy()
    for k, b in seen.items():
        var = np.mean(b ** 2)                          # 900 samples: 1 sigma of the variance is 4.7 %
        assert var == pytest.approx(sigma ** 2 * k * dt, rel=0.15), k


def _rotvec_error(q_true, q_nav):
    """Rotation vector [rad] of ``q_true^-1 (x) q_nav`` (body frame)."""
    qi = q_true * np.array([1.0, -1.0, -1.0, -1.0])
    e = quat_mul(qi, q_nav)
    e = e if e[0] >= 0 else -e
    return 2.0 * e[1:]


def _attitude_flight(n, amp=1.0, **kw):
    f = _func(mission_time_s=n * 0.02 + 1.0, **kw)
    g = [np.random.default_rng(4)]
    state = f.initial(g)
    out = []
    for k in range(n):
        a = amp * np.array([[0.3 * math.sin(0.05 * k), 0.2 * math.cos(0.03 * k)]])
        state = f.transition(state, a, g, inplace=True)
        q_true = f.sim.layout.view(state.sim.x, "state", "q_bi")[0]
        w = f.sim.layout.view(state.sim.x, "state", "omega_bi_b")[0]
        lag = w * _TAU                                 # the filters' group delay times the rate
        err = _rotvec_error(q_true, NAV.view(state.task.nav, "q_nav")[0]) + lag
        out.append((state.sim.t[0], err, state.task.gyro_bias[0].copy()))
    return out


#: group delay of the default filters at low frequency [s]: 2 zeta / w_g + sqrt(2) / w_a
_TAU = 2 * 0.7 / (2 * math.pi * 80.0) + math.sqrt(2) / (2 * math.pi * 20.0)


def test_the_strapdown_attitude_is_the_true_one_without_bias_and_drifts_with_one():
    # without bias or noise the strapdown attitude is the true one but for the filters' lag (rate x
    # group delay, up to 5e-3 rad in this flight, taken out here) and the bending slope at the IMU
    # (the section at the IMU turns by the bending slope, phi' eta, a few 1e-4 rad here)
    for model, bound in (("rigid", 2.5e-4), ("flex", 4e-4)):
        clean = _attitude_flight(500, model=model)               # 10 s, gimbal moving, bending excited
        err = max(np.abs(e).max() for _, e, _ in clean)
        assert err < bound, (model, err)
    # a bias b drifts the attitude by b t (a flight without commands: the body turns little)
    biased = _attitude_flight(500, amp=0.0, randomize={"sensor_noise"}, gyro_bias_radps=1e-3,
                              gyro_arw_rad_per_sqrt_s=0.0, gyro_bias_rw_radps_per_sqrt_s=0.0, accel_noise_mps2=0.0)
    t, e, b = biased[-1]
    assert np.abs(b).min() > 1e-5
    np.testing.assert_allclose(e, b * t, atol=2e-4 + 0.05 * np.abs(b * t).max())


def test_flight_noise_draws_come_from_the_rows_generators():
    f = _func(randomize={"sensor_noise"})
    assert f._draw_sigma.size == sum(fl.size for fl in FLIGHT_DRAWS.fields)
    a = f.initial([np.random.default_rng(3), np.random.default_rng(4)])
    b = f.initial([np.random.default_rng(3)])
    np.testing.assert_array_equal(a.task.obs[0], b.task.obs[0])
    assert not np.array_equal(a.task.obs[0], a.task.obs[1])


OPTS = dict(model="nonrigid", wind="turbulence", randomize=True, observation="flight", mission_time_s=1.2,
            controller_on_after_s=0.2)


def test_flight_envs_pass_the_gymnasium_and_sb3_checkers():
    from stable_baselines3.common.env_checker import check_env as sb3_check_env
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", observation="flight", randomize=True).unwrapped
    gym_check_env(env, skip_render_check=True)
    sb3_check_env(env, warn=False)
    env.close()


def test_flight_vector_env_matches_single_envs_and_seeds_repeat():
    n, seed = 3, 11
    venv = gym.make_vec("lvgym/SmileAscent-v0", num_envs=n, vectorization_mode="vector_entry_point", **OPTS)
    singles = [gym.make("lvgym/SmileAscent-v0", **OPTS) for _ in range(n)]
    vobs, _ = venv.reset(seed=seed)
    np.testing.assert_array_equal(vobs, np.stack([e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]))
    rng = np.random.default_rng(0)
    for _ in range(55):
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        vobs, vrew, vterm, vtrunc, _ = venv.step(actions)
        for i, e in enumerate(singles):
            o, r, term, trunc, _ = e.step(actions[i])
            np.testing.assert_array_equal(vobs[i], o)
            assert vrew[i] == r and vterm[i] == term and vtrunc[i] == trunc
    again = gym.make_vec("lvgym/SmileAscent-v0", num_envs=n, vectorization_mode="vector_entry_point", **OPTS)
    np.testing.assert_array_equal(again.reset(seed=seed)[0], venv.reset(seed=seed)[0])
    assert not np.array_equal(again.reset(seed=seed + 1)[0], venv.reset(seed=seed)[0])


def test_flight_snapshot_replays_bit_for_bit():
    env = gym.make("lvgym/SmileAscent-v0", **OPTS)
    env.reset(seed=21)
    rng = np.random.default_rng(3)
    acts = [rng.uniform(-1, 1, 2).astype(np.float32) for _ in range(50)]
    for a in acts[:20]:
        env.step(a)
    snap = pickle.loads(pickle.dumps(env.unwrapped.get_state()))

    def fly():
        out = []
        for a in acts[20:]:
            o, r, term, trunc, info = env.step(a)
            out.append((o, r, term, trunc, info["attitude_error"]))
            if term or trunc:
                out.append(env.reset()[0])
        return out

    first = fly()
    env.unwrapped.set_state(snap)
    second = fly()
    for x, y in zip(first, second):
        for u, v in zip(x if isinstance(x, tuple) else (x,), y if isinstance(y, tuple) else (y,)):
            assert np.array_equal(np.asarray(u), np.asarray(v))
