"""Dispersions of protocol v1: the load dispersions in the compiled flight conditions against hand
arithmetic, and each randomisation name acting on what it names."""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.envs.spec import RANDOMIZE, RANDOMIZE_V0, TaskSpec
from lvgym.simulator import Simulator, TimelineSpec
from lvgym.simulator import data as simdata
from lvgym.simulator.layouts import CONDITIONS, CONTEXT, DISPERSION


def _conditions():
    sim = Simulator("smile", "rigid", timeline=TimelineSpec(t_end=5.0))
    d = sim.reset(1, rng=np.random.default_rng(0))
    for _ in range(150):                          # 3 s: off the pad, with an angle of attack from the kick
        sim.step(d, np.array([[0.01, -0.005]]), 0.02)
    return sim, d


def test_load_dispersions_scale_the_forces_and_move_the_centre_of_pressure():
    sim, d = _conditions()
    kn, ka, ks, dx = 1.07, 0.95, 1.02, 0.3
    disp = DISPERSION.pack({"thrust_scale": ks, "normal_scale": kn, "axial_scale": ka, "cp_shift": dx})
    # the same state and time (a copy of the rows), conditions recomputed with the dispersions
    e = simdata.take(d)
    CONTEXT.view(e.ctx[:, :CONTEXT.size], "dispersion")[0] = disp
    sim.update_conditions(e)
    view = lambda c, k: CONDITIONS.view(c, k)            # noqa: E731
    f0, m0 = view(d.conditions[0], "f_aero_b"), view(d.conditions[0], "m_aero_b")
    f1, m1 = view(e.conditions[0], "f_aero_b"), view(e.conditions[0], "m_aero_b")
    assert abs(f0[2]) > 10.0 and abs(f0[1]) > 1.0       # a normal force to act on
    np.testing.assert_allclose(f1, [ka * f0[0], kn * f0[1], kn * f0[2]], rtol=1e-12)
    np.testing.assert_allclose(m1, [m0[0], kn * m0[1] - dx * kn * f0[2], kn * m0[2] + dx * kn * f0[1]], rtol=1e-12)
    t0, t1 = view(d.conditions[0], "thrust")[0], view(e.conditions[0], "thrust")[0]
    assert t1 == pytest.approx(ks * t0, rel=1e-12)


def test_randomize_true_keeps_the_v0_set():
    spec = TaskSpec.build(None, {"vehicle": "smile", "randomize": True})
    assert spec.randomize == frozenset(RANDOMIZE_V0)
    assert set(RANDOMIZE) - set(RANDOMIZE_V0) == {"aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency",
                                                  "bending_damping", "servo_bandwidth", "servo_delay",
                                                  "imu_station", "fault"}


@pytest.mark.parametrize("name", ["aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency", "bending_damping"])
def test_each_v1_randomisation_draws_what_it_names(name):
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", mission_time_s=1.0, randomize=[name]).unwrapped
    func = env.func
    scale, offset, mis, loads, servo, station, fault = func.dispersions(np.random.default_rng(5))
    assert not fault.any()
    again = func.dispersions(np.random.default_rng(5))
    assert station == 0.0
    for a, b in zip((scale, offset, mis, loads, servo), again):
        np.testing.assert_array_equal(a, b)                       # seeded
    neutral = DISPERSION.pack({"thrust_scale": 1.0, "normal_scale": 1.0, "axial_scale": 1.0})
    lay = func.sim.layout
    changed_params = set(np.flatnonzero(scale != 1.0))
    assert not offset.any() and not mis.any()
    n_slosh = func.sim.dynamics.n_slosh
    np.testing.assert_array_equal(servo, [1.0, 0.0])
    if name == "aerodynamics":
        assert not changed_params
        changed = {DISPERSION.names[i] for i in np.flatnonzero(loads != neutral)}
        assert changed == {"normal_scale", "axial_scale", "cp_shift"}
        assert abs(loads[DISPERSION.index("cp_shift")]) <= 0.75 * 1.1
    elif name == "thrust_level":
        assert not changed_params
        assert 0.97 <= loads[DISPERSION.index("thrust_scale")] <= 1.03 != loads[DISPERSION.index("thrust_scale")]
    else:
        np.testing.assert_array_equal(loads, neutral)
        want = {"slosh_mass": ["m"], "slosh_frequency": ["length", "omega"], "bending_damping": None}[name]
        if want is None:
            expect = set(np.arange(lay.n_p)[lay.params["zeta_modes"]])
        else:
            expect = {i for j in range(n_slosh) for w in want for i in np.arange(lay.n_p)[lay.slosh_param(j, w)]}
        assert changed_params == expect
        if name == "slosh_frequency":                              # L / f^2 and omega x f: one f
            j = lay.slosh_param(0, "length").start, lay.slosh_param(0, "omega").start
            assert scale[j[0]] == pytest.approx(scale[j[1]] ** -2)


def test_v1_randomisations_change_the_flight():
    def fly(randomize):
        env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", mission_time_s=4.0, randomize=randomize)
        env.reset(seed=2)
        for _ in range(200):
            obs, *_ = env.step(np.zeros(2, np.float32))
        return obs
    base = fly([])
    for name in ("aerodynamics", "thrust_level"):
        assert not np.array_equal(fly([name]), base), name


def _servo_after_one_period(servo_dispersion):
    from lvgym.simulator.servo import Servo
    sim = Simulator("smile", "rigid", timeline=TimelineSpec(t_end=2.0), servo=Servo(15.0, 0.7))
    d = sim.reset(1, rng=np.random.default_rng(0), servo_dispersion=servo_dispersion)
    sim.step(d, np.array([[0.01, 0.0]]), 0.02)           # two physics steps of 10 ms
    first = sim.gimbal(d)[0, 0]
    sim.step(d, np.array([[0.01, 0.0]]), 0.02)
    return first, sim.gimbal(d)[0, 0]


def test_servo_dispersions_against_hand_numbers():
    h, w, c = 0.01, 15.0, 0.01
    # semi-implicit Euler from rest: one step gives rate h w^2 c and position h^2 w^2 c
    first_step = h * h * w * w * c
    delayed, _ = _servo_after_one_period([[1.0, 1.0]])   # the first step follows the previous command (0)
    assert delayed == pytest.approx(first_step, rel=1e-12)
    nominal, nominal2 = _servo_after_one_period(None)
    assert nominal > delayed
    fast, _ = _servo_after_one_period([[2.0, 0.0]])
    r1, p1 = h * (2 * w) ** 2 * c, h * h * (2 * w) ** 2 * c
    r2 = r1 + h * ((2 * w) ** 2 * (c - p1) - 2.0 * 0.7 * (2 * w) * r1)
    assert fast == pytest.approx(p1 + h * r2, rel=1e-12)
    same, same2 = _servo_after_one_period([[1.0, 0.0]])
    assert (same, same2) == (nominal, nominal2)            # neutral dispersion: bit for bit
    with pytest.raises(ValueError, match="servo_dispersion"):
        _servo_after_one_period([[1.0, 0.5]])


@pytest.mark.parametrize("name", ["servo_bandwidth", "servo_delay"])
def test_servo_randomisations_draw_what_they_name(name):
    env = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=1.0, randomize=[name]).unwrapped
    draws = np.array([env.func.dispersions(np.random.default_rng(s))[4] for s in range(200)])
    if name == "servo_bandwidth":
        assert np.all(draws[:, 1] == 0.0) and 0.7 <= draws[:, 0].min() < 1.0 < draws[:, 0].max() <= 1.3
        assert draws[:, 0].std() == pytest.approx(0.1, rel=0.2)
    else:
        assert np.all(draws[:, 0] == 1.0) and set(draws[:, 1]) == {0.0, 1.0}


def test_slosh_frequency_dispersion_counts_once_with_the_specific_force_damper():
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", mission_time_s=1.0, randomize=["slosh_frequency"],
                   slosh_frequency="specific_force").unwrapped
    scale = env.func.dispersions(np.random.default_rng(5))[0]
    lay = env.func.sim.layout
    length, omega = lay.slosh_param(0, "length").start, lay.slosh_param(0, "omega").start
    assert scale[length] != 1.0 and scale[omega] == 1.0        # sqrt(|a_x| / L) already carries f


# ------------------------------------------------------------------------------ the IMU station
def _imu_env(randomize, model="rigid", **kw):
    return gym.make("lvgym/SmileAscent-v1", model=model, randomize=randomize, **kw).unwrapped.func


def test_imu_station_draw_law_and_determinism():
    from lvgym.envs.spec import IMU_STATION_SIGMA
    func = _imu_env(["imu_station"])
    sigma = IMU_STATION_SIGMA * func.vehicle.length                   # 8.25 cm on SMILE
    draws = np.array([func.dispersions(np.random.default_rng(s))[5] for s in range(4000)])
    assert np.all(np.abs(draws) <= 3.0 * sigma + 1e-15) and np.abs(draws).max() > 2.5 * sigma
    assert draws.std() == pytest.approx(sigma, rel=0.05)
    assert abs(draws.mean()) < 4.0 * sigma / np.sqrt(draws.size)
    again = np.array([func.dispersions(np.random.default_rng(s))[5] for s in range(20)])
    np.testing.assert_array_equal(again, draws[:20])                   # seeded
    scale, offset, mis, loads, servo, _, _ = func.dispersions(np.random.default_rng(1))
    assert np.all(scale == 1.0) and not offset.any() and not mis.any()  # it draws nothing else
    np.testing.assert_array_equal(servo, [1.0, 0.0])
    # the tabulated stations cover the clipped range, evenly, the nominal one among them
    st = func.timeline.sensor_stations
    around = np.sort(np.append(st[list(func.sim.imu.probes)], st[0])) - func.imu
    assert around[0] == pytest.approx(-3.0 * sigma) and around[-1] == pytest.approx(3.0 * sigma)
    np.testing.assert_allclose(np.diff(around), 6.0 * sigma / 24, rtol=1e-9)
    # a draw clipped at the range's end lands on the last tabulated station (not outside by round-off)
    ends = func.sim.imu.placement(np.array([-3.0 * sigma, 3.0 * sigma]), st)
    from lvgym.simulator.layouts import IMU_STATION
    lo = IMU_STATION.view(ends, "station_lo")[:, 0].astype(int)
    np.testing.assert_allclose(st[lo], func.imu + np.array([-3.0, 3.0]) * sigma, atol=1e-9)


def test_imu_station_switched_off_or_without_an_imu_is_nominal():
    from lvgym.simulator.layouts import IMU_STATE
    func = _imu_env(["mass"])
    assert func.dispersions(np.random.default_rng(3))[5] == 0.0
    assert func.sim.imu.probes == () and func.timeline.sensor_stations.size == 22
    state = func.initial([np.random.default_rng(s) for s in range(3)])
    block = IMU_STATE.view(state.sim.imu, "station")
    np.testing.assert_array_equal(block, 0.0)          # shift 0, lo = hi = the IMU's sensor 0, weight 0
    # v0's observations have no IMU dynamics: not drawn, the generator untouched
    v0 = gym.make("lvgym/SmileAscent-v0", model="rigid", observation="sensors", randomize=["imu_station"]).unwrapped
    g = np.random.default_rng(7)
    before = g.bit_generator.state
    assert v0.func.dispersions(g)[5] == 0.0 and g.bit_generator.state == before
    assert v0.func.timeline.sensor_stations.size == 22


def test_imu_station_interpolation_against_timelines_built_at_the_station():
    from lvgym.envs.functional import RENDER_STATIONS
    from lvgym.simulator import build_timeline
    from lvgym.simulator.imu import station_modes_k
    from lvgym.simulator.layouts import IMU_STATE
    from lvgym.vehicle import MassModel
    func = _imu_env(["imu_station"], model="nonrigid", mission_time_s=3.0)
    tl, imu = func.timeline, func.sim.imu
    K = tl.dynamics.n_modes
    assert K == 2
    mm = MassModel(func.vehicle)
    stations = tl.sensor_stations
    spacing = stations[imu.probes[1]] - stations[imu.probes[0]]

    def interpolated(shift):
        row = IMU_STATE.zeros(1)
        IMU_STATE.view(row, "station")[:] = imu.placement(np.array([shift]), stations)
        phi, dphi = np.zeros(K), np.zeros(K)
        out = np.zeros((tl.t.size, 2, K))
        for j in range(tl.t.size):
            station_modes_k(row[0], tl.tables, j, phi, dphi)
            out[j] = phi, dphi
        return out

    # exact at a tabulated station
    k = imu.probes[3]
    got = interpolated(stations[k] - func.imu)
    np.testing.assert_array_equal(got[:, 0], tl.phi_sensor[:, k])
    np.testing.assert_array_equal(got[:, 1], tl.dphi_sensor[:, k])
    np.testing.assert_array_equal(interpolated(0.0)[:, 1], tl.dphi_sensor[:, 0])
    # between tabulated stations: against a timeline built with the station meshed (the slope term the gyro
    # sees) and one with it read off the same beam
    for shift in (0.37 * spacing, 1.5 * spacing, -4.6 * spacing):
        got = interpolated(shift)
        meshed = build_timeline(mm, "nonrigid", tl.t_end, 0.05, None, [func.imu + shift], 50.0,
                                strip_stations=tl.strip_stations, mode_interval=tl.mode_interval)
        probed = build_timeline(mm, "nonrigid", tl.t_end, 0.05, None, stations[:1 + RENDER_STATIONS], 50.0,
                                strip_stations=tl.strip_stations, mode_interval=tl.mode_interval,
                                sensor_probes=[func.imu + shift])
        for ref in (meshed.dphi_sensor[:, 0], probed.dphi_sensor[:, -1]):
            scale = np.abs(ref).max(axis=0)
            assert np.all(np.abs(got[:, 1] - ref).max(axis=0) <= 1e-3 * scale), shift
        # probes are not meshed: the meshed stations' shapes are those without them
        meshed_ones = slice(0, 1 + RENDER_STATIONS)
        np.testing.assert_array_equal(probed.dphi_sensor[:, meshed_ones], tl.dphi_sensor[:, meshed_ones])
    with pytest.raises(ValueError, match="outside"):
        imu.placement(np.array([0.5]), stations)


def _imu_flight(imu, timeline, shift, n=100, model="nonrigid"):
    from lvgym.simulator.servo import Servo
    sim = Simulator("smile_v1", model, timeline=timeline, imu=imu, servo=Servo(15.0, 0.7))
    d = sim.reset(1, rng=np.random.default_rng(0), imu_station=None if shift is None else [shift])
    out = []
    for k in range(n):
        sim.step(d, np.array([[0.01 * np.sin(0.3 * k), 0.005]]), 0.02)
        out.append(d.imu[0].copy())
    return np.array(out)


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_shifted_imu_flies_as_an_imu_at_that_station(model):
    """A row's station shifted onto a tabulated station flies bit for bit as an IMU mounted there: the
    gyro's slope term, the accelerometers' phi and their lever arm all follow the station."""
    from lvgym.simulator import build_timeline
    from lvgym.simulator.imu import Imu
    from lvgym.simulator.layouts import IMU_STATE
    from lvgym.vehicle import MassModel, load_vehicle
    s0, d = -4.125, 0.125
    tl = build_timeline(MassModel(load_vehicle("smile_v1")), model, 3.0, 0.05, None, [s0], 50.0, mode_interval=None,
                        sensor_probes=[s0 - d, s0 + d])
    shifted = _imu_flight(Imu(s0, 0, probes=(1, 2)), tl, d, model=model)
    mounted = _imu_flight(Imu(s0 + d, 2), tl, None, model=model)
    filters = slice(0, IMU_STATE.offset("station"))
    np.testing.assert_array_equal(shifted[:, filters], mounted[:, filters])
    nominal = _imu_flight(Imu(s0, 0, probes=(1, 2)), tl, 0.0, model=model)
    plain = _imu_flight(Imu(s0, 0), tl, None, model=model)
    np.testing.assert_array_equal(nominal, plain)                     # nominal: bit for bit
    assert not np.array_equal(shifted[:, filters], nominal[:, filters])
    gy = IMU_STATE.slice("gyro")
    if model == "rigid":                                              # the gyro does not see a rigid shift
        np.testing.assert_array_equal(shifted[:, gy], nominal[:, gy])


def _v1(randomize):
    return _imu_env(randomize, model="nonrigid", mission_time_s=3.0, wind="turbulence")


def test_imu_station_nominal_draw_reproduces_the_undispersed_env():
    from lvgym.simulator.layouts import IMU_STATE
    off, on = _v1(["mass"]), _v1(["mass", "imu_station"])
    a = off.initial([np.random.default_rng(4)])
    b = on.initial([np.random.default_rng(4)])
    assert IMU_STATE.view(b.sim.imu, "station")[0, 0] != 0.0
    IMU_STATE.view(b.sim.imu, "station")[:] = on.sim.imu.placement(np.zeros(1), on.timeline.sensor_stations)
    np.testing.assert_array_equal(a.sim.p, b.sim.p)                   # the same mass draw before it
    for k in range(60):
        u = np.array([[0.2 * np.sin(0.2 * k), 0.1]])
        a = off.transition(a, u, [None], inplace=True)
        b = on.transition(b, u, [None], inplace=True)
        assert off.observation(a).tobytes() == on.observation(b).tobytes(), k


def test_imu_station_batch_against_single_rows():
    from lvgym.simulator.layouts import IMU_STATE
    func = _v1(["imu_station", "sensor_noise"])
    seeds = [0, 1, 2]
    batch = func.initial([np.random.default_rng(s) for s in seeds])
    shifts = IMU_STATE.view(batch.sim.imu, "station_shift")[:, 0]
    assert len(set(shifts.tolist())) == 3
    singles = [func.initial([np.random.default_rng(s)]) for s in seeds]
    g_b = [np.random.default_rng(100 + s) for s in seeds]
    g_s = [np.random.default_rng(100 + s) for s in seeds]
    for k in range(40):
        u = np.tile([[0.3 * np.sin(0.1 * k), -0.1]], (3, 1))
        batch = func.transition(batch, u, g_b, inplace=True)
        for i in range(3):
            singles[i] = func.transition(singles[i], u[i:i + 1], [g_s[i]], inplace=True)
    for i in range(3):
        assert func.observation(batch)[i].tobytes() == func.observation(singles[i])[0].tobytes()
    # a shifted row sees another bending signal than the same row at the nominal station
    again = func.initial([np.random.default_rng(1)])
    IMU_STATE.view(again.sim.imu, "station")[:] = func.sim.imu.placement(np.zeros(1), func.timeline.sensor_stations)
    g = np.random.default_rng(101)
    for k in range(40):
        again = func.transition(again, np.array([[0.3 * np.sin(0.1 * k), -0.1]]), [g], inplace=True)
    assert not np.array_equal(func.observation(again)[0, :3], func.observation(batch)[1, :3])
