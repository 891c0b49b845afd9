"""Dryden continuous turbulence (MIL-F-8785C 3.7.2, MIL-HDBK-1797) as a seeded, frozen wind field.

Scale lengths and intensities by height ``h`` above the ground (in feet, as the specification):

- low altitude, ``h <= 1000 ft``: ``L_w = h``, ``L_u = L_v = h / (0.177 + 0.000823 h)^1.2``,
  ``sigma_w = 0.1 W20`` (W20 the wind speed at 20 ft), ``sigma_u = sigma_v = sigma_w /
  (0.177 + 0.000823 h)^0.4``; ``h`` is clipped at 10 ft, as in JSBSim;
- medium/high altitude, ``h >= 2000 ft``: ``L_u = L_v = L_w = 1750 ft`` and ``sigma_u = sigma_v =
  sigma_w`` from the probability-of-exceedance table (MIL-F-8785C Figure 7, the table of JSBSim's
  ``FGWinds``), interpolated linearly in altitude and held beyond 500 and 80,000 ft;
- in between, each value is interpolated linearly between its values at 1000 and 2000 ft.

``u`` is along the mean wind at 20 ft (``wind_from_deg``), ``v`` horizontal to its right, ``w`` down.

The realisation is a frozen field (Taylor's hypothesis) along one coordinate ``s``: the altitude
above ``alt_min_m`` (``coordinate="altitude"``, a horizontally uniform turbulence column the vehicle
climbs through, so the path length is the altitude gained) or the time (``coordinate="time"``, a
vehicle at ``airspeed`` and fixed ``altitude_m``, where the spatial scale lengths become the time
constants ``L / V``). Along ``s`` each component is ``sigma(s) x(tau(s))`` with ``tau = integral of
ds / L(s)`` and ``x`` the stationary unit-variance process of unit scale length: the first-order
Dryden (Ornstein-Uhlenbeck) process (correlation ``exp(-xi / L)``) for the component along the path
and the second-order Dryden process ``(1 + sqrt(3) L s) / (1 + L s)^2`` (correlation
``(1 - xi / (2 L)) exp(-xi / L)``) for the two across it: ``u`` longitudinal, ``v``, ``w`` transverse
along a horizontal path (time mode, MIL-F-8785C's assignment), ``w`` longitudinal, ``u``, ``v``
transverse along the vertical path of an ascent (altitude mode). With constant ``L`` this is exactly the Dryden spectrum; with a
slowly varying ``L`` it keeps the local scale length. The processes are stepped with their exact
discretisation on a grid with ``d tau <= resolution`` (so every node has exactly the variance
``sigma^2``) and the run-time call interpolates linearly (losing on average a fraction
``resolution / 3`` of the variance between nodes of the ``u`` process, 0.7 % at the default 0.02).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from lvgym.errors import MISSING, ConfigError

from .registry import register
from .wind import _Wind, _choice, _real, grid_params

__all__ = ["DrydenWind", "dryden_scales", "dryden_psd", "unit_dryden", "POE_PROBABILITIES",
           "INTENSITIES"]

FT = 0.3048                      # m per ft
KNOT = 1852.0 / 3600.0           # m/s per knot
#: MIL-F-8785C Figure 7 (as in JSBSim FGWinds): altitude [ft] and sigma [ft/s] by probability
POE_ALT_FT = np.array([500.0, 1750.0, 3750.0, 7500.0, 15000.0, 25000.0, 35000.0, 45000.0,
                       55000.0, 65000.0, 75000.0, 80000.0])
POE_SIGMA_FTPS = {
    2e-1: [3.2, 2.2, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    1e-1: [4.2, 3.6, 3.3, 1.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    1e-2: [6.6, 6.9, 7.4, 6.7, 4.6, 2.7, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0],
    1e-3: [8.6, 9.6, 10.6, 10.1, 8.0, 6.6, 5.0, 4.2, 2.7, 0.0, 0.0, 0.0],
    1e-4: [11.8, 13.0, 16.0, 15.1, 11.6, 9.7, 8.1, 8.2, 7.9, 4.9, 3.2, 2.1],
    1e-5: [15.6, 17.6, 23.0, 23.6, 22.1, 20.0, 16.0, 15.1, 12.1, 7.9, 6.2, 5.1],
    1e-6: [18.7, 21.5, 28.4, 30.2, 30.7, 31.0, 25.2, 23.1, 17.5, 10.7, 8.4, 7.2],
}
POE_PROBABILITIES = tuple(POE_SIGMA_FTPS)
#: MIL-F-8785C 3.7.2: W20 [m/s] and probability of exceedance of light, moderate, severe turbulence
INTENSITIES = {"light": (15.0 * KNOT, 1e-2), "moderate": (30.0 * KNOT, 1e-3),
               "severe": (45.0 * KNOT, 1e-5)}


def dryden_scales(height_m, w20: float, probability: float) -> tuple[np.ndarray, np.ndarray]:
    """Scale lengths ``(L_u, L_v, L_w)`` [m] and intensities ``(sigma_u, sigma_v, sigma_w)`` [m/s].

    ``height_m`` [m] above the ground (any shape; the results get a last axis of 3), ``w20`` the
    wind speed at 20 ft [m/s], ``probability`` of exceedance, one of ``POE_PROBABILITIES``.
    """
    h = np.maximum(np.asarray(height_m, dtype=np.float64) / FT, 10.0)
    lo = np.minimum(h, 1000.0)
    a = 0.177 + 0.000823 * lo
    l_uv_lo = lo / a ** 1.2
    sw_lo = 0.1 * w20 / FT * np.ones_like(h)
    su_lo = sw_lo / a ** 0.4
    sig_hi = np.interp(np.maximum(h, 2000.0), POE_ALT_FT, POE_SIGMA_FTPS[probability])
    f = np.clip((h - 1000.0) / 1000.0, 0.0, 1.0)
    lengths = np.stack([l_uv_lo, l_uv_lo, lo], axis=-1) * (1 - f[..., None]) + \
        1750.0 * f[..., None]
    sigmas = np.stack([su_lo, su_lo, sw_lo], axis=-1) * (1 - f[..., None]) + \
        sig_hi[..., None] * f[..., None]
    return lengths * FT, sigmas * FT


def dryden_psd(omega, sigma: float, length: float, component: str) -> np.ndarray:
    """One-sided Dryden spectrum ``Phi(Omega)`` [(m/s)^2 / (rad/m)] at spatial frequency ``omega``
    [rad/m]: ``u``: ``sigma^2 (2 L / pi) / (1 + (L Omega)^2)``; ``v``, ``w``:
    ``sigma^2 (L / pi) (1 + 3 (L Omega)^2) / (1 + (L Omega)^2)^2``. Integrates to ``sigma^2``.
    (For time, use ``Omega = omega / V`` and divide by ``V``.)"""
    x = (length * np.asarray(omega, dtype=np.float64)) ** 2
    if component == "u":
        return sigma ** 2 * 2.0 * length / math.pi / (1.0 + x)
    return sigma ** 2 * length / math.pi * (1.0 + 3.0 * x) / (1.0 + x) ** 2


@nb.njit(cache=True)
def unit_dryden(dtau, noise):
    """Unit-variance Dryden processes of unit scale length at the nodes of a grid.

    ``dtau`` (n-1, 3): steps of ``tau = integral ds / L`` of the u, v, w components; ``noise``
    (n, 5): standard normal draws. Returns (n, 3). ``u``: exact Ornstein-Uhlenbeck step
    ``x' = e^-d x + sqrt(1 - e^-2d) n``. ``v``, ``w``: the state of ``y'' + 2 y' + y = white`` (whose
    stationary covariance is I / 4) stepped with ``e^(A d) = e^-d [[1 + d, d], [-d, 1 - d]]`` and
    the process noise ``(I - F F^T) / 4``; output ``y + sqrt(3) y'``. All start stationary.
    """
    n = noise.shape[0]
    out = np.empty((n, 3))
    x = noise[0, 0]
    out[0, 0] = x
    for i in range(1, n):
        e = math.exp(-dtau[i - 1, 0])
        x = e * x + math.sqrt(max(1.0 - e * e, 0.0)) * noise[i, 0]
        out[i, 0] = x
    for c in range(1, 3):
        y0 = 0.5 * noise[0, 2 * c - 1]
        y1 = 0.5 * noise[0, 2 * c]
        out[0, c] = y0 + math.sqrt(3.0) * y1
        for i in range(1, n):
            d = dtau[i - 1, c]
            e = math.exp(-d)
            f00, f01, f10, f11 = e * (1 + d), e * d, -e * d, e * (1 - d)
            q00 = 0.25 * (1.0 - f00 * f00 - f01 * f01)
            q01 = -0.25 * (f00 * f10 + f01 * f11)
            q11 = 0.25 * (1.0 - f10 * f10 - f11 * f11)
            l00 = math.sqrt(max(q00, 0.0))
            l10 = q01 / l00 if l00 > 0.0 else 0.0
            l11 = math.sqrt(max(q11 - l10 * l10, 0.0))
            z0 = f00 * y0 + f01 * y1 + l00 * noise[i, 2 * c - 1]
            z1 = f10 * y0 + f11 * y1 + l10 * noise[i, 2 * c - 1] + l11 * noise[i, 2 * c]
            y0, y1 = z0, z1
            out[i, c] = y0 + math.sqrt(3.0) * y1
    return out


@register("wind", "dryden")
class DrydenWind(_Wind):
    """Dryden turbulence (see the module docstring), a new frozen realisation at each ``reset``.

    ``intensity``: ``"light"``, ``"moderate"`` or ``"severe"`` (W20 = 15, 30, 45 kt and probability
    of exceedance 1e-2, 1e-3, 1e-5, MIL-F-8785C); ``w20`` [m/s] and ``probability`` override them.
    ``wind_from_deg``: azimuth of the mean wind at 20 ft (axis of ``u``). ``coordinate="altitude"``:
    field over altitudes ``alt_min_m`` (the ground) to ``alt_max_m`` [m], zero outside.
    ``coordinate="time"``: field over ``0 <= t <= duration`` [s] for ``airspeed`` [m/s] at
    ``altitude_m`` [m] above the ground, zero outside. ``resolution``: the largest grid step in
    scale lengths. After ``reset``: ``grid`` (n,) [m or s], ``scale_length`` (n, 3) [m],
    ``sigma`` (n, 3) [m/s], ``unit`` (n, 3) the unit processes, ``ned`` (n, 3) [m/s].
    Compiled callers: ``wind_ned`` with ``params`` (re-read after ``reset``).
    """

    def __init__(self, intensity: str = "moderate", w20: float | None = None,
                 probability: float | None = None, wind_from_deg: float = 0.0,
                 coordinate: str = "altitude", alt_min_m: float = 0.0, alt_max_m: float = 100e3,
                 airspeed: float | None = None, altitude_m: float | None = None,
                 duration: float | None = None, resolution: float = 0.02) -> None:
        _choice("wind.intensity", intensity, tuple(INTENSITIES))
        w20_default, p_default = INTENSITIES[intensity]
        self.w20 = w20_default if w20 is None else _real("wind.w20", w20, 0.0, 100.0)
        p = p_default if probability is None else probability
        match = [q for q in POE_PROBABILITIES if isinstance(p, (int, float)) and
                 math.isclose(p, q, rel_tol=1e-6)]
        if not match:
            raise ConfigError("wind.probability", probability, f"one of {list(POE_PROBABILITIES)}")
        self.probability = match[0]
        self.wind_from_deg = _real("wind.wind_from_deg", wind_from_deg)
        self.coordinate = _choice("wind.coordinate", coordinate, ("altitude", "time"))
        self.resolution = _real("wind.resolution", resolution, 1e-4, 0.5)
        self.alt_min_m = _real("wind.alt_min_m", alt_min_m, -1e4, 1e5)
        self.alt_max_m = _real("wind.alt_max_m", alt_max_m, self.alt_min_m + 1.0, 1e6)
        if self.coordinate == "time":
            for key, value, lo in (("airspeed", airspeed, 1e-3), ("altitude_m", altitude_m, 0.0),
                                   ("duration", duration, 1e-3)):
                if value is None:
                    raise ConfigError(f"wind.{key}", MISSING, "required with coordinate='time'")
                _real(f"wind.{key}", value, lo, 1e7)
            self.airspeed, self.altitude_m, self.duration = float(airspeed), float(altitude_m), \
                float(duration)
        self._build_grid()

    def _build_grid(self) -> None:
        """Grid nodes ``grid`` and, per component, the steps of ``tau`` between them."""
        if self.coordinate == "time":
            lengths, sigmas = dryden_scales(self.altitude_m, self.w20, self.probability)
            lt = lengths / self.airspeed
            n = int(math.ceil(self.duration / (self.resolution * lt.min()))) + 1
            self.grid = np.linspace(0.0, self.duration, n)
            self.scale_length = np.broadcast_to(lengths, (n, 3)).copy()
            self.sigma = np.broadcast_to(sigmas, (n, 3)).copy()
            self._dtau = np.broadcast_to(np.diff(self.grid)[:, None] / lt, (n - 1, 3)).copy()
            return
        top = self.alt_max_m - self.alt_min_m
        fine = np.unique(np.concatenate([np.linspace(0.0, min(top, 700.0), 7001),
                                         np.arange(700.0, top, 5.0), [top]]))
        lengths, _ = dryden_scales(fine, self.w20, self.probability)
        inv = 1.0 / lengths
        tau = np.concatenate([np.zeros((1, 3)),
                              np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(fine)[:, None], 0)])
        tau_min = np.concatenate([[0.0], np.cumsum(0.5 * (inv.max(1)[1:] + inv.max(1)[:-1]) *
                                                   np.diff(fine))])
        n = int(math.ceil(tau_min[-1] / self.resolution)) + 1
        h = np.interp(np.linspace(0.0, tau_min[-1], n), tau_min, fine)
        self.grid = self.alt_min_m + h
        self.scale_length, self.sigma = dryden_scales(h, self.w20, self.probability)
        self._dtau = np.diff(np.stack([np.interp(h, fine, tau[:, c]) for c in range(3)], -1), axis=0)

    def reset(self, rng: np.random.Generator) -> None:
        super().reset(rng)
        # the first-order (longitudinal) process goes to the component along the path: u along a
        # horizontal flight path (time mode), w along the vertical path of an ascent (altitude mode)
        order = [2, 0, 1] if self.coordinate == "altitude" else [0, 1, 2]
        unit = unit_dryden(np.ascontiguousarray(self._dtau[:, order]), rng.standard_normal((self.grid.size, 5)))
        self.unit = np.empty_like(unit)
        self.unit[:, order] = unit
        uvw = self.sigma * self.unit
        psi = math.radians(self.wind_from_deg) + math.pi     # the mean wind blows towards psi
        c, s = math.cos(psi), math.sin(psi)
        self.ned = np.stack([c * uvw[:, 0] - s * uvw[:, 1], s * uvw[:, 0] + c * uvw[:, 1],
                             uvw[:, 2]], axis=-1)
        self._params = grid_params(self.grid, self.ned, zero_outside=True,
                                   coordinate=0 if self.coordinate == "altitude" else 1)
