"""Gravity models: published numbers, limiting cases between models, g = -grad U, batching, poles."""

import math

import numba
import numpy as np
import pytest
from scipy.special import lpmv

from lvgym.environment import earth, gravity, registry
from lvgym.errors import ConfigError

GM_EGM, R_EGM = 3.986004415e14, 6378136.3          # EGM2008's own constants (Pavlis et al., 2012)
OMEGA = earth.WGS84_OMEGA


def _points():
    """A few inertial points: low orbit, near the surface, on both poles, high above, random."""
    rng = np.random.default_rng(11)
    dirs = rng.normal(size=(5, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    fixed = [[7.0e6, 1.0e5, -3.0e6], [4.0e6, -3.0e6, 4.5e6], [0.0, 0.0, earth.WGS84_B + 1e3],
             [0.0, 0.0, -(earth.WGS84_B + 2e5)], [-2.0e7, 3.0e7, 1.0e7]]
    return np.vstack([fixed, dirs * rng.uniform(6.4e6, 4.2e7, (5, 1))])


def test_models_are_registered_by_name():
    assert set(registry.names("gravity")) >= {"constant", "point_mass", "j2", "wgs84_normal", "egm2008"}
    assert isinstance(registry.make("gravity", "egm2008"), gravity.EGM2008Gravity)
    assert registry.make("gravity", {"model": "egm2008", "degree": 2}).degree == 2


def test_normal_gravity_zonals_match_tr8350():
    # NIMA TR8350.2 (3rd ed., 2000), chapter 3: the WGS84 normal field's C20, C40, C60, C80 (fully normalised)
    J = gravity.normal_gravity_zonals(n_max=4)
    C = -J / np.sqrt(4 * np.arange(1, 5) + 1)
    published = [-0.484166774985e-03, 0.790303733511e-06, -0.168724961151e-08, 0.346052468394e-11]
    np.testing.assert_allclose(C, published, rtol=1e-9)            # measured: < 1e-11 relative


@pytest.mark.parametrize("lat_deg", [0.0, 45.0, 90.0, -90.0, -30.0, 70.0])
def test_wgs84_normal_plus_centrifugal_is_somigliana(lat_deg):
    # Somigliana's formula, TR8350.2 chapter 4: gamma_e = 9.7803253359, gamma_p = 9.8321849378 m/s^2,
    # gamma = gamma_e (1 + k sin^2 lat) / sqrt(1 - e^2 sin^2 lat), k = b gamma_p / (a gamma_e) - 1
    g_e, g_p = 9.7803253359, 9.8321849378
    k = earth.WGS84_B * g_p / (earth.WGS84_A * g_e) - 1.0
    lat, lon = math.radians(lat_deg), 0.4
    s2 = math.sin(lat) ** 2
    gamma = g_e * (1.0 + k * s2) / math.sqrt(1.0 - earth.WGS84_E2 * s2)
    r = earth.geodetic_to_ecef(lat, lon, 0.0)                # Earth-fixed = inertial at t = 0
    g = gravity.WGS84NormalGravity().acceleration(r, 0.0) + OMEGA ** 2 * np.array([r[0], r[1], 0.0])
    # measured: 4e-13 (equator), 3e-12 (45 deg), 7e-12 (pole) relative
    assert np.linalg.norm(g) == pytest.approx(gamma, rel=1e-9)
    down = earth.C_ne(lat, lon)[2]                            # normal gravity is normal to the ellipsoid
    np.testing.assert_allclose(g / np.linalg.norm(g), down, atol=1e-12)


def test_j2_alone_misses_somigliana_at_the_pole():
    # why wgs84_normal carries J4-J8: J2 alone is 1.2e-5 off normal gravity at the pole (measured)
    r = earth.geodetic_to_ecef(math.pi / 2, 0.0, 0.0)
    g = np.linalg.norm(gravity.J2Gravity().acceleration(r))
    assert abs(g / 9.8321849378 - 1.0) > 1e-6


def test_point_mass_hand_number():
    # GM / a^2 = 3.986004418e14 / 6378137^2 = 9.798285479187 m/s^2 (40-digit decimal arithmetic)
    g = gravity.PointMassGravity().acceleration([0.0, -earth.WGS84_A, 0.0])
    np.testing.assert_allclose(g, [0.0, 9.798285479187299, 0.0], rtol=1e-14)
    assert gravity.PointMassGravity().potential([earth.WGS84_A, 0, 0]) == pytest.approx(
        -9.798285479187299 * earth.WGS84_A, rel=1e-14)


def test_j2_hand_numbers_on_the_equator_and_the_pole():
    # by hand from U = -GM/r (1 - J2 (a/r)^2 (3 sin^2 phi - 1)/2) (Montenbruck & Gill 2000, sec. 3.2):
    # equator at r: g = -GM/r^2 (1 + 3/2 J2 (a/r)^2); along the axis: g = -GM/r^2 (1 - 3 J2 (a/r)^2)
    model = gravity.J2Gravity(gm=3.986e14, radius=6.378e6, j2=1.0e-3)
    r = 7.0e6
    base = 3.986e14 / r ** 2
    equator = [-base * (1 + 1.5e-3 * (6.378 / 7) ** 2), 0, 0]
    pole = [0, 0, base * (1 - 3e-3 * (6.378 / 7) ** 2)]
    np.testing.assert_allclose(model.acceleration([r, 0, 0]), equator, rtol=1e-14)
    np.testing.assert_allclose(model.acceleration([0, 0, -r]), pole, rtol=1e-14)
    assert gravity.J2Gravity().j2 == pytest.approx(1.08262982131e-3, rel=1e-10)   # -sqrt(5) C20, TR8350.2


def test_egm2008_degree_zero_is_the_point_mass():
    r = _points()
    np.testing.assert_allclose(gravity.EGM2008Gravity(degree=0).acceleration(r, 100.0),
                               gravity.PointMassGravity(gm=GM_EGM).acceleration(r), rtol=1e-14, atol=1e-15)


def test_egm2008_c20_only_is_j2():
    C = np.zeros((3, 3))
    C[0, 0], C[2, 0] = 1.0, -0.484165143790815e-03
    harmonic = gravity.HarmonicGravity(C, np.zeros((3, 3)), GM_EGM, R_EGM)
    j2 = gravity.J2Gravity(gm=GM_EGM, radius=R_EGM, j2=-math.sqrt(5.0) * C[2, 0])
    r = _points()
    g_h, u_h = harmonic.field(r, 250.0)
    g_j, u_j = j2.field(r, 250.0)
    np.testing.assert_allclose(g_h, g_j, rtol=0, atol=1e-14 * np.linalg.norm(g_j, axis=1).max())
    np.testing.assert_allclose(u_h, u_j, rtol=1e-14)


def test_egm2008_potential_against_scipy_legendre():
    # independent evaluation: U = -GM/r sum (R/r)^n Pbar_nm(sin phi) (C cos m lam + S sin m lam), with
    # Pbar_nm = sqrt((2 - d_m0)(2n + 1)(n - m)!/(n + m)!) P_nm and scipy's P_nm carrying (-1)^m
    model = gravity.EGM2008Gravity()
    C, S, gm, R = gravity.load_egm2008()
    for x in _points():
        r, phi, lam = np.linalg.norm(x), math.asin(x[2] / np.linalg.norm(x)), math.atan2(x[1], x[0])
        total = 0.0
        for n in range(5):
            for m in range(n + 1):
                norm = math.sqrt((2 - (m == 0)) * (2 * n + 1)
                                 * math.factorial(n - m) / math.factorial(n + m))
                p = (-1) ** m * norm * lpmv(m, n, math.sin(phi))
                total += (R / r) ** n * p * (C[n, m] * math.cos(m * lam) + S[n, m] * math.sin(m * lam))
        assert model.potential(x, 0.0) == pytest.approx(-gm / r * total, rel=1e-13)


@pytest.mark.parametrize("name", ["point_mass", "j2", "wgs84_normal", "egm2008"])
def test_acceleration_is_minus_the_gradient_of_the_potential(name):
    model = registry.make("gravity", name)
    d, t = 2.0, 777.0                      # central differences over 2 m: rounding ~1e-10 relative
    for x in _points()[:6]:
        g = model.acceleration(x, t)
        du = [model.potential(x + d * e, t) - model.potential(x - d * e, t) for e in np.eye(3)]
        fd = -np.array(du) / (2 * d)
        assert np.max(np.abs(g - fd)) < 1e-8 * np.linalg.norm(g)   # measured: at most 2.4e-9 (j2)


@pytest.mark.parametrize("n, m", [(n, m) for n in range(2, 5) for m in range(n + 1)])
def test_each_harmonic_term_is_minus_the_gradient_of_its_potential(n, m):
    # one coefficient at a time, scaled up to 1e-3 so that its term (~1e-2 m/s^2) is checked to 1e-6 of
    # itself; differences of U ~ 6e7 J/kg over 2 m round to ~2e-9 m/s^2 (where the term vanishes: the pole)
    C, S = np.zeros((5, 5)), np.zeros((5, 5))
    C[0, 0], C[n, m], S[n, m] = 1.0, 1e-3, (0.7e-3 if m else 0.0)
    model = gravity.HarmonicGravity(C, S, GM_EGM, R_EGM)
    ref = gravity.PointMassGravity(gm=GM_EGM)
    d = 2.0
    for x in _points()[:4]:
        g = model.acceleration(x) - ref.acceleration(x)
        du = [(model.potential(x + d * e) - ref.potential(x + d * e))
              - (model.potential(x - d * e) - ref.potential(x - d * e)) for e in np.eye(3)]
        np.testing.assert_allclose(g, -np.array(du) / (2 * d), atol=1e-6 * np.linalg.norm(g) + 1e-8)


def test_earth_rotation_enters_the_tesseral_field():
    # g_i(r_i, t) = C_ie(t) g_e(C_ei(t) r_i): the field turns with the Earth
    model = gravity.EGM2008Gravity()
    t = np.array([0.0, 1000.0, 40000.0])
    r_e = np.array([[4.0e6, -3.0e6, 4.5e6]] * 3)
    r_i = np.einsum("bji,bj->bi", earth.C_ei(t), r_e)
    g_i = model.acceleration(r_i, t)
    g_e0 = model.acceleration(r_e[0], 0.0)
    for j in range(3):
        np.testing.assert_allclose(earth.C_ei(t[j]) @ g_i[j], g_e0, rtol=1e-13)
    # at one inertial point the tesseral field changes with time; a zonal field (order 0) does not
    r_fixed = np.array([r_e[0]] * 3)
    dg = model.acceleration(r_fixed, t) - model.acceleration(r_e[0], 0.0)
    assert np.min(np.linalg.norm(dg[1:], axis=1)) > 1e-6          # measured: ~1e-5 m/s^2
    zonal = gravity.EGM2008Gravity(order=0)
    np.testing.assert_allclose(zonal.acceleration(r_fixed, t), zonal.acceleration(r_fixed, 0.0), rtol=1e-14)


@pytest.mark.parametrize("name", ["constant", "point_mass", "j2", "wgs84_normal", "egm2008"])
def test_batch_equals_one_by_one(name):
    model = registry.make("gravity", name)
    r = _points()
    t = np.linspace(0.0, 5000.0, len(r))
    g, u = model.field(r, t)
    assert g.shape == (len(r), 3) and u.shape == (len(r),)
    for j in range(len(r)):
        gj, uj = model.field(r[j], t[j])
        assert gj.shape == (3,)
        np.testing.assert_array_equal(g[j], gj)
        assert u[j] == uj


@numba.njit(cache=True)
def _compiled_caller(r, t, p, out):
    """What a simulator does: call the one gravity kernel from compiled code with the model's params."""
    for j in range(r.shape[0]):
        out[j, 0], out[j, 1], out[j, 2] = gravity.gravity_k(r[j, 0], r[j, 1], r[j, 2], t, p)


def test_one_kernel_serves_every_model_from_compiled_code():
    r = _points()
    for name in registry.names("gravity"):
        model = registry.make("gravity", name)
        out = np.empty((len(r), 3))
        _compiled_caller(r, 42.0, model.params, out)
        np.testing.assert_array_equal(out, model.acceleration(r, 42.0))


@pytest.mark.parametrize("name", ["point_mass", "j2", "wgs84_normal", "egm2008"])
def test_a_point_on_the_pole_works(name):
    model = registry.make("gravity", name)
    for z in (earth.WGS84_B, -earth.WGS84_B - 3e5):
        g = model.acceleration([0.0, 0.0, z], 10.0)
        assert np.all(np.isfinite(g))
        assert -g[2] * np.sign(z) == pytest.approx(GM_EGM / z ** 2, rel=5e-3)     # pointing at the centre
        if name != "egm2008":                                                       # zonal: no pull sideways
            assert np.hypot(g[0], g[1]) == 0.0
    # the pole is no special point: the field is continuous across it
    g0 = model.acceleration([0.0, 0.0, earth.WGS84_B])
    g1 = model.acceleration([1e-3, 1e-3, earth.WGS84_B])
    np.testing.assert_allclose(g0, g1, atol=1e-8)


def test_constant_gravity():
    model = registry.make("gravity", {"model": "constant", "g_i": [-9.81, 0.0, 0.0]})
    np.testing.assert_array_equal(model.acceleration(np.ones((4, 3)), 3.0), [[-9.81, 0.0, 0.0]] * 4)
    assert model.potential([100.0, 0.0, 0.0]) == pytest.approx(981.0)


@pytest.mark.parametrize("spec, key, words", [
    ({"model": "egm2008", "degree": 5}, "gravity.degree", "the shipped EGM2008 data stops at degree 4"),
    ({"model": "egm2008", "degree": 2.0}, "gravity.degree", "an integer in [0, 4]"),
    ({"model": "egm2008", "degree": 3, "order": 4}, "gravity.order", "an integer in [0, degree = 3]"),
    ({"model": "point_mass", "gm": -1.0}, "gravity.gm", "a positive finite number"),
    ({"model": "j2", "j2": float("nan")}, "gravity.j2", "|J2| <= 0.1"),
    ({"model": "constant", "g_i": [0.0, 9.81]}, "gravity.g_i", "three finite numbers"),
])
def test_bad_options_raise_config_error(spec, key, words):
    with pytest.raises(ConfigError) as err:
        registry.make("gravity", spec)
    assert err.value.key == key and words in err.value.allowed


def test_lower_order_drops_the_tesseral_terms():
    full, zonal = gravity.EGM2008Gravity(degree=4), gravity.EGM2008Gravity(degree=4, order=0)
    C, S, gm, R = gravity.load_egm2008()
    C[:, 1:], S[:, :] = 0.0, 0.0
    ref = gravity.HarmonicGravity(C, S, gm, R)
    r = _points()
    np.testing.assert_allclose(zonal.acceleration(r), ref.acceleration(r), rtol=1e-14)
    assert np.max(np.abs(full.acceleration(r) - zonal.acceleration(r))) > 1e-6
