"""The Earth: WGS84 ellipsoid, its rotation, local frames and the launch site (thesis section 3.2).

Frames (docs/conventions.md, ``v_b = C_bi @ v_i``):

- ``e`` Earth-fixed (ECEF): origin at the Earth's centre, ``z_e`` along the rotation axis, ``x_e``
  through latitude 0, longitude 0.
- ``i`` inertial (ECI): coincides with ``e`` at ``t = 0``; ``e`` turns about ``z_i`` at
  ``omega_e``, so ``C_ei(t)`` is a rotation of ``omega_e * t`` about z.
- ``n`` local north-east-down (NED) at a geodetic latitude and longitude.
- ``l`` launch frame, fixed to the Earth at the pad: ``x_l`` up (along the ellipsoid normal),
  ``z_l`` horizontal along the launch azimuth (downrange), ``y_l = z_l x x_l`` to the right of the
  flight direction. A vehicle standing on the pad with its pitch plane along the azimuth has
  ``C_bl = I``: ``+x_b`` up, ``+z_b`` downrange, ``+y_b`` to the right; pitching over towards
  downrange is a negative rotation about ``y_b`` (aircraft Euler angles yaw = azimuth,
  pitch = 90 deg, roll = 0 from NED).

Flat-Earth option (verification cases): the launch frame is the inertial frame, with its origin
at the pad, no rotation and altitude ``h = h_pad + x_i``.

Compiled callers use the ``*_k`` kernels with the parameter array :attr:`LaunchSite.params`
(layout ``SITE_*`` below): ``site_geodetic_k``, ``site_dcm_ni_k``, ``site_velocity_wrt_earth_k``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import cached_property
from dataclasses import dataclass, fields
from typing import Any

import numba as nb
import numpy as np

from lvgym.errors import MISSING, ConfigError

# WGS84 defining constants (NIMA TR8350.2, 3rd ed., 2000, table 3.1)
WGS84_A = 6378137.0                      #: semi-major axis [m]
WGS84_INV_F = 298.257223563              #: inverse flattening [-]
WGS84_GM = 3.986004418e14                #: gravitational parameter incl. atmosphere [m^3/s^2]
WGS84_OMEGA = 7.292115e-5                #: rotation rate of the Earth [rad/s]
WGS84_F = 1.0 / WGS84_INV_F              #: flattening [-]
WGS84_B = WGS84_A * (1.0 - WGS84_F)      #: semi-minor axis [m]
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)     #: first eccentricity squared [-]

# layout of LaunchSite.params
SITE_FLAT, SITE_A, SITE_E2, SITE_OMEGA, SITE_LAT, SITE_LON, SITE_H0 = 0, 1, 2, 3, 4, 5, 6
SITE_R_PAD_E, SITE_C_LE, SITE_SIZE = 7, 10, 19


# ------------------------------------------------------------------------------- kernels
@nb.njit(cache=True)
def geodetic_to_ecef_k(lat, lon, h, a, e2):
    """Earth-fixed position [m] of geodetic latitude, longitude [rad] and height ``h`` [m]
    above the ellipsoid of semi-major axis ``a`` [m] and eccentricity squared ``e2``."""
    s, c = math.sin(lat), math.cos(lat)
    n = a / math.sqrt(1.0 - e2 * s * s)          # prime-vertical radius of curvature
    return (n + h) * c * math.cos(lon), (n + h) * c * math.sin(lon), (n * (1.0 - e2) + h) * s


@nb.njit(cache=True)
def ecef_to_geodetic_k(x, y, z, a, e2):
    """Geodetic latitude, longitude [rad] and height [m] of the Earth-fixed point (x, y, z) [m].

    Closed form of Vermeille (2002, J. Geodesy 76:451-454), exact (no iteration), regular at the
    poles and at any altitude; valid outside the evolute of the ellipsoid (about 43 km around
    the Earth's centre for WGS84).
    """
    e4 = e2 * e2
    w2 = x * x + y * y
    p = w2 / (a * a)
    q = (1.0 - e2) * z * z / (a * a)
    r = (p + q - e4) / 6.0
    s = e4 * p * q / (4.0 * r * r * r)
    t = (1.0 + s + math.sqrt(s * (2.0 + s))) ** (1.0 / 3.0)
    u = r * (1.0 + t + 1.0 / t)
    v = math.sqrt(u * u + e4 * q)
    w = e2 * (u + v - q) / (2.0 * v)
    k = math.sqrt(u + v + w * w) - w
    d = k * math.sqrt(w2) / (k + e2)
    dz = math.sqrt(d * d + z * z)
    lat = 2.0 * math.atan2(z, d + dz)
    return lat, math.atan2(y, x), (k + e2 - 1.0) / k * dz


@nb.njit(cache=True)
def dcm_ei_k(t, omega_e, C):
    """Write ``C_ei(t)`` (inertial -> Earth-fixed), a rotation of ``omega_e * t`` [rad/s * s]
    about z, into the 3x3 array ``C``."""
    c, s = math.cos(omega_e * t), math.sin(omega_e * t)
    C[0, 0], C[0, 1], C[0, 2] = c, s, 0.0
    C[1, 0], C[1, 1], C[1, 2] = -s, c, 0.0
    C[2, 0], C[2, 1], C[2, 2] = 0.0, 0.0, 1.0


@nb.njit(cache=True)
def dcm_ne_k(lat, lon, C):
    """Write ``C_ne`` (Earth-fixed -> local NED at geodetic ``lat``, ``lon`` [rad]) into ``C``."""
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    C[0, 0], C[0, 1], C[0, 2] = -sl * co, -sl * so, cl
    C[1, 0], C[1, 1], C[1, 2] = -so, co, 0.0
    C[2, 0], C[2, 1], C[2, 2] = -cl * co, -cl * so, -sl


@nb.njit(cache=True, inline="always")
def site_geodetic_at(x, y, z, t, p, o):
    """:func:`site_geodetic_k` with the site parameters at ``p[o:]`` (a packed array; no view)."""
    if p[o + SITE_FLAT] != 0.0:
        return p[o + SITE_LAT], p[o + SITE_LON], p[o + SITE_H0] + x
    c, s = math.cos(p[o + SITE_OMEGA] * t), math.sin(p[o + SITE_OMEGA] * t)
    return ecef_to_geodetic_k(c * x + s * y, -s * x + c * y, z, p[o + SITE_A], p[o + SITE_E2])


@nb.njit(cache=True)
def site_geodetic_k(x, y, z, t, p):
    """Geodetic latitude, longitude [rad] and altitude [m] of the inertial point (x, y, z) [m] at
    time ``t`` [s], for the site parameters ``p``. Flat Earth: the pad's latitude and longitude
    and ``h_pad + x``."""
    return site_geodetic_at(x, y, z, t, p, 0)


@nb.njit(cache=True)
def site_dcm_ni_k(x, y, z, t, p, C):
    """Write ``C_ni`` (inertial -> local NED under the inertial point (x, y, z) [m] at ``t`` [s])
    into ``C``. Flat Earth: the pad's NED frame for every point."""
    lat, lon, _ = site_geodetic_k(x, y, z, t, p)
    site_dcm_ni_latlon_k(lat, lon, t, p, C)


@nb.njit(cache=True, inline="always")
def site_dcm_ni_latlon_at(lat, lon, t, p, o, C):
    """:func:`site_dcm_ni_latlon_k` with the site parameters at ``p[o:]`` (a packed array)."""
    dcm_ne_k(lat, lon, C)                            # C = C_ne, then C_ne C_ei row by row
    flat = p[o + SITE_FLAT] != 0.0
    c, s = math.cos(p[o + SITE_OMEGA] * t), math.sin(p[o + SITE_OMEGA] * t)
    le = o + SITE_C_LE
    for j in range(3):
        r0, r1, r2 = C[j, 0], C[j, 1], C[j, 2]
        if flat:                                     # "inertial" is the launch frame: C_ei = C_le^T
            for k in range(3):
                C[j, k] = r0 * p[le + 3 * k] + r1 * p[le + 3 * k + 1] + r2 * p[le + 3 * k + 2]
        else:                                        # C_ei = [[c, s, 0], [-s, c, 0], [0, 0, 1]]
            C[j, 0] = r0 * c - r1 * s
            C[j, 1] = r0 * s + r1 * c
            C[j, 2] = r2


@nb.njit(cache=True)
def site_dcm_ni_latlon_k(lat, lon, t, p, C):
    """:func:`site_dcm_ni_k` from the point's geodetic latitude and longitude [rad] (as
    :func:`site_geodetic_k` returns them), for callers that already have them. No allocation."""
    site_dcm_ni_latlon_at(lat, lon, t, p, 0, C)


@nb.njit(cache=True, inline="always")
def site_velocity_wrt_earth_at(x, y, z, vx, vy, vz, p, o):
    """:func:`site_velocity_wrt_earth_k` with the site parameters at ``p[o:]``."""
    if p[o + SITE_FLAT] != 0.0:
        return vx, vy, vz
    w = p[o + SITE_OMEGA]
    return vx + w * y, vy - w * x, vz


@nb.njit(cache=True)
def site_velocity_wrt_earth_k(x, y, z, vx, vy, vz, p):
    """Velocity relative to the rotating Earth, ``v_i - omega_ie_i x r_i`` [m/s], in inertial
    components, of the inertial position (x, y, z) [m] and velocity (vx, vy, vz) [m/s]."""
    return site_velocity_wrt_earth_at(x, y, z, vx, vy, vz, p, 0)


@nb.njit(cache=True)
def _geodetic_batch(r, t, p, out):
    for j in range(r.shape[0]):
        out[j, 0], out[j, 1], out[j, 2] = site_geodetic_k(r[j, 0], r[j, 1], r[j, 2], t[j], p)


@nb.njit(cache=True)
def _ecef_batch(g, a, e2, out):
    for j in range(g.shape[0]):
        out[j, 0], out[j, 1], out[j, 2] = geodetic_to_ecef_k(g[j, 0], g[j, 1], g[j, 2], a, e2)


@nb.njit(cache=True)
def _dcm_ni_batch(r, t, p, out):
    for j in range(r.shape[0]):
        site_dcm_ni_k(r[j, 0], r[j, 1], r[j, 2], t[j], p, out[j])


@nb.njit(cache=True)
def _vrel_batch(r, v, p, out):
    for j in range(r.shape[0]):
        out[j, 0], out[j, 1], out[j, 2] = site_velocity_wrt_earth_k(
            r[j, 0], r[j, 1], r[j, 2], v[j, 0], v[j, 1], v[j, 2], p)


# ------------------------------------------------------------------------------ batching helpers
def _rows(a: Any, width: int) -> np.ndarray:
    """``a`` as a C-contiguous (B, width) float64 array (a single vector becomes one row)."""
    arr = np.ascontiguousarray(np.asarray(a, dtype=np.float64).reshape(-1, width))
    return arr


def _times(t: Any, n: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=np.float64), (n,)))


def _round_earth_params() -> np.ndarray:
    p = np.zeros(SITE_SIZE)
    p[SITE_A], p[SITE_E2], p[SITE_OMEGA] = WGS84_A, WGS84_E2, WGS84_OMEGA
    return p


# ------------------------------------------------------------------------ public batched functions
def geodetic_to_ecef(lat: Any, lon: Any, h: Any) -> np.ndarray:
    """WGS84 Earth-fixed position [m], shape (..., 3), of geodetic latitude, longitude [rad] and
    height [m] (broadcast together; scalars give a (3,) vector)."""
    lat, lon, h = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (lat, lon, h)))
    g = np.ascontiguousarray(np.stack([lat, lon, h], axis=-1).reshape(-1, 3))
    out = np.empty_like(g)
    _ecef_batch(g, WGS84_A, WGS84_E2, out)
    return out.reshape(lat.shape + (3,))


def ecef_to_geodetic(r_e: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic latitude, longitude [rad] and height [m] above WGS84 of Earth-fixed positions
    ``r_e`` [m], shape (3,) or (B, 3)."""
    return geodetic(r_e, 0.0)


def geodetic(r_i: Any, t: Any = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic latitude, longitude [rad] and height [m] of inertial positions ``r_i`` [m],
    shape (3,) or (B, 3), at times ``t`` [s] (scalar or (B,)), on the rotating WGS84 Earth."""
    return _geodetic_with(_round_earth_params(), r_i, t)


def _geodetic_with(p: np.ndarray, r_i: Any, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Latitude, longitude [rad], height [m] of inertial positions with the site parameters ``p``."""
    rows = _rows(r_i, 3)
    out = np.empty_like(rows)
    _geodetic_batch(rows, _times(t, rows.shape[0]), p, out)
    if np.ndim(r_i) == 1:
        return out[0, 0], out[0, 1], out[0, 2]
    return out[:, 0], out[:, 1], out[:, 2]


def geodetic_altitude(r_i: Any, t: Any = 0.0) -> np.ndarray:
    """Height [m] above the WGS84 ellipsoid of inertial positions ``r_i`` [m] at times ``t`` [s]."""
    return geodetic(r_i, t)[2]


def C_ei(t: Any) -> np.ndarray:
    """Inertial -> Earth-fixed DCM at time(s) ``t`` [s]: (3, 3) for a scalar, (B, 3, 3) for (B,)."""
    ts = np.atleast_1d(np.asarray(t, dtype=np.float64))
    out = np.empty((ts.size, 3, 3))
    for j, tj in enumerate(ts.ravel()):
        dcm_ei_k(tj, WGS84_OMEGA, out[j])
    return out[0] if np.ndim(t) == 0 else out


def C_ne(lat: Any, lon: Any) -> np.ndarray:
    """Earth-fixed -> NED DCM at geodetic latitude and longitude [rad]: (3, 3) or (B, 3, 3)."""
    la, lo = np.broadcast_arrays(np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64))
    out = np.empty((la.size, 3, 3))
    for j, (a, b) in enumerate(zip(la.ravel(), lo.ravel(), strict=True)):
        dcm_ne_k(a, b, out[j])
    return out[0] if la.ndim == 0 else out.reshape(la.shape + (3, 3))


def dcm_to_quat(C: Any) -> np.ndarray:
    """Scalar-first unit quaternion ``q_bi`` (q0 >= 0) whose rotation matrix (as built by
    ``lvgym.rotations.quat_to_dcm``) is ``C = C_ib`` (body -> inertial). Shepperd's method."""
    C = np.asarray(C, dtype=np.float64)
    tr = np.trace(C)
    d = np.diag(C)
    if tr >= d.max():
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [0.25 * s, (C[2, 1] - C[1, 2]) / s, (C[0, 2] - C[2, 0]) / s, (C[1, 0] - C[0, 1]) / s]
    elif d[0] >= d[1] and d[0] >= d[2]:
        s = 2.0 * math.sqrt(1.0 + C[0, 0] - C[1, 1] - C[2, 2])
        q = [(C[2, 1] - C[1, 2]) / s, 0.25 * s, (C[0, 1] + C[1, 0]) / s, (C[0, 2] + C[2, 0]) / s]
    elif d[1] >= d[2]:
        s = 2.0 * math.sqrt(1.0 + C[1, 1] - C[0, 0] - C[2, 2])
        q = [(C[0, 2] - C[2, 0]) / s, (C[0, 1] + C[1, 0]) / s, 0.25 * s, (C[1, 2] + C[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + C[2, 2] - C[0, 0] - C[1, 1])
        q = [(C[1, 0] - C[0, 1]) / s, (C[0, 2] + C[2, 0]) / s, (C[1, 2] + C[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


# ------------------------------------------------------------------------------------ launch site
def _check(key: str, value: Any, lo: float, hi: float, unit: str, hi_open: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and lo <= value and (value < hi if hi_open else value <= hi)
    if not ok:
        close = ")" if hi_open else "]"
        raise ConfigError(f"launch_site.{key}", value, f"a number in [{lo}, {hi}{close} {unit}")
    return float(value)


@dataclass(frozen=True)
class LaunchSite:
    """A launch pad on the WGS84 Earth and the launch direction.

    Parameters
    ----------
    latitude_deg, longitude_deg:
        Geodetic latitude in [-90, 90] deg and longitude in [-180, 360] deg of the pad.
    altitude_m:
        Pad height above the ellipsoid [m], in [-1000, 100000].
    azimuth_deg:
        Launch azimuth [deg], clockwise from north, in [0, 360).
    flat_earth:
        Treat the launch frame as inertial (no curvature, no rotation): for verification cases.

    Compiled callers use :attr:`params` with ``site_geodetic_k``, ``site_dcm_ni_k`` and
    ``site_velocity_wrt_earth_k``.
    """

    latitude_deg: float
    longitude_deg: float
    altitude_m: float = 0.0
    azimuth_deg: float = 90.0
    flat_earth: bool = False

    def __post_init__(self) -> None:
        _check("latitude_deg", self.latitude_deg, -90.0, 90.0, "deg")
        _check("longitude_deg", self.longitude_deg, -180.0, 360.0, "deg")
        _check("altitude_m", self.altitude_m, -1000.0, 100000.0, "m")
        _check("azimuth_deg", self.azimuth_deg, 0.0, 360.0, "deg", hi_open=True)
        if not isinstance(self.flat_earth, bool):
            raise ConfigError("launch_site.flat_earth", self.flat_earth, "true or false")

    @classmethod
    def from_config(cls, spec: Mapping[str, Any], key: str = "launch_site") -> LaunchSite:
        """Build from a mapping of the field names; unknown or missing keys raise ConfigError."""
        names = [f.name for f in fields(cls)]
        for k in spec:
            if k not in names:
                raise ConfigError(f"{key}.{k}", spec[k], f"unknown key; allowed: {names}")
        for k in ("latitude_deg", "longitude_deg"):
            if k not in spec:
                raise ConfigError(f"{key}.{k}", MISSING, "required, in degrees")
        return cls(**spec)

    # ---------------------------------------------------------------- fixed quantities of the pad
    @property
    def latitude(self) -> float:
        """Geodetic latitude of the pad [rad]."""
        return math.radians(self.latitude_deg)

    @property
    def longitude(self) -> float:
        """Longitude of the pad [rad]."""
        return math.radians(self.longitude_deg)

    @property
    def azimuth(self) -> float:
        """Launch azimuth [rad], clockwise from north."""
        return math.radians(self.azimuth_deg)

    @cached_property
    def _pad(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``r_pad_e``, ``C_ne`` and ``C_le`` computed once per site (read-only; the properties copy)."""
        r = geodetic_to_ecef(self.latitude, self.longitude, float(self.altitude_m))
        n = C_ne(self.latitude, self.longitude)
        up = -n[2]
        downrange = math.cos(self.azimuth) * n[0] + math.sin(self.azimuth) * n[1]
        le = np.array([up, np.cross(downrange, up), downrange])
        for a in (r, n, le):
            a.flags.writeable = False
        return r, n, le

    @property
    def r_pad_e(self) -> np.ndarray:
        """Pad position in the Earth-fixed frame [m]."""
        return self._pad[0].copy()

    @property
    def C_ne(self) -> np.ndarray:
        """Earth-fixed -> NED DCM at the pad."""
        return self._pad[1].copy()

    @property
    def C_le(self) -> np.ndarray:
        """Earth-fixed -> launch frame DCM (rows: up, right of the azimuth, downrange)."""
        return self._pad[2].copy()

    @cached_property
    def params(self) -> np.ndarray:
        """Parameter array of the compiled kernels (layout ``SITE_*``), built once per site."""
        p = _round_earth_params()
        p[SITE_FLAT] = 1.0 if self.flat_earth else 0.0
        p[SITE_LAT], p[SITE_LON], p[SITE_H0] = self.latitude, self.longitude, self.altitude_m
        p[SITE_R_PAD_E:SITE_R_PAD_E + 3] = self.r_pad_e
        p[SITE_C_LE:SITE_C_LE + 9] = self.C_le.ravel()
        return p

    # ------------------------------------------------------------ inertial quantities at lift-off
    @property
    def r_pad_i(self) -> np.ndarray:
        """Pad position in the inertial frame at t = 0 [m] (zero on a flat Earth)."""
        return np.zeros(3) if self.flat_earth else self.r_pad_e

    @property
    def v_pad_i(self) -> np.ndarray:
        """Inertial velocity of the pad at t = 0 [m/s], ``omega_ie x r`` (zero on a flat Earth)."""
        return np.zeros(3) if self.flat_earth else np.cross([0.0, 0.0, WGS84_OMEGA], self.r_pad_e)

    @property
    def C_ib0(self) -> np.ndarray:
        """Body -> inertial DCM of the vehicle standing on the pad at t = 0: ``+x_b`` up,
        ``+z_b`` downrange, ``+y_b`` to the right (``C_bl = I``)."""
        return np.eye(3) if self.flat_earth else self.C_le.T

    @property
    def q_bi0(self) -> np.ndarray:
        """Scalar-first attitude quaternion ``q_bi`` of the vehicle on the pad at t = 0 (the
        convention of ``lvgym.dynamics``: its rotation matrix is ``C_ib``)."""
        return dcm_to_quat(self.C_ib0)

    def initial_state(self, height_m: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inertial position [m], velocity [m/s] and ``q_bi`` at t = 0 of a point ``height_m`` [m]
        above the pad on the vehicle axis (e.g. the centre of gravity)."""
        r = self.r_pad_i + height_m * self.C_ib0[:, 0]
        v = np.zeros(3) if self.flat_earth else np.cross([0.0, 0.0, WGS84_OMEGA], r)
        return r, v, self.q_bi0

    # --------------------------------------------------------------------------- along the flight
    def C_ei(self, t: Any = 0.0) -> np.ndarray:
        """Inertial -> Earth-fixed DCM at ``t`` [s] (constant ``C_el`` on a flat Earth)."""
        if self.flat_earth:
            C = self.C_le.T
            return C if np.ndim(t) == 0 else np.broadcast_to(C, (np.size(t), 3, 3)).copy()
        return C_ei(t)

    def C_li(self, t: Any = 0.0) -> np.ndarray:
        """Inertial -> launch frame DCM at ``t`` [s] (identity on a flat Earth)."""
        return self.C_le @ self.C_ei(t)

    def geodetic(self, r_zw_i: Any, t: Any = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Latitude, longitude [rad] and geodetic altitude [m] of inertial positions [m] at ``t``."""
        return _geodetic_with(self.params, r_zw_i, t)

    def altitude(self, r_zw_i: Any, t: Any = 0.0) -> np.ndarray:
        """Geodetic altitude [m] of inertial positions (3,) or (B, 3) [m] at ``t`` [s]."""
        return self.geodetic(r_zw_i, t)[2]

    def C_ni(self, r_zw_i: Any, t: Any = 0.0) -> np.ndarray:
        """Inertial -> local NED DCM under inertial positions [m] at ``t`` [s]: (3, 3) or (B, 3, 3)."""
        rows = _rows(r_zw_i, 3)
        out = np.empty((rows.shape[0], 3, 3))
        _dcm_ni_batch(rows, _times(t, rows.shape[0]), self.params, out)
        return out[0] if np.ndim(r_zw_i) == 1 else out

    def velocity_wrt_earth(self, r_zw_i: Any, v_zw_i: Any) -> np.ndarray:
        """Velocity relative to the rotating Earth [m/s], inertial components, shape of ``v_zw_i``."""
        r, v = _rows(r_zw_i, 3), _rows(v_zw_i, 3)
        r, v = np.broadcast_arrays(r, v)
        out = np.empty(r.shape)
        _vrel_batch(np.ascontiguousarray(r), np.ascontiguousarray(v), self.params, out)
        return out[0] if np.ndim(v_zw_i) == 1 and np.ndim(r_zw_i) == 1 else out
