"""The strip-theory aeroelastic loads in the simulator's compiled loads (lvgym/simulator/strips.py)."""

import numba as nb
import numpy as np
import pytest

from lvgym.environment.aerodynamics import AxisymmetricAero
from lvgym.environment.aeroelastic import resample_modes
from lvgym.envs.spec import wind_spec
from lvgym.errors import ConfigError
from lvgym.simulator import data as simdata
from lvgym.simulator import EnvironmentSpec, Simulator, TimelineSpec, flight_loads
from lvgym.simulator.layouts import CTX, DS
from lvgym.simulator.strips import N_STRIPS

T_END = 3.0


@nb.njit
def _call_loads(fn, t, x, p, ctx, u):
    fn(t, x, p, ctx, u)


def slender(model="nonrigid", aeroelastic=None):
    return Simulator("slender", model, environment=EnvironmentSpec(wind="none", aeroelastic=aeroelastic),
                     timeline=TimelineSpec(t_end=T_END))


def fly(sim, seconds, batch=1, rngs=None, winds=None):
    """``batch`` new rows of ``sim`` flown ``seconds`` with the gimbal centred: their SimView."""
    d = sim.reset(batch, rng=rngs, winds=winds)
    for _ in range(int(round(seconds / 0.02))):
        sim.step(d, np.zeros((batch, 2)), 0.02)
    return sim.view(d)


@pytest.fixture(scope="module")
def flown():
    """The slender vehicle flown 1 s with the aeroelastic loads on and off."""
    return fly(slender(aeroelastic=True), 1.0), fly(slender(aeroelastic=False), 1.0)


@pytest.fixture
def pair(flown):
    """:func:`flown`, its rows restored after the test."""
    saved = [simdata.take(v.data) for v in flown]
    yield flown
    for v, rows in zip(flown, saved):
        simdata.put(v.data, np.arange(v.batch), rows)


def test_option_follows_the_vehicle_file():
    sim = slender()
    assert sim.aeroelastic and sim.strips is not None and sim.vehicle.structure.aeroelastic
    assert sim.timeline.strip_stations.shape == (1, N_STRIPS)
    assert slender(aeroelastic=False).strips is None
    assert slender("rigid", aeroelastic=True).strips is None            # no modes: nothing to load
    smile = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=1.0))
    assert not smile.aeroelastic and smile.strips is None
    with pytest.raises(ValueError, match="aeroelastic"):
        slender(aeroelastic="yes")


def test_strip_modes_are_the_beam_modes_at_the_strips():
    # the strips do not change the beam (the modes and every parameter equal the timeline's without
    # strips), and each row's shapes at the strips are the beam's node shapes interpolated there
    on, off = slender(aeroelastic=True).timeline, slender(aeroelastic=False).timeline
    np.testing.assert_array_equal(on.params, off.params)
    np.testing.assert_array_equal(on.t, off.t)
    from lvgym.vehicle import MassModel, load_vehicle
    from lvgym.vehicle.structure import vehicle_modes
    mm = MassModel(load_vehicle("slender"))
    state = mm.initial_state()
    beam = vehicle_modes(mm.vehicle, state, mm.properties(state)).beam
    phi, dphi = resample_modes(on.strip_stations[0], beam.node_stations, beam.phi_nodes.T, beam.dphi_nodes.T)
    np.testing.assert_allclose(on.phi_strip[0], phi, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(on.dphi_strip[0], dphi, rtol=1e-12, atol=1e-15)
    assert np.abs(phi).max() > 0.05 and np.abs(dphi).max() > 0.01


def _bent_state(v, seed):
    """The state of the rows ``v`` (a SimView) with large random modal deflections and rates and a body rate."""
    rng = np.random.default_rng(seed)
    x = v.x.copy()
    lay = v.sim.layout
    lay.view(x, "state", "eta")[:] = rng.normal(0, 0.02, (1, 2, v.sim.dynamics.n_modes))
    lay.view(x, "state", "eta_dot")[:] = rng.normal(0, 1.0, (1, 2, v.sim.dynamics.n_modes))
    lay.view(x, "state", "omega_bi_b")[:] = [0.01, 0.05, -0.03]
    return x


def test_compiled_loads_agree_with_the_python_path(pair):
    # a state with large modal deflections, rates and body rates: the conditions' force and moment gain
    # exactly the strips' elastic increment, and the loads' f_eta are the strips' modal forces
    on, off = pair
    lay = on.sim.layout
    x = _bent_state(on, 5)
    for v in (on, off):
        v.x[:] = x
        v.sim.update_conditions(v.data)
    assert on.t[0] == off.t[0] and np.array_equal(on.p, off.p)
    model = on.sim.strips.stages[0]
    tl = on.sim.timeline
    phi, dphi = tl.left("phi_strip", on.t)[0], tl.left("dphi_strip", on.t)[0]
    eta, eta_dot = on.state("eta")[0].ravel(), on.state("eta_dot")[0].ravel()
    f_b, m_b, f_eta = model.loads(off.conditions("v_air_b")[0], x[0, lay.state["omega_bi_b"]],
                                  off.conditions("density")[0], off.conditions("speed_of_sound")[0],
                                  on.p[0, lay.params["r_cg"].start], eta=eta, eta_dot=eta_dot, phi=phi, dphi=dphi)
    assert np.abs(f_eta).max() > 1.0 and np.abs(m_b).max() > 1.0
    scale = np.abs(off.conditions("f_aero_b")[0]).max() * 1e-13
    np.testing.assert_allclose(on.conditions("f_aero_b")[0] - off.conditions("f_aero_b")[0], f_b, rtol=1e-12,
                               atol=scale)
    scale = np.abs(off.conditions("m_aero_b")[0]).max() * 1e-13
    np.testing.assert_allclose(on.conditions("m_aero_b")[0] - off.conditions("m_aero_b")[0], m_b, rtol=1e-12,
                               atol=scale)
    # the compiled loads at an RK4 stage of the same state (stage time relative to the piece's start)
    loads = {}
    for name, sim in (("on", on), ("off", off)):
        u = lay.zeros_loads()
        ctx = sim.c[0].copy()
        _call_loads(flight_loads, float(on.t[0] - ctx[CTX.time0]), x[0].copy(), sim.p[0].copy(), ctx, u)
        loads[name] = u
    np.testing.assert_allclose(lay.view(loads["on"], "loads", "f_eta").ravel(), f_eta, rtol=1e-12)
    assert np.all(lay.view(loads["off"], "loads", "f_eta") == 0.0)
    np.testing.assert_array_equal(lay.view(loads["on"], "loads", "thrust_b"), lay.view(loads["off"], "loads", "thrust_b"))


def test_the_normal_force_dispersion_scales_the_strip_loads(pair):
    # v1's ``aerodynamics`` draw multiplies the normal force: the strips' elastic force, moment and modal
    # forces scale with it as the table's normal force does (both come from one CN-alpha distribution)
    on, off = pair
    lay = on.sim.layout
    x = _bent_state(on, 7)
    out = {}
    for kn in (1.0, 1.2):
        for name, sim in (("on", on), ("off", off)):
            sim.x[:] = x
            sim.c[0, CTX.dispersion + DS.normal_scale] = kn
            sim.sim.update_conditions(sim.data)
            u = lay.zeros_loads()
            ctx = sim.c[0].copy()
            _call_loads(flight_loads, float(sim.t[0] - ctx[CTX.time0]), x[0].copy(), sim.p[0].copy(), ctx, u)
            out[name, kn] = (sim.conditions("f_aero_b")[0].copy(), sim.conditions("m_aero_b")[0].copy(),
                             lay.view(u, "loads", "f_eta").ravel().copy())
        for sim in (on, off):
            sim.c[0, CTX.dispersion + DS.normal_scale] = 1.0
    for i, what in enumerate(("force", "moment")):
        base = out["on", 1.0][i] - out["off", 1.0][i]
        assert np.abs(base[1:]).max() > 1.0, what
        np.testing.assert_allclose(out["on", 1.2][i] - out["off", 1.2][i], 1.2 * base, rtol=1e-9,
                                   atol=1e-9 * np.abs(out["off", 1.2][i]).max(), err_msg=what)
    assert np.abs(out["on", 1.0][2]).max() > 1.0
    np.testing.assert_allclose(out["on", 1.2][2], 1.2 * out["on", 1.0][2], rtol=1e-12)


def test_the_flag_changes_the_slender_flight(pair):
    on, off = pair
    eta_on, eta_off = on.state("eta")[0], off.state("eta")[0]
    assert np.abs(eta_on - eta_off).max() > 10.0 * np.abs(eta_off).max()
    assert not np.array_equal(on.state("omega_bi_b"), off.state("omega_bi_b"))
    assert np.all(np.isfinite(on.x))


def test_zero_mode_shapes_at_the_strips_fly_as_without():
    # the wiring adds nothing but the strips' loads: with the mode shapes at the strips zeroed the
    # increment and the modal forces are exactly zero and the flight is the flag-off flight, bit for bit
    from dataclasses import replace
    off = slender(aeroelastic=False)
    tl = slender(aeroelastic=True).timeline
    tl = replace(tl, phi_strip=np.zeros_like(tl.phi_strip), dphi_strip=np.zeros_like(tl.dphi_strip))
    zeroed = Simulator("slender", "nonrigid", environment=EnvironmentSpec(wind="none", aeroelastic=True), timeline=tl)
    assert zeroed.strips is not None
    zeroed, off = fly(zeroed, 0.6), fly(off, 0.6)
    np.testing.assert_array_equal(zeroed.x, off.x)
    np.testing.assert_array_equal(zeroed.data.conditions, off.data.conditions)


def test_rigid_model_with_the_flag_is_unchanged():
    a, b = fly(slender("rigid", aeroelastic=True), 0.6), fly(slender("rigid", aeroelastic=False), 0.6)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.data.conditions, b.data.conditions)


def test_batch_rows_fly_as_single_vehicles():
    wind = wind_spec("turbulence", T_END)
    seeds = [3, 8, 21]
    batch = fly(slender(aeroelastic=True), 0.6, 3, [np.random.default_rng(s) for s in seeds], [wind] * 3)
    assert not np.array_equal(batch.x[0], batch.x[1])
    for b, s in enumerate(seeds):
        one = fly(slender(aeroelastic=True), 0.6, 1, [np.random.default_rng(s)], [wind])
        np.testing.assert_array_equal(batch.x[b], one.x[0])
        np.testing.assert_array_equal(batch.data.conditions[b], one.data.conditions[0])


def test_a_prebuilt_timeline_without_strips_is_refused():
    tl = slender(aeroelastic=False).timeline
    with pytest.raises(ValueError, match="strips"):
        Simulator("slender", "nonrigid", environment=EnvironmentSpec(aeroelastic=True), timeline=tl)
    # a table without geometry has no strip distribution
    table = AxisymmetricAero({"mach": [0.0, 2.0], "alpha_deg": [0.0, 10.0], "CA": [[0.3, 0.3], [0.4, 0.4]],
                              "CN": [[0.0, 1.5], [0.0, 1.2]], "Cm": [[0.0, -3.0], [0.0, -2.5]]}, 0.07, 0.3, -4.0)
    with pytest.raises(ConfigError, match="aeroelastic"):
        Simulator("slender", "nonrigid", environment=EnvironmentSpec(aerodynamics=table, aeroelastic=True),
                  timeline=TimelineSpec(t_end=1.0))


def test_env_option():
    import gymnasium as gym

    import lvgym  # noqa: F401
    # v0 envs fly without (TaskSpec default False, whatever the vehicle file says); the key turns them on
    env = gym.make("lvgym/SlenderAscent-v0", model="nonrigid", mission_time_s=1.0)
    assert env.unwrapped.task.aeroelastic is False and env.unwrapped.func.sim.strips is None
    env = gym.make("lvgym/SlenderAscent-v0", model="nonrigid", mission_time_s=1.0, aeroelastic=None)
    assert env.unwrapped.func.sim.strips is not None
    obs, _ = env.reset(seed=1)
    for _ in range(10):
        obs, *_ = env.step(np.zeros(2, np.float32))
    assert np.all(np.isfinite(obs))
    with pytest.raises(ConfigError, match="aeroelastic"):
        gym.make("lvgym/SlenderAscent-v0", aeroelastic="on")
