"""Flight conditions: every environment model evaluated once for a vehicle state (issue 4)."""

import numpy as np
import pytest

from lvgym.environment import LaunchSite, make
from lvgym.environment.conditions import Environment
from lvgym.vehicle import load_vehicle

SITE = LaunchSite(latitude_deg=69.3, longitude_deg=16.0, altitude_m=20.0, azimuth_deg=90.0)  # Andoya


def test_pad_at_rest_in_calm_air():
    env = Environment(SITE)
    r, v, q = SITE.initial_state()
    c = env.conditions(0.0, r, v, q, np.zeros(3), -7.0)
    assert c.altitude[0] == pytest.approx(20.0, abs=1e-6)
    assert np.linalg.norm(c.v_air_b[0]) < 1e-9 and c.qbar[0] < 1e-12
    # EGM2008 at the pad: about 9.83 m/s2 toward the Earth at 69 deg N
    assert np.linalg.norm(c.g_i[0]) == pytest.approx(9.826, abs=5e-3)
    us76 = make("atmosphere", "us76")(20.0)
    assert c.density[0] == pytest.approx(us76.density) and c.speed_of_sound[0] == pytest.approx(us76.speed_of_sound)


def test_wind_from_the_north_on_a_vehicle_standing_on_the_pad():
    # 10 m/s blowing FROM the north: the air moves south, so relative to the air the vehicle moves north.
    # On the pad +x_b is up and +z_b east (downrange), so +y_b = z_b x x_b points south.
    wind = {"model": "profile", "altitude_m": [0.0, 1e5], "speed": [10.0, 10.0], "direction_deg": [0.0, 0.0]}
    env = Environment(SITE, wind=wind)
    r, v, q = SITE.initial_state()
    c = env.conditions(0.0, r, v, q, np.zeros(3), -7.0)
    assert np.allclose(c.wind_n[0], [-10.0, 0.0, 0.0])
    assert np.allclose(c.v_air_b[0], [0.0, -10.0, 0.0], atol=1e-9)
    assert c.beta[0] == pytest.approx(-np.pi / 2)
    assert c.mach[0] == pytest.approx(10.0 / c.speed_of_sound[0])
    assert c.qbar[0] == pytest.approx(0.5 * c.density[0] * 100.0)


def test_loads_are_the_aerodynamic_model_at_the_same_conditions_and_batch_equals_single():
    vehicle = load_vehicle("stratos3")
    env = Environment(SITE, wind={"model": "gust", "amplitude": 15.0, "length": 200.0}, aerodynamics=vehicle.aerodynamics)
    r0, v0, q0 = SITE.initial_state()
    rng = np.random.default_rng(3)
    n = 5
    up = r0 / np.linalg.norm(r0)
    r = r0 + np.outer(np.linspace(100.0, 5000.0, n), up)
    v = v0 + np.outer(np.linspace(50.0, 600.0, n), up) + rng.normal(0.0, 20.0, (n, 3))
    q = np.tile(q0, (n, 1))
    w = rng.normal(0.0, 0.1, (n, 3))
    x_cg = np.linspace(-5.2, -4.8, n)
    t = np.linspace(1.0, 20.0, n)
    c = env.conditions(t, r, v, q, w, x_cg)
    f_b, m_b, st = env.aerodynamics.loads(c.v_air_b, w, c.density, c.speed_of_sound, x_cg, c.altitude)
    assert np.allclose(c.f_aero_b, f_b) and np.allclose(c.m_aero_b, m_b) and np.allclose(c.mach, st.mach)
    assert np.allclose(c.altitude, SITE.altitude(r, t))
    assert np.all(c.qbar > 0) and np.all(np.isfinite(c.alpha))
    for k in range(n):
        one = env.conditions(t[k], r[k], v[k], q[k], w[k], x_cg[k])
        assert np.allclose(one.f_aero_b[0], c.f_aero_b[k]) and np.allclose(one.wind_i[0], c.wind_i[k])


def test_flat_earth_for_verification_cases():
    """Flat, non-rotating Earth: the launch frame (x up) is inertial, altitude = pad altitude + x_i."""
    site = LaunchSite(latitude_deg=37.1, longitude_deg=-6.7, altitude_m=10.0, azimuth_deg=0.0, flat_earth=True)
    env = Environment(site, gravity={"model": "constant", "g_i": [-9.80665, 0.0, 0.0]})
    r, v, q = site.initial_state()
    assert np.allclose(q, [1.0, 0.0, 0.0, 0.0])
    c = env.conditions(0.0, r + [1000.0, 0.0, 0.0], v + [100.0, 0.0, 0.0], q, np.zeros(3), -4.0)
    assert c.altitude[0] == pytest.approx(1010.0)
    assert np.allclose(c.v_air_b[0], [100.0, 0.0, 0.0]) and c.alpha_total[0] == pytest.approx(0.0)
    assert np.allclose(c.g_i[0], [-9.80665, 0.0, 0.0])


@pytest.mark.parametrize("axis", [1, 2])
def test_attitude_sets_the_flow_angles_and_a_stable_vehicle_turns_back(axis):
    """Flat Earth, climbing at 100 m/s along x_i. Turning the body +2 deg about y_b gives alpha = +2 deg;
    about z_b it gives beta = -2 deg. Stratos III (CG ahead of CP) gets a moment turning it back."""
    site = LaunchSite(latitude_deg=37.1, longitude_deg=-6.7, altitude_m=0.0, azimuth_deg=0.0, flat_earth=True)
    env = Environment(site, gravity={"model": "constant"}, aerodynamics=load_vehicle("stratos3").aerodynamics)
    half = np.radians(2.0) / 2.0
    q = np.array([np.cos(half), 0.0, 0.0, 0.0])
    q[1 + axis] = np.sin(half)                       # rotation of +2 deg about y_b or z_b
    c = env.conditions(0.0, [500.0, 0.0, 0.0], [100.0, 0.0, 0.0], q, np.zeros(3), -5.1)
    if axis == 1:
        assert c.alpha[0] == pytest.approx(np.radians(2.0)) and abs(c.beta[0]) < 1e-12
    else:
        assert c.beta[0] == pytest.approx(np.radians(-2.0)) and abs(c.alpha[0]) < 1e-12
    assert c.alpha_total[0] == pytest.approx(np.radians(2.0))
    assert c.m_aero_b[0, axis] < 0.0
