"""Dispersions of protocol v1: the load dispersions in the compiled flight conditions against hand
arithmetic, and each randomisation name acting on what it names."""

import gymnasium as gym
import numpy as np
import pytest

import lvgym  # noqa: F401
from lvgym.envs.spec import RANDOMIZE, RANDOMIZE_V0, TaskSpec
from lvgym.simulator import Simulator
from lvgym.simulator.layouts import CONDITIONS, CONTEXT, DISPERSION


def _conditions():
    sim = Simulator("smile", "rigid", t_end=5.0)
    sim.reset(1, rng=np.random.default_rng(0))
    for _ in range(150):                          # 3 s: off the pad, with an angle of attack from the kick
        sim.step(np.array([[0.01, -0.005]]), 0.02)
    d = sim.get_rows()
    return sim, d


def test_load_dispersions_scale_the_forces_and_move_the_centre_of_pressure():
    sim, d = _conditions()
    kn, ka, ks, dx = 1.07, 0.95, 1.02, 0.3
    disp = DISPERSION.pack({"thrust_scale": ks, "normal_scale": kn, "axial_scale": ka, "cp_shift": dx})
    # the same state and time, conditions recomputed with the dispersions
    sim.set_rows([0], d)
    CONTEXT.view(sim.data.ctx[:, :CONTEXT.size], "dispersion")[0] = disp
    sim.update_conditions()
    view = lambda c, k: CONDITIONS.view(c, k)            # noqa: E731
    f0, m0 = view(d.conditions[0], "f_aero_b"), view(d.conditions[0], "m_aero_b")
    f1, m1 = view(sim.data.conditions[0], "f_aero_b"), view(sim.data.conditions[0], "m_aero_b")
    assert abs(f0[2]) > 10.0 and abs(f0[1]) > 1.0       # a normal force to act on
    np.testing.assert_allclose(f1, [ka * f0[0], kn * f0[1], kn * f0[2]], rtol=1e-12)
    np.testing.assert_allclose(m1, [m0[0], kn * m0[1] - dx * kn * f0[2], kn * m0[2] + dx * kn * f0[1]], rtol=1e-12)
    t0, t1 = view(d.conditions[0], "thrust")[0], view(sim.data.conditions[0], "thrust")[0]
    assert t1 == pytest.approx(ks * t0, rel=1e-12)


def test_randomize_true_keeps_the_v0_set():
    spec = TaskSpec(vehicle="smile", randomize=True)
    assert spec.randomize == frozenset(RANDOMIZE_V0)
    assert set(RANDOMIZE) - set(RANDOMIZE_V0) == {"aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency",
                                                  "bending_damping", "servo_bandwidth", "servo_delay"}


@pytest.mark.parametrize("name", ["aerodynamics", "thrust_level", "slosh_mass", "slosh_frequency", "bending_damping"])
def test_each_v1_randomisation_draws_what_it_names(name):
    env = gym.make("lvgym/SmileAscent-v0", model="nonrigid", mission_time_s=1.0, randomize=[name]).unwrapped
    func = env.func
    scale, offset, mis, loads, servo = func.dispersions(np.random.default_rng(5))
    again = func.dispersions(np.random.default_rng(5))
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
    sim = Simulator("smile", "rigid", t_end=2.0, servo=Servo(15.0, 0.7))
    sim.reset(1, rng=np.random.default_rng(0), servo_dispersion=servo_dispersion)
    sim.step(np.array([[0.01, 0.0]]), 0.02)              # two physics steps of 10 ms
    first = sim.gimbal[0, 0]
    sim.step(np.array([[0.01, 0.0]]), 0.02)
    return first, sim.gimbal[0, 0]


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
