"""Bending modes recomputed through the flight, the modal state carried across each change of basis
(issue 16, section 2): the transfer matrix, the deflection field it keeps, the timeline's changes, and
the compiled step that applies them row by row."""

import numpy as np
import pytest

from lvgym.simulator import Simulator, TimelineSpec, build_timeline, cache
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.structure import mode_transfer, stiffness_factor, vehicle_modes


@pytest.fixture(scope="module")
def smile_modes():
    v = load_vehicle("smile")
    mm = MassModel(v)
    factor = stiffness_factor(v)

    def at(t, K=4):
        s, _ = mm.advance(mm.initial_state(), t)
        return vehicle_modes(v, s, mm.properties(s), n_modes=K, ei_factor=factor)
    return at


def _line_residual(x, d):
    """Largest deviation of ``d(x)`` from its least-squares straight line ``a + b x`` (a rigid-body
    translation and rotation of the beam)."""
    A = np.stack([np.ones_like(x), x], axis=1)
    coef = np.linalg.lstsq(A, d, rcond=None)[0]
    return float(np.abs(d - A @ coef).max())


def test_transfer_is_the_identity_when_the_modes_do_not_change(smile_modes):
    m = smile_modes(0.0)
    np.testing.assert_allclose(mode_transfer(m, m), np.eye(4), atol=1e-10)
    again = smile_modes(0.0)                          # recomputed: equal beams, equal modes
    np.testing.assert_allclose(mode_transfer(m, again), np.eye(4), atol=1e-10)


def test_transfer_is_nearly_orthogonal_for_small_changes(smile_modes):
    m0 = smile_modes(0.0)
    dev = []
    for t in (0.5, 2.0, 10.0):
        T = mode_transfer(m0, smile_modes(t))
        dev.append(np.abs(T.T @ T - np.eye(4)).max())
    # 0.5 s of burn (74 kg of 10.6 t): orthogonal to about 1 %; the departure grows with the change
    # (the old shapes are mass-normalised for the heavier stack)
    assert dev[0] < 0.015
    assert dev[0] < dev[1] < dev[2]


@pytest.mark.parametrize("t1", [2.0, 10.0, 43.0])
def test_projection_keeps_the_elastic_deflection_field(smile_modes, t1):
    """Free vibration across a change: the field sum_k eta_k phi_k(x) of the old modes is the field of
    the projected coordinates in the new modes, up to a straight line (the rigid-body part of the old
    field for the new mass distribution, which no elastic mode carries) and the modal truncation."""
    m0, m1 = smile_modes(0.0), smile_modes(t1, K=8)        # 4 modes into 8: little truncation
    T = mode_transfer(m0, m1)
    assert T.shape == (8, 4)
    x = np.linspace(m1.beam.node_stations.min(), 0.0, 61)
    phi0, _ = m0.beam.shape_at(x)
    phi1, _ = m1.beam.shape_at(x)
    eta0 = np.array([1.0, -0.5, 0.25, 0.1])
    before, after = phi0 @ eta0, phi1 @ (T @ eta0)
    scale = np.abs(before).max()
    # between the nodes the old field is a cubic on the old mesh, the new one on the new mesh
    assert _line_residual(x, before - after) < 3e-3 * scale
    # the coordinates kept as numbers (v0's "held") do not keep the field
    assert _line_residual(x, before - phi1[:, :4] @ eta0) > 10 * _line_residual(x, before - after)


def test_projection_across_a_separation_keeps_the_attached_part():
    """SMILE drops stage 1 at 44 s: the upper stack's field is the old field on the part still attached,
    less its rigid-body motion, within the truncation of the upper stack's modes."""
    v = load_vehicle("smile")
    mm = MassModel(v)
    factor = stiffness_factor(v)
    pre, _ = mm.advance(mm.initial_state(), 44.0 - 1e-9)
    post, _ = mm.advance(mm.initial_state(), 44.0)
    m0 = vehicle_modes(v, pre, mm.properties(pre), n_modes=2, ei_factor=factor)
    m1 = vehicle_modes(v, post, mm.properties(post), n_modes=12, ei_factor=factor)
    assert m1.beam.node_stations.min() > m0.beam.node_stations.min() + 1.0       # a shorter stack
    T = mode_transfer(m0, m1)
    assert T.shape == (12, 2)
    x = np.linspace(m1.beam.node_stations.min(), 0.0, 41)
    phi0, _ = m0.beam.shape_at(x)
    phi1, _ = m1.beam.shape_at(x)
    for k in range(2):
        before, after = phi0[:, k], phi1 @ T[:, k]
        assert _line_residual(x, before - after) < 0.02 * _line_residual(x, before)


@pytest.fixture(scope="module")
def projected_timeline():
    return build_timeline(MassModel(load_vehicle("smile")), "nonrigid", 61.0, 0.05, None, (), 50.0,
                          mode_interval=2.0, mode_basis="projected")


def test_frequencies_step_through_the_flight(projected_timeline):
    tl = projected_timeline
    lay = tl.dynamics.layout.params
    t = np.array([0.0, 1.9, 2.0, 10.0, 20.0, 30.0, 42.9])
    f1 = tl.params_at(t)[:, lay["omega_modes"]][:, 0] / (2 * np.pi)
    assert f1[0] == pytest.approx(9.39, abs=0.01) and f1[1] == f1[0]          # held until the first change
    assert f1[2] > f1[1]
    assert np.all(np.diff(f1[2:]) > 0.0)
    assert f1[-1] == pytest.approx(13.6, abs=0.25)                               # 42 s modes, burnout 43 s
    frozen = build_timeline(MassModel(load_vehicle("smile")), "nonrigid", 61.0, 0.05, None, (), 50.0)
    assert np.all(frozen.params_at(t)[:, lay["omega_modes"]][:, 0] == frozen.params_at([0.0])[0, lay["omega_modes"]][0])
    # changes every 2 s and at the separation, one matrix each; the upper stack's modes are above the
    # 50 Hz cut-off of a 10 ms step, so the separation's matrix carries nothing into them
    ch = tl.mode_change_t
    np.testing.assert_allclose(ch[:21], np.arange(2.0, 43.0, 2.0), atol=1e-9)
    assert 44.0 in ch and tl.mode_transfer.shape == (ch.size, 2, 2)
    assert np.all(tl.mode_transfer[list(ch).index(44.0)] == 0.0)
    assert frozen.mode_change_t.size == 0


def test_held_timelines_have_no_changes_and_the_cache_keeps_the_options(tmp_path, monkeypatch):
    monkeypatch.setenv("LVGYM_CACHE_DIR", str(tmp_path))
    mm = MassModel(load_vehicle("smile"))
    kw = dict(model="nonrigid", t_end=10.0, dt=0.05, sensor_stations=(-4.0,), mode_cutoff_hz=50.0)
    held = build_timeline(mm, **kw, mode_interval=2.0)
    proj = build_timeline(mm, **kw, mode_interval=2.0, mode_basis="projected")
    assert held.mode_change_t.size == 0 and held.mode_basis == "held"
    np.testing.assert_allclose(proj.mode_change_t, [2.0, 4.0, 6.0, 8.0, 10.0])
    assert proj.mode_basis == "projected" and proj.mode_interval == 2.0
    again = build_timeline(mm, **kw, mode_interval=2.0, mode_basis="projected")     # from the cache
    assert len(list((tmp_path / "timelines").glob("*" + cache.SUFFIX))) == 2
    np.testing.assert_array_equal(again.mode_transfer, proj.mode_transfer)
    assert again.mode_interval == 2.0 and again.mode_basis == "projected"
    np.testing.assert_array_equal(held.params, proj.params)       # the same modes in force, only carried
    with pytest.raises(ValueError, match="mode_basis"):
        build_timeline(mm, **kw, mode_basis="rotated")


def _kick(v, rows=None):
    """A bending deflection to carry: modal coordinates and rates set by hand (``v``: the rows' SimView)."""
    eta = v.state("eta")
    eta_dot = v.state("eta_dot")
    sel = slice(None) if rows is None else rows
    eta[sel] = np.array([[2e-3, -1e-3], [1e-3, 5e-4]])
    eta_dot[sel] = np.array([[1e-2, 0.0], [0.0, -1e-2]])


def _reset(sim, batch=1):
    """New rows of ``sim`` and their read-outs."""
    d = sim.reset(batch)
    return d, sim.view(d)


def test_the_step_projects_once_at_the_change():
    stations = np.linspace(0.0, -11.0, 23)
    sim = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=6.0, sensor_stations=stations, mode_interval=2.0,
                                                              mode_basis="projected"))
    d, v = _reset(sim)
    for _ in range(99):
        sim.step(d, [[0.0, 0.0]], 0.02)
    sim.step(d, [[0.0, 0.0]], 2.0 - 1e-7 - float(d.t[0]))
    _kick(v)
    eta0 = v.state("eta")[0].copy()
    t0 = float(d.t[0])
    sim.step(d, [[0.0, 0.0]], 2e-7)                               # across t = 2 s
    eta1 = v.state("eta")[0].copy()
    tl = sim.timeline
    T = tl.mode_transfer[int(np.argmin(np.abs(tl.mode_change_t - 2.0)))]
    np.testing.assert_allclose(eta1, eta0 @ T.T, rtol=1e-5, atol=1e-10)
    # the deflection field at the stations is continuous up to a rigid-body line
    phi0 = tl.left("phi_sensor", [t0])[0]
    phi1 = tl.left("phi_sensor", [float(d.t[0])])[0]
    assert not np.array_equal(phi0, phi1)
    before, after = phi0 @ eta0[0], phi1 @ eta1[0]
    projected = _line_residual(stations, before - after)
    assert projected < 2e-2 * np.abs(before).max()                # two modes: truncation of ~1 %
    assert _line_residual(stations, before - phi1 @ eta0[0]) > 2 * projected          # held: 3 %


def test_a_period_ending_on_the_change_projects_at_the_next_one():
    """A control period that ends at the change time projects at the start of the next period: the
    same flight as one period across the change (and not the held one)."""
    on = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=4.0, mode_interval=2.0, mode_basis="projected"))
    across = Simulator("smile", "nonrigid", timeline=on.timeline)
    held = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=4.0, mode_interval=2.0))
    views = []
    for sim, periods in ((on, (1.0, 1.0, 0.02)), (across, (1.0, 1.02)), (held, (1.0, 1.0, 0.02))):
        d, v = _reset(sim)
        _kick(v)
        for dt in periods:
            sim.step(d, [[0.01, -0.01]], dt)
        views.append(v)
    on, across, held = views
    assert on.t[0] == across.t[0] == 2.02
    np.testing.assert_allclose(on.state("eta"), across.state("eta"), rtol=1e-9, atol=1e-15)
    assert np.abs(held.state("eta") - on.state("eta")).max() > 1e-3 * np.abs(on.state("eta")).max()


def test_projected_equals_held_where_no_change_falls():
    held = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=3.0))
    proj = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=3.0, mode_basis="projected"))
    assert proj.timeline.mode_change_t.size == 0
    rows = []
    for sim in (held, proj):
        d, v = _reset(sim)
        _kick(v)
        for _ in range(50):
            sim.step(d, [[0.01, -0.01]], 0.02)
        rows.append(d)
    np.testing.assert_array_equal(rows[0].x, rows[1].x)


def test_batch_rows_at_different_times_equal_single_rows_across_changes():
    sim = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=8.0, mode_interval=2.0, mode_basis="projected"))
    d, v = _reset(sim, 2)
    _kick(v)
    single = Simulator("smile", "nonrigid", timeline=sim.timeline)
    ds, vs = _reset(single)
    first = Simulator("smile", "nonrigid", timeline=sim.timeline)
    df, vf = _reset(first)
    _kick(vf)
    for _ in range(50):
        sim.step(d, [[0.01, -0.01], [0.0, 0.0]], 0.02)
        first.step(df, [[0.01, -0.01]], 0.02)
    d = sim.reset_rows(d, [1])
    _kick(sim.view(d), [1])
    _kick(vs)
    for _ in range(120):                                          # row 0 crosses 2 s at step 50, row 1 at 100
        sim.step(d, [[0.01, -0.01], [0.01, -0.01]], 0.02)
        single.step(ds, [[0.01, -0.01]], 0.02)
        first.step(df, [[0.01, -0.01]], 0.02)
    np.testing.assert_array_equal(d.x[0], df.x[0])
    np.testing.assert_array_equal(d.x[1], ds.x[0])
    held = Simulator("smile", "nonrigid", timeline=TimelineSpec(t_end=8.0, mode_interval=2.0))
    dh, vh = _reset(held)
    _kick(vh)
    for _ in range(170):
        held.step(dh, [[0.01, -0.01]], 0.02)
    assert not np.array_equal(dh.x[0], df.x[0])


def test_a_prebuilt_timeline_brings_its_mode_options_and_must_fly_the_model(projected_timeline):
    sim = Simulator("smile", "nonrigid", timeline=projected_timeline)
    assert sim.timeline is projected_timeline
    assert (sim.timeline.mode_basis, sim.timeline.mode_interval) == ("projected", 2.0)
    with pytest.raises(ValueError, match="timeline"):
        Simulator("smile", "rigid", timeline=projected_timeline)
    with pytest.raises(ValueError, match="mode_basis"):
        TimelineSpec(mode_basis="kept")
    with pytest.raises(ValueError, match="mode_interval"):
        TimelineSpec(mode_interval=-1.0)


def test_task_options_reach_the_simulator():
    import gymnasium as gym

    import lvgym  # noqa: F401
    from lvgym.errors import ConfigError
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", mission_time_s=5.0, mode_interval_s=2.0,
                   mode_basis="projected", slosh_frequency="specific_force")
    env.reset(seed=3)
    sim = env.unwrapped.func.sim
    assert sim.timeline.mode_basis == "projected" and sim.timeline.mode_interval == 2.0
    assert sim.slosh_frequency == "specific_force" and sim.setup.slosh_frequency == 1
    np.testing.assert_allclose(sim.timeline.mode_change_t, [2.0, 4.0, 6.0])
    for _ in range(120):                                          # through the change at 2 s
        env.step(np.zeros(2, dtype=np.float32))
    default = gym.make("lvgym/SmileAscent-v0", mission_time_s=5.0).unwrapped.func
    assert default.spec.mode_basis == "held" and default.spec.mode_interval_s is None
    assert default.sim.slosh_frequency == "vacuum_thrust" and default.timeline.mode_change_t.size == 0
    for key, value in (("mode_basis", "rotated"), ("slosh_frequency", "vacuum"), ("mode_interval_s", -1.0)):
        with pytest.raises(ConfigError, match=key):
            gym.make("lvgym/SmileAscent-v0", **{key: value})
