"""The simulator: compiled loads against the environment models, the timeline against the mass model,
events, the rail, batch against single rows."""

import numpy as np
import pytest

from lvgym.environment import Environment
from lvgym.simulator import CONDITIONS, SITES, EnvironmentSpec, LaunchSpec, Simulator, TimelineSpec
from lvgym.vehicle import MassModel


@pytest.fixture(scope="module")
def smile():
    return Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=60.0))


def test_flight_conditions_equal_the_environment_models(smile):
    wind = {"model": "profile", "altitude_m": [0.0, 10e3], "speed": [5.0, 30.0], "direction_deg": [270.0, 200.0]}
    sim = Simulator("stratos3", "rigid", launch=LaunchSpec("el_arenosillo"), environment=EnvironmentSpec(wind=wind),
                    timeline=TimelineSpec(t_end=5.0))
    d = sim.reset()
    rng = np.random.default_rng(3)
    x = d.x[0].copy()
    lay = sim.layout.state
    x[lay["r_zw_i"]] += sim.C_ib0[:, 0] * 4000.0
    x[lay["v_zw_i"]] += sim.C_ib0 @ np.array([600.0, 20.0, -35.0])
    x[lay["omega_bi_b"]] = rng.normal(0.0, 0.1, 3)
    d.x[0] = x
    d.t[0] = 12.0
    sim.update_conditions(d)
    env = Environment(sim.site, gravity=sim.gravity, atmosphere=sim.atmosphere, wind=sim.wind,
                      aerodynamics=sim.aerodynamics)
    env.reset(np.random.default_rng(0))
    fc = env.conditions(12.0, x[lay["r_zw_i"]], x[lay["v_zw_i"]], x[lay["q_bi"]], x[lay["omega_bi_b"]],
                        d.p[0, sim.layout.params["r_cg"].start])
    for name in ("altitude", "density", "pressure", "mach", "qbar", "alpha", "beta", "alpha_total"):
        assert sim.conditions(d, name)[0] == pytest.approx(getattr(fc, name)[0], rel=1e-10, abs=1e-12), name
    for name in ("wind_n", "v_air_b", "f_aero_b", "m_aero_b", "g_i"):
        np.testing.assert_allclose(sim.conditions(d, name)[0], getattr(fc, name)[0], rtol=1e-10, atol=1e-9)


def test_thrust_includes_the_ambient_pressure(smile):
    tl = smile.timeline
    mm = MassModel(smile.vehicle)
    state, _ = mm.advance(mm.initial_state(), 10.0)
    for p_amb in (0.0, 5e4, 101325.0):
        expected = mm.thrust(state, 1.0, p_amb)
        got = tl.interp("thrust0", [10.0])[0] - tl.interp("exit_area", [10.0])[0] * p_amb
        assert got == pytest.approx(expected, rel=1e-12)


def test_timeline_matches_the_mass_model_between_rows(smile):
    mm = MassModel(smile.vehicle)
    for t in (0.013, 17.31, 42.99, 44.5, 50.27):
        state, _ = mm.advance(mm.initial_state(), t)
        props = mm.properties(state)
        assert smile.timeline.interp("mass", [t])[0] == pytest.approx(props.mass, rel=1e-8)
        p = smile.timeline.params_at([t])[0]
        assert p[smile.layout.params["m_b"]][0] == pytest.approx(props.m_b, rel=1e-4)


def test_events_are_reported_once_at_their_times(smile):
    d = smile.reset()
    seen = []
    while d.t[0] < 46.0:
        for t, e in smile.step(d, [[0.0, 0.0]], 0.03)[0]:
            seen.append((round(t, 9), e))
    names = [e for _, e in seen]
    assert names[0] == "lift-off"
    assert (43.0, "stage 'stage1' burnout") in seen
    assert (44.0, "stage 'stage1' separation") in seen
    assert (45.0, "stage 'stage2' ignition") in seen
    assert len(names) == len(set(names))


def test_rail_holds_the_attitude_until_exit():
    sim = Simulator("stratos3", "nonrigid", launch=LaunchSpec("el_arenosillo", 80.0, 10.0),
                    timeline=TimelineSpec(t_end=3.0))
    d = sim.reset()
    v = sim.view(d)
    q0 = v.state("q_bi")[0].copy()
    events = []
    while v.on_rail[0]:
        events += sim.step(d, [[0.02, -0.02]], 0.01)[0]     # gimbal deflected: would turn it off the rail
        w = v.state("omega_bi_b")[0]
        assert np.linalg.norm(w) < 1e-4                     # only the Earth's rate
    names = [e for _, e in events]
    assert names == ["lift-off", "rail exit"]
    assert v.rail_s[0] >= 10.0
    assert abs(v.state("q_bi")[0] @ q0) > 1 - 1e-9        # Earth turned less than 1e-4 rad
    before = v.state("omega_bi_b")[0].copy()
    sim.step(d, [[0.02, -0.02]], 0.2)
    assert np.linalg.norm(v.state("omega_bi_b")[0] - before) > 1e-3


def test_batch_rows_at_different_times_equal_single_rows():
    gust = EnvironmentSpec(wind={"model": "gust", "amplitude": 10.0, "length": 100.0, "onset": 500.0})
    sim = Simulator("smile", "nonrigid", environment=gust, timeline=TimelineSpec(t_end=50.0))
    d = sim.reset(2)
    single = Simulator("smile", "nonrigid", environment=gust, timeline=sim.timeline)
    one = single.reset(1)
    for _ in range(50):
        sim.step(d, [[0.01, -0.01], [0.0, 0.0]], 0.02)
    d = sim.reset_rows(d, [1])
    for _ in range(60):
        sim.step(d, [[0.01, -0.01], [0.01, -0.01]], 0.02)
        single.step(one, [[0.01, -0.01]], 0.02)
    assert d.t[1] == pytest.approx(one.t[0])
    np.testing.assert_array_equal(d.x[1], one.x[0])


def test_the_simulator_holds_no_rows_and_its_view_reads_the_given_ones():
    sim = Simulator("stratos3", "rigid", timeline=TimelineSpec(t_end=2.0))
    a, b = sim.reset(), sim.reset(3)
    assert not hasattr(sim, "data") and a.t.shape == (1,) and b.t.shape == (3,)
    sim.step(b, np.zeros((3, 2)), 0.5)
    assert a.t[0] == 0.0 and np.all(b.t == 0.5)                   # only the given rows moved
    v = sim.view(b)
    assert v.batch == 3 and v.t is b.t and v.x is b.x
    assert np.shares_memory(v.conditions("qbar"), b.conditions) and v.conditions("qbar").shape == (3,)
    np.testing.assert_array_equal(v.state("omega_bi_b"), b.x[:, sim.layout.state["omega_bi_b"]])
    np.testing.assert_array_equal(v.gimbal, sim.gimbal(b))


def test_rigid_and_nonrigid_share_the_rigid_equivalent_mass(smile):
    rigid = Simulator("smile", "rigid", timeline=TimelineSpec(t_end=60.0))
    t = np.array([0.0, 20.0, 50.0])
    np.testing.assert_allclose(rigid.timeline.interp("mass", t), smile.timeline.interp("mass", t))
    m_nr = smile.timeline.params_at(t)[:, 0] + smile.timeline.interp("slosh_mass", t).sum(axis=1)
    np.testing.assert_allclose(rigid.timeline.params_at(t)[:, 0], m_nr, rtol=1e-12)


def test_modes_above_the_step_nyquist_frequency_are_decoupled(smile):
    p = smile.timeline.params_at([50.0])[0]
    lay = smile.layout.params
    omega, phi = p[lay["omega_modes"]], p[lay["phi_gimbal"]]
    assert np.all(phi[omega > 2 * np.pi * 0.5 / smile.physics_dt] == 0.0)
    assert np.all(phi[omega <= 2 * np.pi * 0.5 / smile.physics_dt] != 0.0)


def test_bad_options_raise_with_the_key():
    with pytest.raises(ValueError, match="model"):
        Simulator("smile", model="elastic")
    with pytest.raises(ValueError, match="site"):
        Simulator("smile", launch=LaunchSpec(site="kourou"))
    with pytest.raises(ValueError, match="elevation_deg"):
        Simulator("smile", launch=LaunchSpec(elevation_deg=120.0))


def test_the_specs_are_frozen_and_a_bad_value_names_its_key_in_one_line():
    import dataclasses
    import pickle

    from lvgym.errors import ConfigError
    from lvgym.simulator import PhysicsSpec

    bad = {"site": lambda: LaunchSpec(site="kourou"), "rail_length": lambda: LaunchSpec(rail_length=-1.0),
           "aeroelastic": lambda: EnvironmentSpec(aeroelastic="yes"), "t_end": lambda: TimelineSpec(t_end=0.0),
           "n_modes": lambda: TimelineSpec(n_modes=1.5), "sensor_stations": lambda: TimelineSpec(sensor_stations=1.0),
           "cg_convention": lambda: TimelineSpec(cg_convention="wet"), "physics_dt": lambda: PhysicsSpec(0.5),
           "slosh_frequency": lambda: PhysicsSpec(slosh_frequency="vacuum"), "threads": lambda: PhysicsSpec(threads=0),
           "launch": lambda: Simulator("smile", launch="andoya")}
    for key, make in bad.items():
        with pytest.raises(ConfigError, match=f"^{key} = ") as err:
            make()
        assert "\n" not in str(err.value) and str(pickle.loads(pickle.dumps(err.value))) == str(err.value)
    with pytest.raises(dataclasses.FrozenInstanceError):
        TimelineSpec().t_end = 1.0
    spec = TimelineSpec(t_end=5, n_modes=np.int64(2), sensor_stations=np.array([-1.0, -2.5]))
    assert (spec.t_end, spec.n_modes, spec.sensor_stations) == (5.0, 2, (-1.0, -2.5))
    assert LaunchSpec("flat").launch_site() is SITES["flat"]


def test_conditions_names_are_checked(smile):
    d = smile.reset()
    with pytest.raises(KeyError, match="one of"):
        smile.conditions(d, "altitud")
    assert set(CONDITIONS.names) >= {"altitude", "mach", "qbar", "alpha", "thrust"}
    assert "flat" in SITES


def _smile_mapping():
    from pathlib import Path

    import yaml

    import lvgym.vehicle.config as cfg

    return yaml.safe_load((Path(cfg.VEHICLE_DIR) / "smile.yaml").read_text())


def test_aerodynamics_of_the_stack_in_flight_after_separation():
    """A stage's own aerodynamics is in force once it is the lowest attached stage: SMILE with the
    finless upper stack after stage 1 separates at 44 s."""
    from lvgym.vehicle.config import parse_vehicle

    data = _smile_mapping()
    data["stages"][1]["aerodynamics"] = {"model": "barrowman", "nose": {"shape": "ogive", "length": 1.8},
                                         "body": {"diameter": 1.1, "length": 5.3}}
    wind = {"model": "profile", "altitude_m": [0.0, 1e5], "speed": [5.0, 5.0], "direction_deg": [90.0, 90.0]}
    sim = Simulator(parse_vehicle(data), "rigid", environment=EnvironmentSpec(wind=wind),
                    timeline=TimelineSpec(t_end=46.0))
    d = sim.reset()
    v = sim.view(d)
    lift_off, upper = sim.stage_aerodynamics[0], sim.stage_aerodynamics[1]
    assert upper is not lift_off and sim.stage_aerodynamics[2] is upper       # stage 3 inherits
    for t_stop, model in ((43.5, lift_off), (45.5, upper)):
        while d.t[0] < t_stop - 1e-9:
            sim.step(d, [[0.0, 0.0]], 0.05)
        f, m, _ = model.loads(v.conditions("v_air_b")[0], v.state("omega_bi_b")[0], v.conditions("density")[0],
                              v.conditions("speed_of_sound")[0], d.p[0, sim._i_cg])
        np.testing.assert_allclose(v.conditions("f_aero_b")[0], f, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(v.conditions("m_aero_b")[0], m, rtol=1e-12, atol=1e-9)
    # the finless upper stack is statically unstable (positive Cm at positive alpha), the lift-off stack stable
    assert lift_off.coefficients(5.8, np.radians(2.0))["Cm"] < 0.0 < upper.coefficients(5.8, np.radians(2.0))["Cm"]
    # the shipped smile keeps the lift-off stack's aerodynamics all flight (as the thesis)
    shipped = Simulator("smile", "rigid", timeline=TimelineSpec(t_end=2.0))
    assert all(m is shipped.aerodynamics for m in shipped.stage_aerodynamics)


def test_stage_aerodynamics_must_be_a_mapping():
    from lvgym.errors import ConfigError
    from lvgym.vehicle.config import parse_vehicle

    data = _smile_mapping()
    data["stages"][1]["aerodynamics"] = [1, 2]
    with pytest.raises(ConfigError, match="aerodynamics"):
        parse_vehicle(data)


def test_a_diverged_row_fails_alone_instead_of_raising():
    """A row whose state runs away (here its position put 1000 times further from the Earth's centre, where
    the atmosphere table's density underflows to zero and a gimbal at its stops once spun a slosh pendulum
    up) is failed as a non-finite one is; the other rows of the batch fly on, as their single envs do."""
    import lvgym
    from lvgym.benchmark.suites import condition

    cond = condition("smile-v2", "nonrigid").with_options(mission_time_s=1.0)
    vec = cond.make_vec_env(2)
    vec.reset(seed=3)
    core = vec.unwrapped.core if hasattr(vec.unwrapped, "core") else vec.core
    core.state.sim.x[0, 0:3] *= 1000.0
    a = np.zeros((2, 2), np.float32)
    obs, reward, terminated, truncated, info = vec.step(a)
    assert terminated[0] and not terminated[1] and core.state.sim.failed[0]
    single = lvgym.make_env("smile-v2", model="nonrigid", mission_time_s=1.0)
    single.reset(seed=4)
    assert np.array_equal(obs[1], single.step(a[1])[0])
