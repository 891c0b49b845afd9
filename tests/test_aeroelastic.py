"""Aeroelastic strip theory (lvgym/environment/aeroelastic.py; thesis eq. 2.14-2.19)."""

import math

import numpy as np
import pytest

from lvgym.environment.aeroelastic import StripAeroelastic, resample_modes
from lvgym.environment.barrowman import BarrowmanAero
from lvgym.errors import ConfigError

GEOMETRY = {"nose": {"shape": "ogive", "length": 0.9}, "body": {"diameter": 0.28, "length": 7.3},
            "fins": {"count": 4, "root_chord": 0.6, "tip_chord": 0.25, "span": 0.3, "sweep": 0.35,
                     "station": -7.6, "thickness": 0.006}}
X_REF = -4.1


@pytest.fixture(scope="module")
def vehicle():
    return BarrowmanAero(**GEOMETRY, x_ref=X_REF)


def strip_model(vehicle, n, **kw):
    """Strips of the generator at every table Mach number (CNa per metre against Mach)."""
    mach = vehicle.axes[0]
    x, width, _ = vehicle.strips(0.0, n)
    per_m = np.array([vehicle.strips(m, n)[2] / width for m in mach])
    return StripAeroelastic(x, width, per_m, vehicle.s_ref, mach=mach, **kw)


def test_rigid_modes_reduce_to_the_tables_cn_alpha(vehicle):
    # zero mode shapes (K = 2 per plane) with nonzero eta: only the rigid crossflow remains;
    # the strips sum to the table's CNa (generator.cn_alpha at a grid Mach, 0.4 = 136 m/s / 340)
    k, n = 2, 200
    model = strip_model(vehicle, n, phi=np.zeros((k, n)), dphi=np.zeros((k, n)))
    speed, alpha, beta = 136.0, 1e-3, -2e-3
    v = speed * np.array([math.cos(alpha) * math.cos(beta), math.sin(beta),
                          math.sin(alpha) * math.cos(beta)])
    f, m, f_eta = model.loads(v, np.zeros(3), 1.0, 340.0, X_REF, eta=[0.1, -0.2, 0.3, 0.4],
                              eta_dot=[1.0, 2.0, -1.0, 0.5])
    qs = 0.5 * speed ** 2 * vehicle.s_ref
    cna = vehicle.cn_alpha(0.4)
    assert model.cn_alpha(0.4) == pytest.approx(cna, rel=1e-12)
    assert f[2] == pytest.approx(-qs * cna * v[2] / speed, rel=1e-12)
    assert f[1] == pytest.approx(-qs * cna * v[1] / speed, rel=1e-12)
    assert np.all(f_eta == 0.0)
    # pitching moment about x_ref: the strips' CP is the generator's within half a strip
    x_cp_strips = -m[1] / f[2] + X_REF                 # m_y = -(x_cp - x_cg) f_z
    assert x_cp_strips == pytest.approx(vehicle.x_cp(0.4), abs=0.5 * vehicle.length / n)


def test_body_rate_gives_the_tables_pitch_damping(vehicle):
    # pitch rate q about the CG at x_ref: m_y = rho V S d^2 / 4 * Cmq q with the generator's Cmq
    # (the same strip integral, 400 strips)
    model = strip_model(vehicle, 400)
    speed, q = 136.0, 0.2
    _, m, _ = model.loads(np.array([speed, 0.0, 0.0]), [0.0, q, 0.0], 1.0, 340.0, X_REF)
    cmq = vehicle.coefficients(0.4, 0.0)["Cmq"]
    assert m[1] == pytest.approx(0.25 * speed * vehicle.s_ref * 0.28 ** 2 * cmq * q, rel=1e-9)
    assert m[1] < 0.0


def hand_model(**kw):
    # three strips at -1, -2, -3 m with CNa shares 0.5, 0.2, 1.0 (width 1 m), S = 0.5 m^2, one mode
    phi = np.array([[0.1, -0.05, 0.2]])
    dphi = np.array([[0.02, 0.04, -0.03]])
    return StripAeroelastic([-1.0, -2.0, -3.0], 1.0, [0.5, 0.2, 1.0], 0.5, phi=phi, dphi=dphi, **kw)


def test_pure_bending_slope_by_hand():
    # V = u = 100 m/s along x_b, rho 1: rho V S / 2 = 25. eta_z = 2: slopes 2 dphi = 0.04, 0.08,
    # -0.06; crossflow -u s = -4, -8, +6 m/s; dF_z = -25 c (-u s) = 50, 40, -150 N;
    # f_eta_z = 0.1*50 - 0.05*40 + 0.2*(-150) = -27; f_z = -60 N;
    # m_y about x_cg = -2: -sum (x - x_cg) dF_z = -(1*50 + 0 - 1*(-150)) = -200 N m
    f, m, f_eta, dfs = hand_model().loads([100.0, 0.0, 0.0], np.zeros(3), 1.0, 340.0, -2.0,
                                          eta=[0.0, 2.0], eta_dot=[0.0, 0.0], strips=True)
    np.testing.assert_allclose(dfs[:, 1], [50.0, 40.0, -150.0])
    np.testing.assert_allclose(f_eta, [0.0, -27.0])
    np.testing.assert_allclose(f, [0.0, 0.0, -60.0])
    np.testing.assert_allclose(m, [0.0, -200.0, 0.0])


def test_deflection_rate_by_hand():
    # eta_dot_y = 3: plunge velocity phi eta_dot = 0.3, -0.15, 0.6 m/s; dF_y = -25 c v_j =
    # -3.75, 0.75, -15 N; f_eta_y = 0.1*(-3.75) - 0.05*0.75 + 0.2*(-15) = -3.4125
    f, m, f_eta = hand_model().loads([100.0, 0.0, 0.0], np.zeros(3), 1.0, 340.0, -2.0,
                                     eta=[0.0, 0.0], eta_dot=[3.0, 0.0])
    np.testing.assert_allclose(f_eta, [-3.4125, 0.0])
    np.testing.assert_allclose(f, [0.0, -18.0, 0.0])
    # m_z = sum (x - x_cg) dF_y = 1*(-3.75) + 0 - 1*(-15) = 11.25
    np.testing.assert_allclose(m, [0.0, 0.0, 11.25])


def test_virtual_work_consistency():
    # f_eta = sum_j phi_k(x_j) dF(x_j), and for any virtual modal displacement d_eta the work of the
    # strip forces on the displaced stations, sum_j dF_j . (phi(x_j) d_eta), equals f_eta . d_eta
    rng = np.random.default_rng(11)
    n, k = 40, 3
    x = -np.sort(rng.uniform(0.0, 10.0, n))
    phi, dphi = rng.normal(0, 0.1, (k, n)), rng.normal(0, 0.05, (k, n))
    model = StripAeroelastic(x, 0.25, rng.uniform(0.0, 2.0, n), 0.3, phi=phi, dphi=dphi)
    v, w = rng.normal(0, 80, 3) + [300, 0, 0], rng.normal(0, 0.2, 3)
    eta, eta_dot = rng.normal(0, 0.1, 2 * k), rng.normal(0, 1.0, 2 * k)
    f, m, f_eta, dfs = model.loads(v, w, 0.7, 320.0, -4.0, eta=eta, eta_dot=eta_dot, strips=True)
    np.testing.assert_allclose(f_eta[:k], phi @ dfs[:, 0], rtol=1e-12)
    np.testing.assert_allclose(f_eta[k:], phi @ dfs[:, 1], rtol=1e-12)
    d_eta = rng.normal(0, 1.0, 2 * k)
    work = np.sum(dfs[:, 0] * (d_eta[:k] @ phi)) + np.sum(dfs[:, 1] * (d_eta[k:] @ phi))
    assert work == pytest.approx(f_eta @ d_eta, rel=1e-10)
    np.testing.assert_allclose(f[1:], dfs.sum(axis=0), rtol=1e-12)
    np.testing.assert_allclose(m[1:], [-np.sum((x + 4.0) * dfs[:, 1]), np.sum((x + 4.0) * dfs[:, 0])],
                               rtol=1e-10)


def test_elastic_increment_only():
    # include_rigid=False: no body load from rigid crossflow, the same f_eta as the full model
    v, w = [100.0, 5.0, -8.0], [0.0, 0.1, 0.05]
    full = hand_model().loads(v, w, 1.0, 340.0, -2.0, eta=[0.0, 0.0], eta_dot=[0.0, 0.0])
    inc = hand_model(include_rigid=False).loads(v, w, 1.0, 340.0, -2.0, eta=[0.0, 0.0], eta_dot=[0.0, 0.0])
    assert np.all(inc[0] == 0.0) and np.all(inc[1] == 0.0)
    np.testing.assert_array_equal(inc[2], full[2])
    assert np.all(full[2] != 0.0)


def test_y_and_z_planes_are_symmetric():
    # a quarter turn about x_b maps (v, w) -> (-w, v), eta_z -> eta_y ... f_eta_y(v) = f_eta_z(w)
    model = hand_model()
    _, _, fz = model.loads([100.0, 0.0, 7.0], [0.0, -0.1, 0.0], 1.0, 340.0, -2.0, eta=[0.0, 0.5],
                           eta_dot=[0.0, 1.0])
    _, _, fy = model.loads([100.0, 7.0, 0.0], [0.0, 0.0, 0.1], 1.0, 340.0, -2.0, eta=[0.5, 0.0],
                           eta_dot=[1.0, 0.0])
    assert fy[0] == pytest.approx(fz[1]) and fy[1] == 0.0 and fz[0] == 0.0


def test_zero_airspeed_gives_zero_loads():
    f, m, f_eta = hand_model().loads(np.zeros(3), [1.0, 1.0, 1.0], 1.2, 340.0, -2.0, eta=[1.0, 1.0],
                                     eta_dot=[5.0, -5.0])
    assert np.all(f == 0.0) and np.all(m == 0.0) and np.all(f_eta == 0.0)


def test_batch_equals_single():
    model = hand_model()
    rng = np.random.default_rng(3)
    v, w = rng.normal(0, 100, (5, 3)), rng.normal(0, 0.2, (5, 3))
    eta, eta_dot = rng.normal(0, 0.1, (5, 2)), rng.normal(0, 1, (5, 2))
    rho = rng.uniform(0.2, 1.2, 5)
    f, m, fe = model.loads(v, w, rho, 330.0, -2.0, eta=eta, eta_dot=eta_dot)
    for j in range(5):
        fj, mj, fej = model.loads(v[j], w[j], rho[j], 330.0, -2.0, eta=eta[j], eta_dot=eta_dot[j])
        np.testing.assert_array_equal(f[j], fj)
        np.testing.assert_array_equal(m[j], mj)
        np.testing.assert_array_equal(fe[j], fej)


def test_resample_modes_and_bad_inputs():
    phi, dphi = resample_modes([-0.5, -1.5], [0.0, -1.0, -2.0], [[0.0, 1.0, 4.0]], [[1.0, 2.0, 3.0]])
    np.testing.assert_allclose(phi, [[0.5, 2.5]])
    np.testing.assert_allclose(dphi, [[1.5, 2.5]])
    with pytest.raises(ConfigError, match="x_strip"):
        StripAeroelastic([1.0, -1.0], 1.0, [1.0, 1.0], 1.0)
    with pytest.raises(ConfigError, match="cna_per_m"):
        StripAeroelastic([-1.0, -2.0], 1.0, [1.0], 1.0)
    with pytest.raises(ConfigError, match="phi"):
        StripAeroelastic([-1.0, -2.0], 1.0, [1.0, 1.0], 1.0, phi=[[1.0, 2.0, 3.0]], dphi=[[1.0, 2.0, 3.0]])
