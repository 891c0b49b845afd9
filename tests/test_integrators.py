"""Fixed-step RK4 (integrating-factor and classic), event alignment, adaptive scipy solvers."""

import numpy as np
import pytest

from lvgym.dynamics import NonRigidModel, compile_loads, integrate, step_batch
from lvgym.dynamics.model import _grid


def _free_mode(zeta=0.0):
    model = NonRigidModel(0, 1)
    omega = 2 * np.pi * 15
    p = model.params(m_b=50.0, J_b=[1, 200, 200], omega_modes=[omega], zeta_modes=[zeta])
    x = model.layout.zeros_state()
    x[model.layout.state["eta"]] = [0.2, 0.5]
    x[model.layout.state["eta_dot"]] = [0.1, -0.25]
    return model, x, p, omega


@pytest.mark.parametrize("zeta", [0.0, 0.02, 1.0, 1.5])
def test_integrating_factor_rk4_propagates_free_modes_exactly(zeta):
    model, x, p, omega = _free_mode(zeta)
    t = 1.0
    x1 = model.step(x, p, model.loads(), 1e-2, 100)
    # analytic damped oscillator from scipy's matrix exponential
    from scipy.linalg import expm
    L = np.array([[0.0, 1.0], [-omega ** 2, -2 * zeta * omega]])
    for plane in range(2):
        y0 = [x[13 + plane], x[15 + plane]]
        np.testing.assert_allclose([x1[13 + plane], x1[15 + plane]], expm(L * t) @ y0, atol=1e-12)


def test_classic_rk4_loses_mode_energy_as_predicted():
    """Classical RK4 multiplies an undamped mode's energy by 1 - (Omega h)^6/72 per step."""
    model, x, p, omega = _free_mode()
    h, n = 1e-3, 15000
    e0 = model.energy(x, p, [0, 0, 0])["elastic"] + model.energy(x, p, [0, 0, 0])["kinetic"]
    x1 = model.step(x, p, model.loads(), h, n, method="rk4-classic")
    e1 = model.energy(x1, p, [0, 0, 0])["elastic"] + model.energy(x1, p, [0, 0, 0])["kinetic"]
    z = omega * h
    assert e1 / e0 == pytest.approx((1 - z ** 6 / 72 + z ** 8 / 576) ** n, rel=1e-9)


def test_integrating_factor_equals_classic_without_modes():
    model = NonRigidModel(2, 0)
    p = model.params(m_b=10.0, J_b=[1, 3, 3], slosh=[{"m": 1.0, "length": 0.5, "r_hinge": [1, 0, 0]},
                                                    {"m": 2.0, "length": 0.7, "r_hinge": [-1, 0, 0]}])
    x = model.layout.zeros_state()
    x[model.layout.state["omega_si_s"]] = [0.3, 0.1, -0.2, 0.4]
    u = model.loads(thrust_b=[300, 5, 0], g_i=[-9.8, 0, 0])
    np.testing.assert_array_equal(model.step(x, p, u, 1e-3, 50),
                                  model.step(x, p, u, 1e-3, 50, method="rk4-classic"))


def test_event_grid_lands_on_events():
    grid = _grid(0.0, 1.0, 0.3, [0.5, 0.55, 2.0])
    assert grid[0] == 0.0 and grid[-1] == 1.0
    assert 0.5 in grid and 0.55 in grid
    assert np.all(np.diff(grid) <= 0.3 + 1e-12) and np.all(np.diff(grid) > 0)


def test_adaptive_solvers_match_rk4_on_piecewise_loads():
    model = NonRigidModel()
    p = model.params(m_b=2.0, J_b=[1, 1, 1])

    def loads(t):
        return model.loads(f_b_i=[2.0 if t < 1.0 else -2.0, 0, 0], m_b_b=[0, 0.1, 0])

    rk4 = integrate(model, model.layout.zeros_state(), p, loads, (0, 2), dt=0.01, t_events=[1.0])
    for method in ("RK45", "DOP853"):
        ref = integrate(model, model.layout.zeros_state(), p, loads, (0, 2), method=method,
                        t_events=[1.0], record_dt=0.5)
        assert ref.t[-1] == 2.0
        np.testing.assert_allclose(ref.x[-1], rk4.x[-1], atol=1e-8)
    assert rk4.x[-1, 0] == pytest.approx(1.0)   # +1 m/s2 for 1 s then -1 m/s2: 1 m, at rest


def test_custom_loads_function_is_evaluated_at_every_stage():
    """A state-dependent load (a spring pulling the CG to the origin) integrated to fourth order."""
    model = NonRigidModel()
    lay = model.layout

    def spring(t, x, p, c, u):
        for i in range(u.size):
            u[i] = 0.0
        u[0] = -c[0] * x[0]

    loads_fn = compile_loads(spring)
    p = model.params(m_b=1.0, J_b=[1, 1, 1])[None, :]
    errors = []
    for h in (0.02, 0.01):
        x = lay.zeros_state(batch=1)
        x[0, 0] = 1.0
        step_batch(loads_fn, x, p.copy(), np.array([[4.0]]), 0.0, h, int(round(2.0 / h)), 0, 0, True,
                   lay.n_u)
        errors.append(abs(x[0, 0] - np.cos(2.0 * 2.0)))
    assert errors[1] < 1e-6
    assert errors[0] / errors[1] == pytest.approx(16, rel=0.1)


def test_bad_arguments():
    model = NonRigidModel()
    p = model.params(m_b=1.0, J_b=[1, 1, 1])
    x = model.layout.zeros_state()
    with pytest.raises(ValueError, match="method 'euler'"):
        model.step(x, p, model.loads(), 0.1, method="euler")
    with pytest.raises(ValueError, match="dt = 0"):
        model.step(x, p, model.loads(), 0.0)
    with pytest.raises(ValueError, match="allowed"):
        integrate(model, x, p, model.loads(), (0, 1), method="LSODA")


def test_divergence_is_reported_with_its_time():
    model = NonRigidModel(0, 1)
    p = model.params(m_b=1.0, J_b=[1, 1, 1], omega_modes=[2000.0])
    x = model.layout.zeros_state()
    x[model.layout.state["eta"]] = 1.0
    with pytest.raises(FloatingPointError, match="not finite at t ="):
        integrate(model, x, p, model.loads(), (0, 5), dt=0.01, method="rk4-classic")
