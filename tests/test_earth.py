"""Earth model: WGS84 geodetic <-> Earth-fixed, rotation, NED and launch frames, launch site."""

import math

import numpy as np
import pytest

from lvgym.rotations import quat_to_dcm
from lvgym.environment import earth
from lvgym.environment.earth import LaunchSite
from lvgym.errors import ConfigError

A, B = earth.WGS84_A, earth.WGS84_B


def _C_ib(q):
    """Body -> inertial DCM built by the dynamics core from the scalar-first q_bi."""
    C = np.empty((3, 3))
    quat_to_dcm(*q, C)
    return C


def test_wgs84_derived_constants():
    # NIMA TR8350.2 (2000) table 3.3: b = 6356752.3142 m, e^2 = 6.69437999014e-3
    assert B == pytest.approx(6356752.3142, abs=1e-4)
    assert earth.WGS84_E2 == pytest.approx(6.69437999014e-3, rel=1e-12)


@pytest.mark.parametrize("lat_deg, lon_deg, h, r_expected", [
    # hand numbers: x = (N + h) cos(lat) cos(lon), y = (N + h) cos(lat) sin(lon),
    # z = (N (1 - e^2) + h) sin(lat), N = a / sqrt(1 - e^2 sin^2 lat), 40-digit decimal arithmetic
    (0.0, 0.0, 0.0, (6378137.0, 0.0, 0.0)),
    (90.0, 0.0, 0.0, (0.0, 0.0, 6356752.314245179)),
    (-90.0, 123.0, 500.0, (0.0, 0.0, -6357252.314245179)),
    (0.0, 90.0, 1000.0, (0.0, 6379137.0, 0.0)),
    (45.0, 45.0, 0.0, (3194419.145060574, 3194419.145060574, 4487348.408865920)),
    (30.0, -60.0, 1000.0, (2764561.332348310, -4788360.688267582, 3170873.735383638)),
])
def test_known_geodetic_ecef_pairs(lat_deg, lon_deg, h, r_expected):
    r = earth.geodetic_to_ecef(math.radians(lat_deg), math.radians(lon_deg), h)
    np.testing.assert_allclose(r, r_expected, atol=1e-6)
    lat, lon, hh = earth.ecef_to_geodetic(np.array(r_expected))
    assert lat == pytest.approx(math.radians(lat_deg), abs=1e-12)
    assert hh == pytest.approx(h, abs=1e-6)
    if abs(lat_deg) < 90.0:
        assert lon == pytest.approx(math.radians(lon_deg), abs=1e-12)


def test_round_trip_below_a_millimetre_and_a_nanoradian_poles_and_high_altitude():
    rng = np.random.default_rng(20240704)
    n = 20000
    lat = rng.uniform(-math.pi / 2, math.pi / 2, n)
    lon = rng.uniform(-math.pi, math.pi, n)
    h = rng.uniform(-1e4, 4.2e7, n)                  # below sea level up to beyond GEO
    lat[:6] = [math.pi / 2, -math.pi / 2, math.pi / 2 - 1e-10, -math.pi / 2 + 1e-10, 0.0, 0.0]
    h[:6] = [0.0, 4.2e7, 100.0, 0.0, -1e4, 4.2e7]
    r = earth.geodetic_to_ecef(lat, lon, h)
    lat2, lon2, h2 = earth.ecef_to_geodetic(r)
    # measured: 4.4e-16 rad, 2.3e-8 m, 2.4e-8 m
    assert np.max(np.abs(lat2 - lat)) < 1e-9
    assert np.max(np.abs(h2 - h)) < 1e-3
    dlon = np.angle(np.exp(1j * (lon2 - lon)))[2:]   # longitude is undefined on the poles themselves
    assert np.max(np.abs(dlon)) < 1e-9
    assert np.max(np.linalg.norm(earth.geodetic_to_ecef(lat2, lon2, h2) - r, axis=1)) < 1e-3


def test_earth_rotation_dcm():
    ts = np.array([0.0, 10.0, 3600.0, 2 * math.pi / earth.WGS84_OMEGA])
    C = earth.C_ei(ts)
    for Cj in C:
        np.testing.assert_allclose(Cj @ Cj.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(Cj) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(C[0], np.eye(3))
    np.testing.assert_allclose(C[-1], np.eye(3), atol=1e-12)     # one sidereal turn
    # a point fixed on the equator at longitude 0 moves east (+y_i) in the inertial frame
    r_i = earth.C_ei(3600.0).T @ np.array([A, 0.0, 0.0])
    angle = earth.WGS84_OMEGA * 3600.0
    np.testing.assert_allclose(r_i, [A * math.cos(angle), A * math.sin(angle), 0.0], atol=1e-6)


def test_pad_velocity_at_the_equator_is_omega_a():
    site = LaunchSite(0.0, 0.0, 0.0, 90.0)
    # hand number: omega_e a = 7.292115e-5 * 6378137 = 465.10108489755 m/s, eastwards (+y at lon 0)
    np.testing.assert_allclose(site.v_pad_i, [0.0, 465.10108489755, 0.0], atol=1e-9)
    # and it is the time derivative of the pad's inertial position
    site = LaunchSite(37.1, -6.7, 20.0, 250.0)
    dt = 1e-3
    fd = (earth.C_ei(dt).T @ site.r_pad_e - earth.C_ei(-dt).T @ site.r_pad_e) / (2 * dt)
    np.testing.assert_allclose(site.v_pad_i, fd, atol=1e-6)
    assert np.linalg.norm(site.v_pad_i) == pytest.approx(
        earth.WGS84_OMEGA * np.hypot(*site.r_pad_e[:2]), rel=1e-14)
    np.testing.assert_allclose(site.velocity_wrt_earth(site.r_pad_i, site.v_pad_i), 0.0, atol=1e-12)


def test_ned_frame():
    C = earth.C_ne(0.0, 0.0)               # equator, Greenwich: N = +z_e, E = +y_e, D = -x_e
    np.testing.assert_allclose(C, [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-16)
    C = earth.C_ne(math.pi / 2, 0.7)         # north pole: down is -z_e
    np.testing.assert_allclose(C[2], [0, 0, -1], atol=1e-16)
    lat, lon = np.radians([[10.0, 20.0], [-60.0, 33.0]]).T
    for Cj, la, lo in zip(earth.C_ne(lat, lon), lat, lon, strict=True):
        np.testing.assert_allclose(Cj @ Cj.T, np.eye(3), atol=1e-15)
        assert np.linalg.det(Cj) == pytest.approx(1.0)
        # down is minus the ellipsoid normal: the gradient of x^2/a^2 + y^2/a^2 + z^2/b^2 at h > 0
        r = earth.geodetic_to_ecef(la, lo, 0.0)
        normal = r / np.array([A * A, A * A, B * B])
        np.testing.assert_allclose(Cj[2], -normal / np.linalg.norm(normal), atol=1e-15)


@pytest.mark.parametrize("lat_deg, lon_deg, az_deg", [
    (0.0, 0.0, 90.0), (37.1, -6.7, 250.0), (69.3, 16.0, 0.0), (-45.0, 170.0, 135.0), (90.0, 0.0, 30.0)])
def test_vehicle_on_the_pad_points_up_with_z_b_downrange(lat_deg, lon_deg, az_deg):
    site = LaunchSite(lat_deg, lon_deg, 50.0, az_deg)
    q = site.q_bi0
    assert q[0] >= 0.0 and np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)
    C_ib = _C_ib(q)                    # the core's convention: v_i = R(q_bi) v_b
    lat, lon, az = map(math.radians, (lat_deg, lon_deg, az_deg))
    up = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
    downrange = earth.C_ne(lat, lon).T @ np.array([math.cos(az), math.sin(az), 0.0])
    np.testing.assert_allclose(C_ib @ [1.0, 0.0, 0.0], up, atol=1e-14)
    np.testing.assert_allclose(C_ib @ [0.0, 0.0, 1.0], downrange, atol=1e-14)
    np.testing.assert_allclose(site.C_li(0.0) @ C_ib, np.eye(3), atol=1e-14)   # C_bl = I


def test_equator_east_launch_quaternion_by_hand():
    # up = +x_i, downrange (east) = +y_i, so z_b -> +y_i: a -90 deg turn about x, q = (cos 45, -sin 45, 0, 0)
    q = LaunchSite(0.0, 0.0, 0.0, 90.0).q_bi0
    np.testing.assert_allclose(q, [math.sqrt(0.5), -math.sqrt(0.5), 0.0, 0.0], atol=1e-15)


def test_dcm_to_quat_all_branches_round_trip():
    rng = np.random.default_rng(7)
    for k in range(40):
        v = rng.normal(size=4)
        if k < 4:                              # drive each of Shepperd's four branches
            v = np.eye(4)[k] + 0.1 * v
        q = v / np.linalg.norm(v) * (1 if v[0] >= 0 else -1)
        np.testing.assert_allclose(earth.dcm_to_quat(_C_ib(q)), q, atol=1e-14)


def test_altitude_of_an_inertial_position_at_time_t():
    site = LaunchSite(5.2, -52.8, 10.0, 45.0)
    lat = np.radians([5.2, 40.0, -89.9, 90.0])
    lon = np.radians([-52.8, 100.0, 10.0, 0.0])
    h = np.array([10.0, 15e3, 2.0e5, 7.0e6])
    t = np.array([0.0, 60.0, 600.0, 3600.0])
    r_i = np.einsum("bji,bj->bi", earth.C_ei(t), earth.geodetic_to_ecef(lat, lon, h))   # C_ie r_e
    np.testing.assert_allclose(site.altitude(r_i, t), h, atol=1e-6)
    np.testing.assert_allclose(earth.geodetic_altitude(r_i, t), h, atol=1e-6)
    la, lo, _ = site.geodetic(r_i, t)
    np.testing.assert_allclose(la, lat, atol=1e-12)
    np.testing.assert_allclose(lo[:3], lon[:3], atol=1e-12)
    assert site.altitude(site.r_pad_i) == pytest.approx(10.0, abs=1e-6)
    # NED under a point at time t: the inertial down direction is C_ie(t) times the Earth-fixed one
    C_ni = site.C_ni(r_i, t)
    for j in range(4):
        np.testing.assert_allclose(C_ni[j], earth.C_ne(lat[j], lon[j]) @ earth.C_ei(t[j]), atol=1e-12)


def test_initial_state_of_the_centre_of_gravity():
    site = LaunchSite(69.3, 16.0, 0.0, 350.0)
    r, v, q = site.initial_state(height_m=12.5)
    up = site.C_le[0]
    np.testing.assert_allclose(r, site.r_pad_e + 12.5 * up, atol=1e-8)
    np.testing.assert_allclose(v, np.cross([0, 0, earth.WGS84_OMEGA], r), atol=1e-12)
    assert site.altitude(r) == pytest.approx(12.5, abs=1e-6)
    np.testing.assert_allclose(q, site.q_bi0)


def test_flat_earth_launch_frame_is_inertial():
    site = LaunchSite(37.1, -6.7, 15.0, 90.0, flat_earth=True)
    np.testing.assert_allclose(site.r_pad_i, 0.0)
    np.testing.assert_allclose(site.v_pad_i, 0.0)
    np.testing.assert_allclose(site.q_bi0, [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(site.C_li(123.0), np.eye(3), atol=1e-15)
    r = np.array([[1000.0, 5.0, 300.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(site.altitude(r, 50.0), [1015.0, 15.0])
    np.testing.assert_allclose(site.velocity_wrt_earth(r, [[1.0, 2.0, 3.0]] * 2), [[1.0, 2.0, 3.0]] * 2)
    # NED of the pad for every point: up (x) is -down, east of the azimuth-90 launch is downrange (z)
    C_ni = site.C_ni(r[0], 50.0)
    np.testing.assert_allclose(C_ni @ [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], atol=1e-15)
    np.testing.assert_allclose(C_ni @ [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("kwargs, key", [
    (dict(latitude_deg=91.0, longitude_deg=0.0), "launch_site.latitude_deg"),
    (dict(latitude_deg=float("nan"), longitude_deg=0.0), "launch_site.latitude_deg"),
    (dict(latitude_deg=0.0, longitude_deg=400.0), "launch_site.longitude_deg"),
    (dict(latitude_deg=0.0, longitude_deg=0.0, altitude_m=2e5), "launch_site.altitude_m"),
    (dict(latitude_deg=0.0, longitude_deg=0.0, azimuth_deg=360.0), "launch_site.azimuth_deg"),
    (dict(latitude_deg="north", longitude_deg=0.0), "launch_site.latitude_deg"),
    (dict(latitude_deg=0.0, longitude_deg=0.0, flat_earth="yes"), "launch_site.flat_earth"),
])
def test_launch_site_rejects_bad_values(kwargs, key):
    with pytest.raises(ConfigError) as err:
        LaunchSite(**kwargs)
    assert err.value.key == key
    assert str(err.value).startswith(f"{key} = ")
    assert "a number in" in err.value.allowed or "true or false" in err.value.allowed


def test_launch_site_from_config():
    site = LaunchSite.from_config({"latitude_deg": 69.3, "longitude_deg": 16.0, "azimuth_deg": 0.0})
    assert site == LaunchSite(69.3, 16.0, 0.0, 0.0)
    with pytest.raises(ConfigError, match=r"launch_site\.azimut = 3: unknown key"):
        LaunchSite.from_config({"latitude_deg": 0.0, "longitude_deg": 0.0, "azimut": 3})
    with pytest.raises(ConfigError, match=r"pad\.longitude_deg = <missing>: required"):
        LaunchSite.from_config({"latitude_deg": 0.0}, key="pad")
