"""Gravity models (thesis section 3.2): constant, central, J2, WGS84 normal field, EGM2008.

Every model has one call, ``model.acceleration(r_zw_i, t) -> g_i``: the gravitational acceleration
[m/s^2] in the inertial frame at inertial positions ``r_zw_i`` [m] (shape (3,) or (B, 3)) and times
``t`` [s] (scalar or (B,)). ``model.potential(r_zw_i, t)`` is the potential energy per unit mass
``U`` [J/kg] with ``g = -grad U`` (``U = -GM/r`` for a point mass). Neither contains the centrifugal
term: the inertial frame does not rotate (``earth.py``: ECI = ECEF at t = 0).

Compiled callers use one kernel for all models, ``gravity_k(x, y, z, t, p) -> (gx, gy, gz)``
(and ``gravity_potential_k(x, y, z, t, p) -> U``) with the model's parameter array ``model.params``:
``p[0]`` is the model kind (``KIND_*``), the rest its parameters (layout ``P_*``).

Spherical harmonics (``egm2008``, ``wgs84_normal``) use Cunningham's recursion of the solid
harmonics ``V_nm + i W_nm = (R/r)^(n+1) P_nm(sin phi) exp(i m lambda)`` in Cartesian coordinates
(Montenbruck & Gill, Satellite Orbits, 2000, sec. 3.2.4-3.2.5), written here for fully normalised
functions with the normalised Legendre recursion coefficients: no division by cos(latitude), so the
poles are regular, and no factorials, so it stays stable to high degree.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np

from lvgym.errors import ConfigError

from .earth import WGS84_A, WGS84_E2, WGS84_F, WGS84_GM, WGS84_OMEGA
from .registry import register

KIND_CONSTANT, KIND_POINT_MASS, KIND_J2, KIND_HARMONICS = 0.0, 1.0, 2.0, 3.0
P_KIND, P_OMEGA = 0, 1          # all models: kind, Earth rotation rate [rad/s]
P_G = 2                         # constant: g_i[3] [m/s^2]
P_GM, P_RADIUS = 2, 3           # point mass (GM only), J2 and harmonics [m^3/s^2], [m]
P_J2 = 4                        # J2: J2 [-]
P_DEGREE, P_ORDER, P_COEF = 4, 5, 6   # harmonics: N, M, then C[K], S[K], K = (N+1)(N+2)/2, at n(n+1)/2+m,
F_A, F_B, F_FZ, F_F0, F_FA, F_FB = range(6)   # then harmonic_factors(N): six (N+2, N+2) blocks

DATA_FILE = Path(__file__).with_name("data") / "egm2008_n4.csv"


_u = nb.uint64                  # an unsigned array index: no negative-index wraparound


# ------------------------------------------------------------------------------- kernels
def harmonic_factors(N: int) -> np.ndarray:
    """Recursion and gradient factors of the fully normalised harmonics up to degree N, as six
    (N+2, N+2) blocks end to end (``F_*`` order): the column recursion ``a``, ``b`` and the gradient
    factors ``fz``, ``f0`` (m = 0), ``fa``, ``fb``, so the kernel takes no square root. Computed once per
    process and degree (each call gets its own array)."""
    return _harmonic_factors(int(N)).copy()


@functools.lru_cache(maxsize=8)
def _harmonic_factors(N: int) -> np.ndarray:
    """:func:`harmonic_factors` (read-only)."""
    n2 = N + 2
    F = np.zeros((6, n2, n2))
    for m in range(n2):
        for n in range(m + 1, n2):
            F[F_A, n, m] = math.sqrt((2.0 * n + 1.0) * (2.0 * n - 1.0) / ((n - m) * (n + m)))
            if n > m + 1:
                F[F_B, n, m] = math.sqrt((2.0 * n + 1.0) * (n + m - 1.0) * (n - m - 1.0)
                                         / ((n - m) * (n + m) * (2.0 * n - 3.0)))
    for n in range(N + 1):
        for m in range(n + 1):
            F[F_FZ, n, m] = math.sqrt((2.0 * n + 1.0) * (n + m + 1.0) * (n - m + 1.0) / (2.0 * n + 3.0))
            F[F_F0, n, m] = math.sqrt((2.0 * n + 1.0) * (n + 1.0) * (n + 2.0) / (2.0 * (2.0 * n + 3.0)))
            F[F_FA, n, m] = math.sqrt((2.0 * n + 1.0) * (n + m + 1.0) * (n + m + 2.0) / (2.0 * n + 3.0))
            F[F_FB, n, m] = math.sqrt((2.0 if m == 1 else 1.0) * (2.0 * n + 1.0) * (n - m + 1.0)
                                      * (n - m + 2.0) / (2.0 * n + 3.0))
    F = F.ravel()
    F.flags.writeable = False
    return F


def harmonics_work(p: np.ndarray) -> int:
    """Scratch entries :func:`harmonics_at` needs for the harmonics parameters ``p`` (0 otherwise)."""
    return 2 * (int(p[P_DEGREE]) + 2) ** 2 if p[P_KIND] == KIND_HARMONICS else 0


@nb.njit(cache=True, inline="always")
def harmonics_at(x, y, z, p, o, w, ow):
    """:func:`harmonics_k` with the parameters at ``p[o:]`` and the solid harmonics ``V``, ``W``
    ((N+2, N+2) each, row major) in the scratch ``w[ow:ow + harmonics_work]`` (any contents).
    Indices are cast to unsigned (``_u``): numba then skips its negative-index wraparound, which
    took 40 % of the kernel's time."""
    gm, R = p[_u(o + P_GM)], p[_u(o + P_RADIUS)]
    N, M = int(p[_u(o + P_DEGREE)]), int(p[_u(o + P_ORDER)])
    K = (N + 1) * (N + 2) // 2
    n2 = N + 2
    oc = o + P_COEF                                    # C at oc, S at oc + K, F at oc + 2K
    of = oc + 2 * K
    ov, ow_ = ow, ow + n2 * n2                         # V[n, m] = w[ov + n n2 + m], W likewise
    r2 = x * x + y * y + z * z
    rho = R / r2
    x0, y0, z0, rr = x * rho, y * rho, z * rho, R * rho
    w[_u(ov)] = R / math.sqrt(r2)
    w[_u(ow_)] = 0.0
    for m in range(min(M + 1, N + 1) + 1):
        if m > 0:                                      # sectoral: V_mm from V_m-1,m-1
            f = math.sqrt(3.0) if m == 1 else math.sqrt((2.0 * m + 1.0) / (2.0 * m))
            d, e = (m - 1) * n2 + m - 1, m * n2 + m
            w[_u(ov + e)] = f * (x0 * w[_u(ov + d)] - y0 * w[_u(ow_ + d)])
            w[_u(ow_ + e)] = f * (x0 * w[_u(ow_ + d)] + y0 * w[_u(ov + d)])
        for n in range(m + 1, n2):                     # along the column m
            a = p[_u(of + (F_A * n2 + n) * n2 + m)]
            e = n * n2 + m
            w[_u(ov + e)] = a * z0 * w[_u(ov + e - n2)]
            w[_u(ow_ + e)] = a * z0 * w[_u(ow_ + e - n2)]
            if n > m + 1:
                b = p[_u(of + (F_B * n2 + n) * n2 + m)]
                w[_u(ov + e)] -= b * rr * w[_u(ov + e - 2 * n2)]
                w[_u(ow_ + e)] -= b * rr * w[_u(ow_ + e - 2 * n2)]
    ax = ay = az = u = 0.0
    for n in range(N + 1):
        for m in range(min(n, M) + 1):
            C, S = p[_u(oc + n * (n + 1) // 2 + m)], p[_u(oc + K + n * (n + 1) // 2 + m)]
            if C == 0.0 and S == 0.0:
                continue
            e = n * n2 + m                             # (n, m); (n + 1, m) is e + n2
            u += C * w[_u(ov + e)] + S * w[_u(ow_ + e)]
            az -= p[_u(of + F_FZ * n2 * n2 + e)] * (C * w[_u(ov + e + n2)] + S * w[_u(ow_ + e + n2)])
            if m == 0:
                f0 = p[_u(of + F_F0 * n2 * n2 + e)]
                ax -= f0 * C * w[_u(ov + (n + 1) * n2 + 1)]
                ay -= f0 * C * w[_u(ow_ + (n + 1) * n2 + 1)]
            else:
                fa, fb = p[_u(of + F_FA * n2 * n2 + e)], p[_u(of + F_FB * n2 * n2 + e)]
                up, dn = e + n2 + 1, e + n2 - 1
                ax += 0.5 * (fa * (-C * w[_u(ov + up)] - S * w[_u(ow_ + up)])
                             + fb * (C * w[_u(ov + dn)] + S * w[_u(ow_ + dn)]))
                ay += 0.5 * (fa * (-C * w[_u(ow_ + up)] + S * w[_u(ov + up)])
                             + fb * (-C * w[_u(ow_ + dn)] + S * w[_u(ov + dn)]))
    s = gm / (R * R)
    return s * ax, s * ay, s * az, -gm / R * u


@nb.njit(cache=True)
def harmonics_k(x, y, z, p):
    """Acceleration (3) [m/s^2] and potential energy [J/kg] of the spherical-harmonic field with
    parameters ``p`` (layout ``P_*``) at the body-fixed point (x, y, z) [m], as a 4-tuple."""
    n2 = int(p[P_DEGREE]) + 2
    return harmonics_at(x, y, z, p, 0, np.empty(2 * n2 * n2), 0)


@nb.njit(cache=True)
def j2_k(x, y, z, gm, a, j2):
    """Acceleration (3) [m/s^2] and potential energy [J/kg] of the J2 field
    ``U = -GM/r (1 - J2 (a/r)^2 P2(z/r))`` at the body-fixed point (x, y, z) [m]."""
    r2 = x * x + y * y + z * z
    r = math.sqrt(r2)
    k = 1.5 * j2 * a * a / r2
    zz = 5.0 * z * z / r2
    c = -gm / (r2 * r)
    u = -gm / r * (1.0 - j2 * a * a / r2 * (1.5 * z * z / r2 - 0.5))
    h = c * (1.0 - k * (zz - 1.0))
    return h * x, h * y, c * z * (1.0 - k * (zz - 3.0)), u


@nb.njit(cache=True, inline="always")
def gravity_field_at(x, y, z, t, p, o, w, ow):
    """:func:`gravity_field_k` with the model's parameters at ``p[o:]`` and, for harmonics, the
    scratch ``w[ow:]`` of :func:`harmonics_work` entries (``ow < 0``: allocated here)."""
    kind = p[o + P_KIND]
    if kind == KIND_CONSTANT:
        g = o + P_G
        return p[g], p[g + 1], p[g + 2], -(p[g] * x + p[g + 1] * y + p[g + 2] * z)
    if kind == KIND_POINT_MASS:
        r2 = x * x + y * y + z * z
        r = math.sqrt(r2)
        c = -p[o + P_GM] / (r2 * r)
        return c * x, c * y, c * z, -p[o + P_GM] / r
    if kind == KIND_J2:                                # zonal: no rotation to the Earth frame needed
        return j2_k(x, y, z, p[o + P_GM], p[o + P_RADIUS], p[o + P_J2])
    c, s = math.cos(p[o + P_OMEGA] * t), math.sin(p[o + P_OMEGA] * t)
    if ow < 0:
        n2 = int(p[o + P_DEGREE]) + 2
        w, ow = np.empty(2 * n2 * n2), 0
    ge0, ge1, gz, u = harmonics_at(c * x + s * y, -s * x + c * y, z, p, o, w, ow)   # r_e = C_ei(t) r_i
    return c * ge0 - s * ge1, s * ge0 + c * ge1, gz, u                            # g_i = C_ei^T g_e


@nb.njit(cache=True)
def gravity_field_k(x, y, z, t, p):
    """``(gx, gy, gz, U)``: inertial acceleration [m/s^2] and potential energy [J/kg] at the
    inertial point (x, y, z) [m] and time ``t`` [s] for any model's parameter array ``p``."""
    return gravity_field_at(x, y, z, t, p, 0, p, -1)


@nb.njit(cache=True, inline="always")
def gravity_at(x, y, z, t, p, o, w, ow):
    """:func:`gravity_k` with the parameters at ``p[o:]`` and scratch ``w[ow:]`` (see
    :func:`gravity_field_at`): what the simulator's loads call, allocating nothing."""
    gx, gy, gz, _ = gravity_field_at(x, y, z, t, p, o, w, ow)
    return gx, gy, gz


@nb.njit(cache=True)
def gravity_k(x, y, z, t, p):
    """Inertial gravitational acceleration ``(gx, gy, gz)`` [m/s^2] at the inertial point
    (x, y, z) [m] and time ``t`` [s]: the one kernel a compiled caller needs, for every model."""
    gx, gy, gz, _ = gravity_field_k(x, y, z, t, p)
    return gx, gy, gz


@nb.njit(cache=True)
def gravity_potential_k(x, y, z, t, p):
    """Potential energy per unit mass [J/kg] at the inertial point (x, y, z) [m] at ``t`` [s]."""
    return gravity_field_k(x, y, z, t, p)[3]


@nb.njit(cache=True)
def _field_batch(r, t, p, out):
    for j in range(r.shape[0]):
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = gravity_field_k(r[j, 0], r[j, 1], r[j, 2], t[j], p)


# ------------------------------------------------------------------------------- WGS84 normal field
def normal_gravity_zonals(a: float = WGS84_A, f: float = WGS84_F, gm: float = WGS84_GM,
                          omega: float = WGS84_OMEGA, n_max: int = 4) -> np.ndarray:
    """Zonal harmonics ``J2, J4, ..., J_2n_max`` [-] of the normal gravitational field of the level
    ellipsoid (a [m], f [-], GM [m^3/s^2], omega [rad/s]).

    NIMA TR8350.2 (3rd ed., 2000), eq. 3-34 to 3-39 (Heiskanen & Moritz 1967, eq. 2-92):
    ``J2 = e^2/3 (1 - 2/15 m e'/q0)``, ``q0 = ((1 + 3/e'^2) atan e' - 3/e') / 2``,
    ``m = omega^2 a^2 b / GM`` and ``J2n = (-1)^(n+1) 3 e^2n / ((2n+1)(2n+3)) (1 - n + 5 n J2/e^2)``.
    """
    e2 = f * (2.0 - f)
    b = a * (1.0 - f)
    ep = math.sqrt(e2 / (1.0 - e2))
    q0 = 0.5 * ((1.0 + 3.0 / ep ** 2) * math.atan(ep) - 3.0 / ep)
    m = omega ** 2 * a ** 2 * b / gm
    j2 = e2 / 3.0 * (1.0 - 2.0 / 15.0 * m * ep / q0)
    return np.array([(-1.0) ** (n + 1) * 3.0 * e2 ** n / ((2 * n + 1) * (2 * n + 3))
                     * (1.0 - n + 5.0 * n * j2 / e2) for n in range(1, n_max + 1)])


# ------------------------------------------------------------------------------------- models
class GravityModel:
    """Base of the gravity models: holds ``params`` (float64 array for ``gravity_k``) and batches.

    ``acceleration(r_zw_i, t)`` and ``potential(r_zw_i, t)`` loop the compiled ``gravity_field_k``
    over the leading axis: a single vector gives a single result.
    """

    params: np.ndarray

    def field(self, r_zw_i: Any, t: Any = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Acceleration [m/s^2] (shape of ``r_zw_i``) and potential energy [J/kg] ((), or (B,))."""
        r = np.ascontiguousarray(np.asarray(r_zw_i, dtype=np.float64).reshape(-1, 3))
        ts = np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=np.float64), (r.shape[0],)))
        out = np.empty((r.shape[0], 4))
        _field_batch(r, ts, self.params, out)
        if np.ndim(r_zw_i) == 1:
            return out[0, :3], out[0, 3]
        return out[:, :3], out[:, 3]

    def acceleration(self, r_zw_i: Any, t: Any = 0.0) -> np.ndarray:
        """Gravitational acceleration ``g_i`` [m/s^2] at inertial positions [m] at times [s]."""
        return self.field(r_zw_i, t)[0]

    def potential(self, r_zw_i: Any, t: Any = 0.0) -> np.ndarray:
        """Potential energy per unit mass ``U`` [J/kg], ``g = -grad U``."""
        return self.field(r_zw_i, t)[1]

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params[:6].tolist()}...)"


def _positive(key: str, value: Any) -> float:
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not number or not 0.0 < value < math.inf:
        raise ConfigError(key, value, "a positive finite number")
    return float(value)


@register("gravity", "constant")
class ConstantGravity(GravityModel):
    """A fixed inertial vector ``g_i`` [m/s^2] (default 9.80665 along ``-x``, the launch frame's
    up axis on a flat Earth); ``U = -g . r``."""

    def __init__(self, g_i: Any = (-9.80665, 0.0, 0.0)) -> None:
        g = np.asarray(g_i, dtype=np.float64)
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ConfigError("gravity.g_i", g_i, "three finite numbers [m/s^2]")
        self.g_i = g
        self.params = np.array([KIND_CONSTANT, 0.0, *g])


@register("gravity", "point_mass")
class PointMassGravity(GravityModel):
    """Central field ``g = -GM r / |r|^3`` (thesis: "central gravity"); ``gm`` [m^3/s^2]."""

    def __init__(self, gm: float = WGS84_GM) -> None:
        self.gm = _positive("gravity.gm", gm)
        self.params = np.array([KIND_POINT_MASS, 0.0, self.gm])


@register("gravity", "j2")
class J2Gravity(GravityModel):
    """Central field plus the J2 oblateness term (closed form); ``gm`` [m^3/s^2], ``radius`` [m],
    ``j2`` [-] (default WGS84: ``J2 = 1.08263e-3`` from :func:`normal_gravity_zonals`)."""

    def __init__(self, gm: float = WGS84_GM, radius: float = WGS84_A, j2: float | None = None) -> None:
        self.gm = _positive("gravity.gm", gm)
        self.radius = _positive("gravity.radius", radius)
        self.j2 = float(normal_gravity_zonals(n_max=1)[0]) if j2 is None else float(j2)
        if not math.isfinite(self.j2) or abs(self.j2) > 0.1:
            raise ConfigError("gravity.j2", j2, "a finite number with |J2| <= 0.1")
        self.params = np.array([KIND_J2, WGS84_OMEGA, self.gm, self.radius, self.j2])


class HarmonicGravity(GravityModel):
    """Spherical-harmonic field from fully normalised coefficients ``C[n, m]``, ``S[n, m]`` (square
    arrays of degree N), ``gm`` [m^3/s^2], reference ``radius`` [m], Earth rotation ``omega``
    [rad/s]; ``order`` M <= N limits the orders used. Evaluated by ``harmonics_k``."""

    def __init__(self, C: Any, S: Any, gm: float, radius: float, order: int | None = None,
                 omega: float = WGS84_OMEGA) -> None:
        C, S = np.asarray(C, dtype=np.float64), np.asarray(S, dtype=np.float64)
        if C.ndim != 2 or C.shape[0] != C.shape[1] or S.shape != C.shape:
            raise ConfigError("gravity.coefficients", (C.shape, S.shape), "square C and S of one shape")
        N = C.shape[0] - 1
        M = N if order is None else order
        self.degree, self.order = N, M
        self.gm, self.radius = gm, radius
        self.C, self.S = np.tril(C), np.tril(S)
        n_idx, m_idx = np.tril_indices(N + 1)
        self.params = np.concatenate([[KIND_HARMONICS, omega, gm, radius, N, M],
                                      self.C[n_idx, m_idx], self.S[n_idx, m_idx], harmonic_factors(N)])


def load_egm2008(path: Path = DATA_FILE) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Fully normalised EGM2008 coefficients ``C``, ``S`` (square arrays up to the shipped degree),
    ``gm`` [m^3/s^2] and ``radius`` [m] read from the data file (header lines ``# key = value``); the file
    is parsed once per process and content (each call gets its own arrays)."""
    C, S, gm, radius = _parsed_egm2008(Path(path).read_bytes())
    return C.copy(), S.copy(), gm, radius


@functools.lru_cache(maxsize=4)
def _parsed_egm2008(content: bytes) -> tuple[np.ndarray, np.ndarray, float, float]:
    """:func:`load_egm2008` of a file's ``content`` (read-only arrays)."""
    header, rows = {}, []
    for line in content.decode("utf-8").splitlines():
        if line.startswith("#"):
            k, _, v = line[1:].partition("=")
            if k.strip() in ("gm", "radius"):
                header[k.strip()] = float(v)
        elif line.strip() and not line.startswith("n,"):
            rows.append([float(v) for v in line.split(",")])
    rows = np.array(rows)
    n_max = int(rows[:, 0].max())
    C, S = np.zeros((n_max + 1, n_max + 1)), np.zeros((n_max + 1, n_max + 1))
    for n, m, c, s in rows:
        C[int(n), int(m)], S[int(n), int(m)] = c, s
    C.flags.writeable = S.flags.writeable = False
    return C, S, header["gm"], header["radius"]


@register("gravity", "egm2008")
class EGM2008Gravity(HarmonicGravity):
    """EGM2008 (tide-free) of ``degree`` N and ``order`` M (default M = N; thesis default N = 4).

    The shipped coefficients stop at degree 4 (``data/egm2008_n4.csv``); EGM2008's own GM
    3.986004415e14 m^3/s^2 and radius 6378136.3 m are used with them.
    """

    def __init__(self, degree: int = 4, order: int | None = None) -> None:
        C, S, gm, radius = load_egm2008()
        n_max = C.shape[0] - 1
        if isinstance(degree, bool) or not isinstance(degree, int) or not 0 <= degree <= n_max:
            raise ConfigError("gravity.degree", degree, f"an integer in [0, {n_max}]: the shipped "
                              f"EGM2008 data stops at degree {n_max}")
        if order is not None and (isinstance(order, bool) or not isinstance(order, int)
                                  or not 0 <= order <= degree):
            raise ConfigError("gravity.order", order, f"an integer in [0, degree = {degree}]")
        super().__init__(C[:degree + 1, :degree + 1], S[:degree + 1, :degree + 1], gm, radius, order)


@register("gravity", "wgs84_normal")
class WGS84NormalGravity(HarmonicGravity):
    """Normal gravitational field of the WGS84 ellipsoid: even zonal harmonics J2-J8 computed from
    the defining constants (:func:`normal_gravity_zonals`), WGS84 GM and a. Plus the centrifugal
    acceleration of the Earth-fixed frame it gives Somigliana's normal gravity on the ellipsoid."""

    def __init__(self) -> None:
        J = normal_gravity_zonals(n_max=4)
        C = np.zeros((9, 9))
        for k, jn in enumerate(J, start=1):
            C[2 * k, 0] = -jn / math.sqrt(4 * k + 1)          # C_2n,0 = -J_2n / sqrt(4n + 1)
        C[0, 0] = 1.0
        super().__init__(C, np.zeros((9, 9)), WGS84_GM, WGS84_A, order=0)
