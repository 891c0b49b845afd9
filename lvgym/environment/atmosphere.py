"""Atmosphere models (thesis section 3.2): US76 (default), exponential, NRLMSISE-00.

Every model is called the same way::

    >>> from lvgym.environment.atmosphere import Us76Atmosphere
    >>> atm = Us76Atmosphere()
    >>> s = atm([0.0, 11000.0])            # geometric altitude [m], any shape
    >>> [round(float(x), 4) for x in s.density]
    [1.225, 0.3648]

and returns an :class:`AtmosphereState` of arrays shaped like ``alt_m``: density [kg/m^3], pressure [Pa],
temperature [K] and speed of sound [m/s].

Compiled callers (a numba loads function of the simulator) use the one dispatch kernel
``atmosphere_state(p, alt_m, out)`` with ``p = model.params`` (a float64 array that holds the model code
and its parameters) and ``out`` a float64 array of 4 entries written in the order ``OUT_DENSITY``,
``OUT_PRESSURE``, ``OUT_TEMPERATURE``, ``OUT_SOUND`` (indices 0..3). The model-specific kernels
(``us76_lower``, ``exponential_state``, ``table_state``) are what it dispatches to.

Parameter array ``p``:

- ``p[0]`` model code: ``CODE_US76`` (0), ``CODE_EXPONENTIAL`` (1), ``CODE_TABLE`` (2).
- US76: ``p[1:]`` is a table block of US76 from 86 to 1000 km (below 86 km the seven layers are
  computed in closed form).
- exponential: ``p[1] = rho0`` [kg/m^3], ``p[2] = scale_height`` [m], ``p[3] = temperature`` [K].
- table (NRLMSISE-00 on a grid): ``p[1:]`` is a table block.

A table block at offset ``o`` holds ``n = p[o]`` nodes: altitudes ``z`` [m], then ``ln rho``, its slope,
``ln p``, its slope, ``T``, its slope (each ``n`` values; slopes per metre). It is a monotone cubic
Hermite (PCHIP) interpolant of log-density, log-pressure and temperature; outside the nodes
log-density and log-pressure continue linearly with the end slopes and temperature is held. The
speed of sound of a table is ``sqrt(1.4 p / rho)``, that is ``sqrt(gamma R* T / M)`` with the mean
molar mass ``M`` of the mixture and gamma = 1.4.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import NamedTuple

import numba as nb
import numpy as np

from lvgym.errors import ConfigError
from lvgym.packing import Field, Packed

from .registry import register
from .search import search_right_k

__all__ = [
    "AtmosphereState", "Us76Atmosphere", "ExponentialAtmosphere", "Nrlmsise00Atmosphere",
    "atmosphere_state", "atmosphere_batch", "us76_lower", "exponential_state", "table_state",
    "table_block", "OUT_DENSITY", "OUT_PRESSURE", "OUT_TEMPERATURE", "OUT_SOUND",
    "CODE_US76", "CODE_EXPONENTIAL", "CODE_TABLE",
]

OUT_DENSITY, OUT_PRESSURE, OUT_TEMPERATURE, OUT_SOUND = 0, 1, 2, 3
CODE_US76, CODE_EXPONENTIAL, CODE_TABLE = 0, 1, 2

# US76 defining constants (NOAA-S/T 76-1562, Part 1, Tables 2 and 4)
G0 = 9.80665                     # m/s^2, and m^2/(s^2 m') for geopotential metres
#: what every atmosphere kernel writes, in this order (an interface: callers read (B, 4) arrays)
AIR = Packed("air state", [Field("density", 1, "kg/m^3", "air density"), Field("pressure", 1, "Pa", "ambient pressure"),
                           Field("temperature", 1, "K", "air temperature"),
                           Field("speed_of_sound", 1, "m/s", "speed of sound")], interface=True)
_AIR = AIR.at
R_STAR = 8314.32                 # N m/(kmol K), gas constant of US76
M0 = 28.9644                     # kg/kmol, sea-level mean molar mass
R_AIR = R_STAR / M0              # 287.05287 J/(kg K)
R0_GEOPOT = 6356766.0            # m, Earth radius of the geopotential altitude
GAMMA = 1.4                      # ratio of specific heats
K_BOLTZMANN = 1.380649e-23       # J/K (CODATA 2018), for the NRLMSISE-00 pressure p = n k T
#: geopotential base heights [m'], base temperatures [K], lapse rates [K/m'] of the seven layers
US76_HB = np.array([0.0, 11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0])
US76_LB = np.array([-0.0065, 0.0, 0.0010, 0.0028, 0.0, -0.0028, -0.0020])
US76_H_TOP = 84852.0             # m', top of the seventh layer (86 km geometric)
US76_Z_TOP = 86000.0             # m, geometric altitude where the tabulated upper atmosphere starts


def _us76_bases() -> tuple[np.ndarray, np.ndarray]:
    """Base temperatures [K] and pressures [Pa] of the seven layers, from the lapse rates (eq. 33)."""
    tb = np.empty(7)
    pb = np.empty(7)
    tb[0], pb[0] = 288.15, 101325.0
    for b in range(6):
        dh = US76_HB[b + 1] - US76_HB[b]
        tb[b + 1] = tb[b] + US76_LB[b] * dh
        if US76_LB[b] == 0.0:
            pb[b + 1] = pb[b] * math.exp(-G0 * M0 * dh / (R_STAR * tb[b]))
        else:
            pb[b + 1] = pb[b] * (tb[b] / tb[b + 1]) ** (G0 * M0 / (R_STAR * US76_LB[b]))
    return tb, pb


US76_TB, US76_PB = _us76_bases()


@nb.njit(cache=True)
def us76_lower_at(alt_m, out, oo):
    """:func:`us76_lower` into ``out[oo:oo + 4]``."""
    h = R0_GEOPOT * alt_m / (R0_GEOPOT + alt_m)
    b = 0
    while b < 6 and h >= US76_HB[b + 1]:
        b += 1
    dh = h - US76_HB[b]
    tb = US76_TB[b]
    lapse = US76_LB[b]
    t = tb + lapse * dh
    if lapse == 0.0:
        p = US76_PB[b] * math.exp(-G0 * M0 * dh / (R_STAR * tb))
    else:
        p = US76_PB[b] * (tb / t) ** (G0 * M0 / (R_STAR * lapse))
    out[oo + _AIR.density] = p * M0 / (R_STAR * t)
    out[oo + _AIR.pressure] = p
    out[oo + _AIR.temperature] = t
    out[oo + _AIR.speed_of_sound] = math.sqrt(GAMMA * R_STAR * t / M0)


@nb.njit(cache=True)
def us76_lower(alt_m, out):
    """US76 below 86 km: the seven layers in closed form (eqs. 18, 33a, 33b, 42, 50).

    ``alt_m`` is the geometric altitude [m]; below 0 the first layer is extended (the standard
    covers -5 km), above 86 km the seventh. Writes density [kg/m^3], pressure [Pa], temperature
    (molecular-scale temperature, equal to the kinetic temperature below 80 km) [K] and speed of
    sound [m/s] into ``out[0:4]``.
    """
    us76_lower_at(alt_m, out, 0)


@nb.njit(cache=True)
def exponential_state_at(p, o, alt_m, out, oo):
    """:func:`exponential_state` with the parameters at ``p[o:]``, into ``out[oo:oo + 4]``."""
    rho = p[o + 1] * math.exp(-alt_m / p[o + 2])
    out[oo + _AIR.density] = rho
    out[oo + _AIR.pressure] = rho * R_AIR * p[o + 3]
    out[oo + _AIR.temperature] = p[o + 3]
    out[oo + _AIR.speed_of_sound] = math.sqrt(GAMMA * R_AIR * p[o + 3])


@nb.njit(cache=True)
def exponential_state(p, alt_m, out):
    """Isothermal exponential atmosphere: ``rho = rho0 exp(-alt / H)``, ``T = T0``, ``p = rho R T0``.

    ``p[1:4] = rho0 [kg/m^3], H [m], T0 [K]``; ``R = 287.05287 J/(kg K)``, speed of sound
    ``sqrt(1.4 R T0)``. Writes ``out[0:4]`` as :func:`us76_lower`.
    """
    exponential_state_at(p, 0, alt_m, out, 0)


@nb.njit(cache=True)
def table_state_at(p, o, alt_m, out, oo):
    """:func:`table_state` into ``out[oo:oo + 4]`` (no array view)."""
    n = int(p[o])
    z = o + 1                             # the nodes are p[z:z + n]
    if alt_m <= p[z] or alt_m >= p[z + n - 1]:
        k = 0 if alt_m <= p[z] else n - 1
        dz = alt_m - p[z + k]
        lnrho = p[o + 1 + n + k] + p[o + 1 + 2 * n + k] * dz
        lnp = p[o + 1 + 3 * n + k] + p[o + 1 + 4 * n + k] * dz
        t = p[o + 1 + 5 * n + k]
    else:
        i = search_right_k(p, z, z + n, alt_m) - z - 1
        h = p[z + i + 1] - p[z + i]
        s = (alt_m - p[z + i]) / h
        s2 = s * s
        s3 = s2 * s
        h00 = 2.0 * s3 - 3.0 * s2 + 1.0
        h10 = (s3 - 2.0 * s2 + s) * h
        h01 = 3.0 * s2 - 2.0 * s3
        h11 = (s3 - s2) * h
        y = o + 1 + n + i                 # ln rho at node i; its slope, ln p, ... follow by n
        lnrho = h00 * p[y] + h10 * p[y + n] + h01 * p[y + 1] + h11 * p[y + n + 1]
        y += 2 * n
        lnp = h00 * p[y] + h10 * p[y + n] + h01 * p[y + 1] + h11 * p[y + n + 1]
        y += 2 * n
        t = h00 * p[y] + h10 * p[y + n] + h01 * p[y + 1] + h11 * p[y + n + 1]
    rho = math.exp(lnrho)
    pres = math.exp(lnp)
    out[oo + _AIR.density] = rho
    out[oo + _AIR.pressure] = pres
    out[oo + _AIR.temperature] = t
    # far beyond the table (a diverged flight) the density underflows to zero: the ratio from the logarithms
    out[oo + _AIR.speed_of_sound] = math.sqrt(GAMMA * pres / rho) if rho > 0.0 else math.sqrt(GAMMA * math.exp(lnp - lnrho))


@nb.njit(cache=True)
def table_state(p, o, alt_m, out):
    """Cubic Hermite interpolation of the table block at ``p[o:]`` (layout in the module docstring).

    Writes density [kg/m^3], pressure [Pa], temperature [K] and ``sqrt(1.4 p / rho)`` [m/s].
    """
    table_state_at(p, o, alt_m, out, 0)


@nb.njit(cache=True, inline="always")
def atmosphere_state_at(p, o, alt_m, out, oo):
    """:func:`atmosphere_state` with the model's parameters at ``p[o:]`` (a packed array), into
    ``out[oo:oo + 4]``: no array view, no allocation."""
    code = int(p[o])
    if code == CODE_US76:
        if alt_m < US76_Z_TOP:
            us76_lower_at(alt_m, out, oo)
        else:
            table_state_at(p, o + 1, alt_m, out, oo)
    elif code == CODE_EXPONENTIAL:
        exponential_state_at(p, o, alt_m, out, oo)
    else:
        table_state_at(p, o + 1, alt_m, out, oo)


@nb.njit(cache=True)
def atmosphere_state(p, alt_m, out):
    """Density [kg/m^3], pressure [Pa], temperature [K] and speed of sound [m/s] at geometric
    altitude ``alt_m`` [m] into ``out[0:4]``, for any model's parameter array ``p``."""
    atmosphere_state_at(p, 0, alt_m, out, 0)


@nb.njit(cache=True)
def atmosphere_batch(p, alt_m, out):
    """:func:`atmosphere_state` for each altitude of ``alt_m`` (B,) into the rows of ``out`` (B, 4)."""
    for i in range(alt_m.shape[0]):
        atmosphere_state(p, alt_m[i], out[i])


def table_block(alt_m: np.ndarray, density: np.ndarray, pressure: np.ndarray,
                temperature: np.ndarray) -> np.ndarray:
    """Table block (layout in the module docstring) of PCHIP interpolants through the nodes.

    ``alt_m`` [m] strictly increasing, ``density`` [kg/m^3], ``pressure`` [Pa], ``temperature`` [K].
    """
    from scipy.interpolate import PchipInterpolator

    z = np.asarray(alt_m, dtype=np.float64)
    cols = [np.log(np.asarray(density, float)), np.log(np.asarray(pressure, float)),
            np.asarray(temperature, dtype=np.float64)]
    parts = [np.array([z.size], dtype=np.float64), z]
    for y in cols:
        parts += [y, PchipInterpolator(z, y).derivative()(z)]
    return np.concatenate(parts)


class AtmosphereState(NamedTuple):
    """State of the air at the requested altitudes; each field has the shape of ``alt_m``."""

    density: np.ndarray          #: kg/m^3
    pressure: np.ndarray         #: Pa
    temperature: np.ndarray      #: K
    speed_of_sound: np.ndarray   #: m/s


class _Atmosphere:
    """Common call of the atmosphere models: ``model(alt_m) -> AtmosphereState``.

    ``params`` is the float64 parameter array and ``kernel`` the compiled
    ``atmosphere_state(p, alt_m, out)`` a compiled caller uses.
    """

    params: np.ndarray

    def __call__(self, alt_m) -> AtmosphereState:
        """State at geometric altitude(s) ``alt_m`` [m] (scalar or array of any shape)."""
        alt = np.asarray(alt_m, dtype=np.float64)
        flat = np.ascontiguousarray(alt.reshape(-1))
        out = np.empty((flat.size, 4))
        atmosphere_batch(self.params, flat, out)
        if alt.ndim == 0:
            return AtmosphereState(*out[0])
        return AtmosphereState(*(out[:, k].reshape(alt.shape) for k in range(4)))


@functools.lru_cache(maxsize=1)
def _upper_us76_block() -> np.ndarray:
    """Table block of US76 from 86 to 1000 km (``data/us76_upper.csv``, provenance in its header)."""
    path = Path(__file__).with_name("data") / "us76_upper.csv"
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln and ln[0] != "#"]
    names = lines[0].split(",")
    d = dict(zip(names, np.array([ln.split(",") for ln in lines[1:]], dtype=np.float64).T))
    return table_block(d["altitude_m"], d["density_kg_m3"], d["pressure_pa"], d["temperature_k"])


@register("atmosphere", "us76")
class Us76Atmosphere(_Atmosphere):
    """COESA 1976 U.S. Standard Atmosphere from -5 to 1000 km geometric altitude (the default).

    Below 86 km: the seven layers of the standard in closed form (geopotential altitude with
    r0 = 6356766 m; the first layer extended below 0). From 86 to 1000 km: the printed Table I
    densities, the defining kinetic-temperature profile and pressures matched to the printed
    values (``data/us76_upper.csv``), interpolated in log. Above 1000 km log-density and
    log-pressure continue linearly, temperature stays 1000 K. Compiled callers: ``atmosphere_state``
    with ``params``.
    """

    def __init__(self) -> None:
        self.params = np.concatenate([[float(CODE_US76)], _upper_us76_block()])   # a fresh copy


@register("atmosphere", "exponential")
class ExponentialAtmosphere(_Atmosphere):
    """Isothermal exponential atmosphere ``rho = rho0 exp(-alt / scale_height)``.

    Defaults: ``rho0 = 1.225 kg/m^3`` (US76 sea level), ``scale_height = 7200 m`` (a fit of the US76
    density between about 20 and 70 km), ``temperature = 288.15 K``. Pressure is ``rho R T``, so it
    is hydrostatic only for ``scale_height = R T / g0`` (8434.5 m at 288.15 K). Compiled callers:
    ``atmosphere_state`` (or ``exponential_state``) with ``params``.
    """

    def __init__(self, rho0: float = 1.225, scale_height: float = 7200.0,
                 temperature: float = 288.15) -> None:
        for key, value in (("rho0", rho0), ("scale_height", scale_height),
                           ("temperature", temperature)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ConfigError(f"atmosphere.{key}", value, "must be a finite number > 0")
        self.rho0, self.scale_height, self.temperature = float(rho0), float(scale_height), \
            float(temperature)
        self.params = np.array([float(CODE_EXPONENTIAL), self.rho0, self.scale_height,
                                self.temperature])


def _number(key: str, value, lo: float, hi: float) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or not lo <= value <= hi:
        raise ConfigError(f"atmosphere.{key}", value, f"must be a number in [{lo:g}, {hi:g}]")
    return float(value)


@register("atmosphere", "nrlmsise00")
class Nrlmsise00Atmosphere(_Atmosphere):
    """NRLMSISE-00 (``pymsis``, ``version=0``) at one site and date, tabulated at construction.

    ``pymsis`` is called once on the altitude grid ``alt_min_m : alt_step_m : alt_max_m`` (geodetic
    altitude [m]) above ``latitude_deg``, ``longitude_deg`` at ``date`` (ISO string, ``datetime`` or
    ``numpy.datetime64``, UT) with the GIVEN solar and geomagnetic indices ``f107`` (previous day),
    ``f107a`` (81-day mean) [sfu] and daily ``ap``, so pymsis never looks for (or downloads) index
    files. Density is pymsis's total mass density; pressure ``p = k T sum(n_i)`` over every species
    it returns (N2, O2, O, He, H, Ar, N, anomalous O); speed of sound ``sqrt(1.4 R* T / M)`` with the
    mixture's mean molar mass ``M = rho N_A / sum(n_i)``, that is ``sqrt(1.4 p / rho)`` (gamma 1.4
    even where atomic oxygen dominates). Between nodes: PCHIP in log-density, log-pressure and
    temperature (``table_state``); outside the grid: linear in the logs, temperature held.
    Defaults: 45 N, 0 E, 2020-03-20 12:00 UT, F10.7 = F10.7a = 150, Ap = 4 (moderate sun, quiet).
    Compiled callers: ``atmosphere_state`` with ``params``.
    """

    def __init__(self, latitude_deg: float = 45.0, longitude_deg: float = 0.0,
                 date="2020-03-20T12:00:00", f107: float = 150.0, f107a: float = 150.0,
                 ap: float = 4.0, alt_min_m: float = 0.0, alt_max_m: float = 1000e3,
                 alt_step_m: float = 1000.0) -> None:
        import pymsis

        self.latitude_deg = _number("latitude_deg", latitude_deg, -90.0, 90.0)
        self.longitude_deg = _number("longitude_deg", longitude_deg, -180.0, 360.0)
        self.f107 = _number("f107", f107, 0.0, 500.0)
        self.f107a = _number("f107a", f107a, 0.0, 500.0)
        self.ap = _number("ap", ap, 0.0, 400.0)
        lo = _number("alt_min_m", alt_min_m, 0.0, 2.0e6)
        hi = _number("alt_max_m", alt_max_m, lo, 2.0e6)
        step = _number("alt_step_m", alt_step_m, 1.0, max(hi - lo, 1.0))
        if hi - lo < step:
            raise ConfigError("atmosphere.alt_max_m", alt_max_m,
                              f"must be at least alt_min_m + alt_step_m = {lo + step:g}")
        try:
            self.date = np.datetime64(date, "s")
        except (ValueError, TypeError):
            raise ConfigError("atmosphere.date", date,
                              "an ISO date-time such as '2020-03-20T12:00:00' (UT)") from None
        n = int(round((hi - lo) / step)) + 1
        self.alt_grid_m = np.linspace(lo, lo + (n - 1) * step, n)
        out = pymsis.calculate(self.date, self.longitude_deg, self.latitude_deg,
                               self.alt_grid_m / 1e3, [self.f107], [self.f107a], [[self.ap] * 7],
                               version=0).reshape(n, 11).astype(np.float64)
        rho = out[:, 0]
        temp = out[:, 10]
        number = np.nansum(out[:, 1:10], axis=1)
        self.params = np.concatenate([[float(CODE_TABLE)],
                                      table_block(self.alt_grid_m, rho, number * K_BOLTZMANN * temp,
                                                  temp)])
