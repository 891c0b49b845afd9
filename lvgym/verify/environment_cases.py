"""Environment models against published numbers: the 1976 U.S. Standard Atmosphere's printed table and
Somigliana's normal gravity of WGS84 (the full checks are in tests/test_atmosphere.py, test_gravity.py)."""

from __future__ import annotations

import numpy as np

from lvgym.environment import earth, make

from .report import Check

# U.S. Standard Atmosphere 1976 (NOAA-S/T 76-1562), Part 4, Table I, geometric altitude:
# z [m], T [K], p [Pa], rho [kg/m^3], as printed
_US76 = [(0.0, 288.150, 101325.0, 1.2250), (11000.0, 216.774, 22699.0, 0.36480),
         (20000.0, 216.650, 5529.3, 0.088910), (32000.0, 228.490, 889.06, 0.013555),
         (50000.0, 270.650, 79.779, 1.0269e-3), (85000.0, 188.893, 0.44568, 8.2196e-6)]
# WGS84 normal gravity on the ellipsoid (NIMA TR8350.2, eq. 4-1): equator and pole [m/s^2]
_GAMMA_E, _GAMMA_P = 9.7803253359, 9.8321849378


def _somigliana(lat: float) -> float:
    a, b = earth.WGS84_A, earth.WGS84_B
    k = b * _GAMMA_P / (a * _GAMMA_E) - 1.0
    s2 = np.sin(lat) ** 2
    return _GAMMA_E * (1.0 + k * s2) / np.sqrt(1.0 - earth.WGS84_E2 * s2)


def case_environment() -> list[Check]:
    """US76 rows within 5e-5 relative of the printed five significant figures, normal gravity within
    1e-6 of Somigliana's formula."""
    out = []
    atm = make("atmosphere", "us76")
    for z, T, p, rho in _US76:
        s = atm(z)
        km = f"{z / 1000:g} km"
        out += [Check("US76", f"temperature, {km}", T, float(s.temperature), "K", 5e-5, True),
                Check("US76", f"pressure, {km}", p, float(s.pressure), "Pa", 5e-5, True),
                Check("US76", f"density, {km}", rho, float(s.density), "kg/m3", 5e-5, True)]
    grav = make("gravity", "wgs84_normal")
    for lat_deg in (0.0, 45.0, 90.0):
        lat = np.radians(lat_deg)
        r = earth.geodetic_to_ecef(lat, 0.0, 0.0)
        g = grav.acceleration(r, 0.0) + earth.WGS84_OMEGA**2 * np.array([r[0], r[1], 0.0])
        out.append(Check("gravity", f"WGS84 normal gravity at {lat_deg:g} deg (Somigliana)", _somigliana(lat),
                         float(np.linalg.norm(g)), "m/s2", 1e-6, True))
    return out
