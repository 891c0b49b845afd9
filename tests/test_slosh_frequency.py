"""The slosh damper's frequency from the axial specific force the pendulums feel (issue 16, section 2):
hand numbers of the kernels, the coast, and the flight with either option."""

import math

import numpy as np
import pytest

from lvgym.dynamics import NonRigidModel
from lvgym.simulator import CONDITIONS, PhysicsSpec, Simulator, TimelineSpec
from lvgym.simulator.piece import axial_specific_force_k, slosh_frequency_k


@pytest.fixture()
def two_pendulums():
    """Parameters of B (9,000 kg) with pendulums of 600 kg on 0.4 m, 400 kg on 0.1 m and an empty
    third one, damping ratio 0.01."""
    dyn = NonRigidModel(3, 2)
    slosh = [{"m": 600.0, "length": 0.4, "r_hinge": [-3.0, 0, 0], "zeta": 0.01, "omega": 0.0, "phi": [0.0, 0.0]},
             {"m": 400.0, "length": 0.1, "r_hinge": [-6.0, 0, 0], "zeta": 0.01, "omega": 0.0, "phi": [0.0, 0.0]},
             {"m": 0.0, "length": 0.0, "r_hinge": [-7.0, 0, 0], "zeta": 0.01, "omega": 0.0, "phi": [0.0, 0.0]}]
    p = dyn.params(m_b=9000.0, J_b=np.eye(3), r_cg=[-5.0, 0, 0], r_gimbal=[-10.0, 0, 0], omega_modes=[60.0, 160.0],
                   zeta_modes=[0.01, 0.01], phi_gimbal=[0.0, 0.0], dphi_gimbal=[0.0, 0.0], slosh=slosh)
    return dyn, p


def _omega(dyn, p, j):
    return float(p[dyn.layout.slosh_param(j, "omega")][0])


def _conditions(thrust_x, aero_x):
    cond = CONDITIONS.zeros()
    CONDITIONS.view(cond, "thrust_b")[:] = [thrust_x, 0.0, 300.0]
    CONDITIONS.view(cond, "f_aero_b")[:] = [aero_x, 50.0, 0.0]
    return cond


def test_damping_coefficient_of_a_given_specific_force(two_pendulums):
    dyn, p = two_pendulums
    # 120 kN of thrust against 20 kN of drag on 10,000 kg: a_x = 10 m/s^2
    a_x = axial_specific_force_k(_conditions(120e3, -20e3), 0, p, 3, 2)
    assert a_x == pytest.approx(10.0, rel=1e-14)
    ones, zeros = np.ones_like(p), np.zeros_like(p)
    slosh_frequency_k(p, ones, zeros, a_x, 3, 2)
    # sqrt(10 / 0.4) = 5 rad/s and sqrt(10 / 0.1) = 10 rad/s; the empty tank has none
    assert _omega(dyn, p, 0) == pytest.approx(5.0, rel=1e-14)
    assert _omega(dyn, p, 1) == pytest.approx(10.0, rel=1e-14)
    assert _omega(dyn, p, 2) == 0.0
    # the damper's coefficient per unit slosh mass, 2 zeta omega L^2 [m^2/s]: 0.016 and 0.002
    c = [2 * 0.01 * _omega(dyn, p, j) * L ** 2 for j, L in ((0, 0.4), (1, 0.1))]
    assert c == pytest.approx([0.016, 0.002], rel=1e-14)


def test_coast_frequency_from_the_drag_and_the_drag_free_limit(two_pendulums):
    dyn, p = two_pendulums
    # coast: no thrust, 500 N of drag on 10 t: the liquid is pushed forward at 0.05 m/s^2
    a_x = axial_specific_force_k(_conditions(0.0, -500.0), 0, p, 3, 2)
    assert a_x == pytest.approx(-0.05, rel=1e-14)
    slosh_frequency_k(p, np.ones_like(p), np.zeros_like(p), a_x, 3, 2)
    assert _omega(dyn, p, 0) == pytest.approx(math.sqrt(0.125), rel=1e-14)
    assert _omega(dyn, p, 1) == pytest.approx(math.sqrt(0.5), rel=1e-14)
    # no force at all: no frequency, no damper
    slosh_frequency_k(p, np.ones_like(p), np.zeros_like(p), 0.0, 3, 2)
    assert _omega(dyn, p, 0) == 0.0 and _omega(dyn, p, 1) == 0.0


def test_dispersion_of_the_frequency_applies_on_top(two_pendulums):
    dyn, p = two_pendulums
    scale, offset = np.ones_like(p), np.zeros_like(p)
    i = dyn.layout.slosh_param(0, "omega")
    scale[i], offset[i] = 1.2, 0.5
    slosh_frequency_k(p, scale, offset, 10.0, 3, 2)
    assert _omega(dyn, p, 0) == pytest.approx(5.0 * 1.2 + 0.5, rel=1e-14)


@pytest.fixture(scope="module")
def flights():
    """SMILE, slosh model, zero gimbal, to 44.5 s (through burnout into the drag coast), both options."""
    out = {}
    for option in ("vacuum_thrust", "specific_force"):
        sim = Simulator("smile", "slosh", timeline=TimelineSpec(t_end=46.0),
                        physics=PhysicsSpec(slosh_frequency=option))
        d = sim.reset(1)
        v = sim.view(d)
        lay = sim.layout
        i_w = [lay.slosh_param(j, "omega").start for j in range(sim.dynamics.n_slosh)]
        i_L = [lay.slosh_param(j, "length").start for j in range(sim.dynamics.n_slosh)]
        rec = {}
        for k in range(int(round(44.5 / 0.02))):
            sim.step(d, [[0.0, 0.0]], 0.02)
            t = round(float(v.t[0]), 6)
            if t in (10.0, 43.5, 44.5):
                m = v.p[0, lay.params["m_b"]][0] + v.p[0, [lay.slosh_param(j, "m").start
                                                           for j in range(sim.dynamics.n_slosh)]].sum()
                a_x = (v.conditions("thrust_b")[0, 0] + v.conditions("f_aero_b")[0, 0]) / m
                rec[t] = (v.p[0, i_w].copy(), v.p[0, i_L].copy(), a_x, sim.timeline.params_at([t])[0, i_w])
        out[option] = rec
    return out


def test_vacuum_thrust_option_flies_the_timelines_frequency(flights):
    for t, (omega, _, _, table) in flights["vacuum_thrust"].items():
        np.testing.assert_allclose(omega, table, rtol=2e-3)          # held over the last piece
    assert np.all(flights["vacuum_thrust"][44.5][0] == 0.0)          # no thrust: no damper (v0)


def test_specific_force_option_follows_the_flight_conditions(flights):
    for t, (omega, L, a_x, table) in flights["specific_force"].items():
        on = L > 0.0
        # the frequency of the last piece, from its start's conditions: within the change over one step
        np.testing.assert_allclose(omega[on], np.sqrt(abs(a_x) / L[on]), rtol=5e-3)
    omega10, _, a10, table10 = flights["specific_force"][10.0]
    assert a10 > 0.0 and np.all(omega10 < table10)                   # ambient pressure and drag take their share
    omega_c, L_c, a_c, _ = flights["specific_force"][44.5]
    assert a_c < 0.0                                                 # the drag coast
    assert np.all(omega_c[L_c > 0.0] > 0.0)                          # damped through it
