"""Wind models (thesis section 3.2): none, profile, 1-cosine gust, Dryden turbulence, jet stream, sum.

Every model is called the same way::

    >>> import numpy as np
    >>> from lvgym.environment.wind import ProfileWind
    >>> wind = ProfileWind(altitude_m=[0.0, 1000.0], speed=[0.0, 10.0], direction_deg=[270.0, 270.0])
    >>> wind.reset(np.random.default_rng(0))              # draws what is random (nothing here)
    >>> wind.velocity_ned(500.0, t=0.0).round(6) + 0.0     # a west wind blows towards the east
    array([0., 5., 0.])

``velocity_ned(alt_m, t)`` is the wind velocity, i.e. the velocity of the air relative to the Earth,
in the local north-east-down frame [m/s]; ``alt_m`` [m] and ``t`` [s] broadcast together and the
result has their shape plus a last axis of 3. After ``reset(rng)`` it is a deterministic function of
``(alt_m, t)``, so it can be evaluated at every Runge-Kutta stage.

Directions are azimuths in degrees clockwise from north of where the wind blows FROM (the
meteorological convention: a 270 deg wind blows towards the east), unless a model says otherwise.

Compiled callers use ``wind_ned(p, alt_m, t, out)`` with ``p = model.params`` (re-read it after each
``reset``: random models build a new array) and ``out`` a float64 array of 3 entries, which it
overwrites with the NED wind. Parameter arrays (float64):

- ``p[0]`` model code: ``CODE_NONE`` (0), ``CODE_GRID`` (1), ``CODE_GUST`` (2), ``CODE_SUM`` (3).
- grid (profile, jet stream, Dryden realisation): ``p[1]`` coordinate (0 altitude [m], 1 time [s]),
  ``p[2]`` outside the grid (0 hold the end values, 1 zero), ``p[3] = n``, then ``n`` grid
  coordinates and ``n`` north, ``n`` east, ``n`` down components [m/s]; linear interpolation.
- gust: ``p[1]`` amplitude [m/s], ``p[2]`` length [m], ``p[3:6]`` unit NED direction of the air's
  motion, ``p[6]`` onset [m or s], ``p[7]`` onset by (0 altitude, 1 time), ``p[8]`` speed through
  the gust [m/s] (time onset), ``p[9]`` shape (0 ramp and hold, 1 bump back to zero).
- sum: ``p[1] = k`` children, ``p[2 + 2 i], p[3 + 2 i]`` start and end of child ``i`` in ``p``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numba as nb
import numpy as np
import yaml

from lvgym.errors import MISSING, ConfigError

from .registry import make, register
from .search import search_right_k

__all__ = [
    "NoWind", "ProfileWind", "GustWind", "JetStreamWind", "SumWind", "wind_ned", "wind_ned_batch",
    "wind_grid_ned", "wind_gust_ned", "grid_params", "ned_from_speed_direction",
    "CODE_NONE", "CODE_GRID", "CODE_GUST", "CODE_SUM",
]

CODE_NONE, CODE_GRID, CODE_GUST, CODE_SUM = 0, 1, 2, 3


@nb.njit(cache=True)
def wind_grid_at(p, o, alt_m, t, out, oo):
    """:func:`wind_grid_ned` with the parameters at ``p[o:]``, adding to ``out[oo:oo + 3]``."""
    x = alt_m if p[o + 1] == 0.0 else t
    n = int(p[o + 3])
    s = o + 4                                 # the grid coordinates are p[s:s + n]
    if x < p[s] or x > p[s + n - 1] or n == 1:
        if p[o + 2] != 0.0:
            return
        k = 0 if x <= p[s] else n - 1
        for c in range(3):
            out[oo + c] += p[s + (c + 1) * n + k]
        return
    i = min(search_right_k(p, s, s + n, x) - s - 1, n - 2)
    f = (x - p[s + i]) / (p[s + i + 1] - p[s + i])
    for c in range(3):
        j = s + (c + 1) * n + i
        out[oo + c] += (1.0 - f) * p[j] + f * p[j + 1]


@nb.njit(cache=True)
def wind_grid_ned(p, alt_m, t, out):
    """Add the linearly interpolated grid wind [m/s] of ``p`` (layout in the module docstring) to
    ``out[0:3]``; the grid coordinate is ``alt_m`` [m] or ``t`` [s]."""
    wind_grid_at(p, 0, alt_m, t, out, 0)


@nb.njit(cache=True)
def wind_gust_at(p, o, alt_m, t, out, oo):
    """:func:`wind_gust_ned` with the parameters at ``p[o:]``, adding to ``out[oo:oo + 3]``."""
    x = alt_m - p[o + 6] if p[o + 7] == 0.0 else p[o + 8] * (t - p[o + 6])
    dm = p[o + 2]
    if x <= 0.0:
        return
    if x <= dm or (p[o + 9] != 0.0 and x <= 2.0 * dm):
        f = 0.5 * (1.0 - math.cos(math.pi * x / dm))
    elif p[o + 9] != 0.0:
        return
    else:
        f = 1.0
    for c in range(3):
        out[oo + c] += p[o + 1] * f * p[o + 3 + c]


@nb.njit(cache=True)
def wind_gust_ned(p, alt_m, t, out):
    """Add the 1-cosine gust of MIL-F-8785C / MIL-HDBK-1797 [m/s] to ``out[0:3]``.

    ``V = (Vm / 2) (1 - cos(pi x / dm))`` for ``0 <= x <= dm``, 0 before, ``Vm`` after (ramp) or the
    cosine continued back to 0 at ``2 dm`` and 0 after (bump); ``x`` is the distance into the gust:
    ``alt_m - onset`` or ``speed (t - onset)``.
    """
    wind_gust_at(p, 0, alt_m, t, out, 0)


@nb.njit(cache=True, inline="always")
def _leaf(p, o, alt_m, t, out, oo):
    code = int(p[o])
    if code == CODE_GRID:
        wind_grid_at(p, o, alt_m, t, out, oo)
    elif code == CODE_GUST:
        wind_gust_at(p, o, alt_m, t, out, oo)


@nb.njit(cache=True, inline="always")
def wind_ned_at(p, o, alt_m, t, out, oo):
    """:func:`wind_ned` with the model's parameters at ``p[o:]`` (a packed array; child offsets of a
    sum are relative to ``o``), into ``out[oo:oo + 3]``: no array view, no allocation."""
    out[oo] = 0.0
    out[oo + 1] = 0.0
    out[oo + 2] = 0.0
    if int(p[o]) == CODE_SUM:
        for i in range(int(p[o + 1])):
            _leaf(p, o + int(p[o + 2 + 2 * i]), alt_m, t, out, oo)
    else:
        _leaf(p, o, alt_m, t, out, oo)


@nb.njit(cache=True)
def wind_ned(p, alt_m, t, out):
    """Wind velocity [m/s] in NED at altitude ``alt_m`` [m] and time ``t`` [s] into ``out[0:3]``
    (overwritten), for any model's parameter array ``p``."""
    wind_ned_at(p, 0, alt_m, t, out, 0)


@nb.njit(cache=True)
def wind_ned_batch(p, alt_m, t, out):
    """:func:`wind_ned` for each pair ``alt_m[i]``, ``t[i]`` (B,) into the rows of ``out`` (B, 3)."""
    for i in range(alt_m.shape[0]):
        wind_ned(p, alt_m[i], t[i], out[i])


def grid_params(s, ned, *, coordinate: int = 0, zero_outside: bool = False) -> np.ndarray:
    """Grid parameter array: coordinates ``s`` (n,) [m or s], NED wind ``ned`` (n, 3) [m/s]."""
    s = np.asarray(s, dtype=np.float64)
    ned = np.asarray(ned, dtype=np.float64).reshape(s.size, 3)
    head = [float(CODE_GRID), float(coordinate), 1.0 if zero_outside else 0.0, float(s.size)]
    return np.concatenate([head, s, ned[:, 0], ned[:, 1], ned[:, 2]])


def ned_from_speed_direction(speed, direction_deg, convention: str = "from") -> np.ndarray:
    """NED wind (n, 3) [m/s] from horizontal speed [m/s] and azimuth [deg] the wind blows FROM
    (``convention="from"``) or TO (``"to"``)."""
    psi = np.radians(np.asarray(direction_deg, dtype=np.float64))
    sign = -1.0 if convention == "from" else 1.0
    v = sign * np.asarray(speed, dtype=np.float64)
    return np.stack([v * np.cos(psi), v * np.sin(psi), np.zeros_like(v)], axis=-1)


def _real(key: str, value, lo: float = -math.inf, hi: float = math.inf) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or not lo <= value <= hi:
        raise ConfigError(key, value, f"must be a finite number in [{lo:g}, {hi:g}]")
    return float(value)


def _choice(key: str, value, allowed: Sequence[str]) -> str:
    if value not in allowed:
        raise ConfigError(key, value, f"one of {list(allowed)}")
    return value


class _Wind:
    """Common call of the wind models (see the module docstring).

    ``params`` is the float64 parameter array and ``kernel`` the compiled
    ``wind_ned(p, alt_m, t, out)`` a compiled caller uses.
    """

    _params: np.ndarray | None = None

    @property
    def params(self) -> np.ndarray:
        """Parameter array of ``wind_ned`` (built by ``reset`` for random models)."""
        if self._params is None:
            raise RuntimeError(f"{type(self).__name__}: call reset(rng) before using the wind")
        return self._params

    def reset(self, rng: np.random.Generator) -> None:
        """Draw whatever is random from ``rng`` (deterministic models only check it)."""
        if not isinstance(rng, np.random.Generator):
            raise TypeError(f"reset needs a numpy.random.Generator, got {type(rng).__name__}")

    def velocity_ned(self, alt_m, t=0.0) -> np.ndarray:
        """Wind velocity [m/s] in NED at altitude ``alt_m`` [m] and time ``t`` [s] (broadcast)."""
        alt, tt = np.broadcast_arrays(np.asarray(alt_m, dtype=np.float64),
                                      np.asarray(t, dtype=np.float64))
        a = np.ascontiguousarray(alt.reshape(-1))
        out = np.empty((a.size, 3))
        wind_ned_batch(self.params, a, np.ascontiguousarray(tt.reshape(-1)), out)
        return out.reshape(alt.shape + (3,))


@register("wind", "none")
class NoWind(_Wind):
    """No wind (the thesis default): the air is at rest relative to the Earth."""

    def __init__(self) -> None:
        self._params = np.array([float(CODE_NONE)])


def _read_profile_file(path: Path) -> dict:
    """``altitude_m``, ``speed``, ``direction_deg`` (and ``convention``) from a YAML or CSV file."""
    key = "wind.file"
    if not path.is_file():
        raise ConfigError(key, str(path), "an existing .yaml, .yml or .csv file")
    text = path.read_text(encoding="utf-8")
    if path.suffix.lower() in (".yaml", ".yml"):
        data = yaml.safe_load(text)
        if not isinstance(data, Mapping):
            raise ConfigError("wind", data, "a mapping with altitude_m, speed, direction_deg",
                              source=str(path))
        unknown = set(data) - {"altitude_m", "speed", "direction_deg", "convention"}
        if unknown:
            name = sorted(unknown)[0]
            raise ConfigError(f"wind.{name}", data[name], "unknown key; allowed: altitude_m, "
                              "speed, direction_deg, convention", source=str(path))
        return dict(data)
    if path.suffix.lower() != ".csv":
        raise ConfigError(key, str(path), "a .yaml, .yml or .csv file")
    rows = [r for r in csv.reader(ln for ln in text.splitlines() if ln.strip()
                                  and not ln.lstrip().startswith("#"))]
    header = [h.strip() for h in rows[0]] if rows else []
    cols = {}
    for name in ("altitude_m", "speed", "direction_deg"):
        if name not in header:
            raise ConfigError(f"wind.{name}", MISSING, "a CSV column (header: altitude_m, speed, "
                              "direction_deg)", source=str(path))
        j = header.index(name)
        try:
            cols[name] = [float(r[j]) for r in rows[1:]]
        except (ValueError, IndexError):
            raise ConfigError(f"wind.{name}", "<table>", "numbers in every row",
                              source=str(path)) from None
    return cols


@register("wind", "profile")
class ProfileWind(_Wind):
    """Tabulated horizontal wind: altitude [m] -> speed [m/s] and direction [deg].

    ``direction_deg`` is the azimuth the wind blows FROM (``convention="from"``, meteorological) or
    TO (``convention="to"``). Give the three arrays, or ``file``: a YAML mapping with those keys
    (and optionally ``convention``) or a CSV file with the header ``altitude_m,speed,direction_deg``
    (``#`` comments allowed). The north and east components are interpolated linearly in altitude
    (so the wind turns through the shorter way and is never undefined between nodes); above and
    below the table the end values hold. Compiled callers: ``wind_ned`` with ``params``.
    """

    def __init__(self, altitude_m=None, speed=None, direction_deg=None, convention: str = "from",
                 file: str | None = None) -> None:
        if file is not None:
            data = _read_profile_file(Path(file))
            altitude_m, speed, direction_deg = (data.get(k) for k in
                                                ("altitude_m", "speed", "direction_deg"))
            convention = data.get("convention", convention)
        self.convention = _choice("wind.convention", convention, ("from", "to"))
        arrays = {}
        for key, value in (("altitude_m", altitude_m), ("speed", speed),
                           ("direction_deg", direction_deg)):
            try:
                a = np.atleast_1d(np.asarray(value, dtype=np.float64))
            except (TypeError, ValueError):
                a = None
            if value is None or a is None or a.ndim != 1 or a.size == 0 or \
                    not np.all(np.isfinite(a)):
                raise ConfigError(f"wind.{key}", MISSING if value is None else value,
                                  "a non-empty list of finite numbers")
            arrays[key] = a
        z, v, d = arrays["altitude_m"], arrays["speed"], arrays["direction_deg"]
        if not z.size == v.size == d.size:
            raise ConfigError("wind.speed", list(v), f"as many values as altitude_m ({z.size})")
        if np.any(np.diff(z) <= 0):
            raise ConfigError("wind.altitude_m", list(z), "strictly increasing")
        if np.any(v < 0):
            raise ConfigError("wind.speed", list(v), "every speed >= 0")
        self.altitude_m, self.speed, self.direction_deg = z, v, d
        self._params = grid_params(z, ned_from_speed_direction(v, d, self.convention))


@register("wind", "gust")
class GustWind(_Wind):
    """Discrete 1-cosine gust (MIL-F-8785C 3.7.4, MIL-HDBK-1797): horizontal, from ``direction_deg``.

    ``amplitude`` Vm [m/s], ``length`` dm [m] (the ramp length), ``direction_deg`` azimuth it blows
    FROM. ``onset_by="altitude"``: the gust starts at altitude ``onset`` [m] and ``x = alt - onset``
    (a horizontal gust layer the vehicle climbs through); ``onset_by="time"``: it starts at time
    ``onset`` [s] and ``x = speed (t - onset)`` with ``speed`` [m/s] the vehicle's speed through it.
    ``shape="ramp"`` holds Vm after the ramp (the specification); ``"bump"`` falls back to zero over
    a second length. Compiled callers: ``wind_ned`` (or ``wind_gust_ned``) with ``params``.
    """

    def __init__(self, amplitude: float = 10.0, length: float = 100.0, direction_deg: float = 270.0,
                 onset: float = 1000.0, onset_by: str = "altitude", speed: float | None = None,
                 shape: str = "ramp") -> None:
        self.amplitude = _real("wind.amplitude", amplitude, 0.0)
        self.length = _real("wind.length", length, 1e-6)
        self.direction_deg = _real("wind.direction_deg", direction_deg)
        self.onset = _real("wind.onset", onset)
        self.onset_by = _choice("wind.onset_by", onset_by, ("altitude", "time"))
        self.shape = _choice("wind.shape", shape, ("ramp", "bump"))
        if self.onset_by == "time":
            if speed is None:
                raise ConfigError("wind.speed", MISSING, "required with onset_by='time': the speed "
                                  "[m/s] that turns the gust length into a ramp time")
            self.speed = _real("wind.speed", speed, 1e-6)
        else:
            self.speed = 0.0 if speed is None else _real("wind.speed", speed, 0.0)
        unit = ned_from_speed_direction(1.0, self.direction_deg)
        self._params = np.array([float(CODE_GUST), self.amplitude, self.length, *unit,
                                 self.onset, 0.0 if self.onset_by == "altitude" else 1.0,
                                 self.speed, 0.0 if self.shape == "ramp" else 1.0])


def _range(key: str, value, lo: float, hi: float) -> tuple[float, float]:
    ok = isinstance(value, Sequence) and len(value) == 2
    pair = tuple(_real(key, x, lo, hi) for x in value) if ok else None
    if pair is None or pair[0] > pair[1]:
        raise ConfigError(key, value, f"a pair [low, high] with {lo:g} <= low <= high <= {hi:g}")
    return pair


@register("wind", "jet_stream")
class JetStreamWind(_Wind):
    """Randomised wind profile for domain randomisation; each ``reset`` draws a new ``profile``.

    Speed ``U(h) G_a(h) + V_jet G(h)`` with the boundary-layer power law
    ``U(h) = U10 (min(h, h_bl) / 10 m)^alpha``, the jet ``G(h) = exp(-((h - h_jet) / w)^2 / 2)``,
    ``G_a = 1`` up to the jet and ``G`` above it, and ``V_jet`` chosen so that the speed at
    ``h_jet`` is the drawn peak speed (or ``U(h_jet)`` if that is larger). The direction (FROM)
    veers linearly from the surface direction at the ground to the jet's at ``h_jet``. Each
    quantity is drawn uniformly from its range ``[low, high]`` (defaults): ``surface_speed`` U10
    (0, 10) m/s, ``shear_exponent`` alpha (0.1, 0.2), ``boundary_layer_m`` h_bl (300, 1000) m,
    ``peak_altitude_m`` h_jet (9, 14) km, ``peak_speed`` (15, 70) m/s, ``width_m`` w (1.5, 4) km,
    ``direction_deg`` of the jet (0, 360), ``veer_deg`` surface minus jet direction (-90, 90).
    The profile is tabulated from 0 to ``alt_max_m`` (25 m steps to 2 km, 250 m above) and holds
    its top value above. ``drawn`` holds the last draw. Compiled callers: ``wind_ned`` with
    ``params`` (re-read after ``reset``).
    """

    def __init__(self, surface_speed=(0.0, 10.0), shear_exponent=(0.1, 0.2),
                 boundary_layer_m=(300.0, 1000.0), peak_altitude_m=(9000.0, 14000.0),
                 peak_speed=(15.0, 70.0), width_m=(1500.0, 4000.0), direction_deg=(0.0, 360.0),
                 veer_deg=(-90.0, 90.0), alt_max_m: float = 40e3) -> None:
        self.ranges = {
            "surface_speed": _range("wind.surface_speed", surface_speed, 0.0, 100.0),
            "shear_exponent": _range("wind.shear_exponent", shear_exponent, 0.0, 1.0),
            "boundary_layer_m": _range("wind.boundary_layer_m", boundary_layer_m, 10.0, 5000.0),
            "peak_altitude_m": _range("wind.peak_altitude_m", peak_altitude_m, 1000.0, 30000.0),
            "peak_speed": _range("wind.peak_speed", peak_speed, 0.0, 200.0),
            "width_m": _range("wind.width_m", width_m, 100.0, 20000.0),
            "direction_deg": _range("wind.direction_deg", direction_deg, -360.0, 720.0),
            "veer_deg": _range("wind.veer_deg", veer_deg, -180.0, 180.0),
        }
        self.alt_max_m = _real("wind.alt_max_m", alt_max_m, 2500.0, 1e6)
        self.altitude_m = np.unique(np.concatenate([np.arange(0.0, 2000.0, 25.0),
                                                    np.arange(2000.0, self.alt_max_m, 250.0),
                                                    [self.alt_max_m]]))
        self.drawn: dict[str, float] = {}
        self.profile: ProfileWind | None = None

    def reset(self, rng: np.random.Generator) -> None:
        super().reset(rng)
        self.drawn = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in self.ranges.items()}
        d = self.drawn
        h = self.altitude_m
        base = d["surface_speed"] * (np.minimum(h, d["boundary_layer_m"]) / 10.0) ** \
            d["shear_exponent"]
        base_jet = d["surface_speed"] * (min(d["peak_altitude_m"], d["boundary_layer_m"]) / 10.0) \
            ** d["shear_exponent"]
        g = np.exp(-0.5 * ((h - d["peak_altitude_m"]) / d["width_m"]) ** 2)
        v_jet = max(d["peak_speed"] - base_jet, 0.0)
        speed = np.where(h <= d["peak_altitude_m"], base, base * g) + v_jet * g
        frac = np.minimum(h / d["peak_altitude_m"], 1.0)
        direction = d["direction_deg"] + d["veer_deg"] * (1.0 - frac)
        self.profile = ProfileWind(altitude_m=h, speed=speed, direction_deg=direction)
        self._params = self.profile.params


@register("wind", "random_gust")
class RandomGustWind(_Wind):
    """A discrete 1-cosine gust (:class:`GustWind`, ``shape="bump"``, onset by altitude) whose amplitude
    [m/s], length [m] (the ramp: half the gust's wavelength), direction it blows FROM [deg] and onset
    altitude [m] are drawn uniformly from their ranges ``[low, high]`` at every ``reset``. Defaults:
    ``amplitude`` (5, 15) m/s and ``length`` (30, 300) m, around the 9 m/s 1-cosine gust of 30-300 m that
    NASA's terrestrial environment criteria add to a design wind profile; ``onset_m`` (1, 15) km, the
    whole climb through the dense atmosphere (the max-q suite narrows it to the max-q altitude);
    ``direction_deg`` (0, 360). ``drawn`` holds the last draw."""

    def __init__(self, amplitude=(5.0, 15.0), length=(30.0, 300.0), direction_deg=(0.0, 360.0),
                 onset_m=(1000.0, 15000.0)) -> None:
        self.ranges = {"amplitude": _range("wind.amplitude", amplitude, 0.0, 100.0),
                       "length": _range("wind.length", length, 1.0, 10000.0),
                       "direction_deg": _range("wind.direction_deg", direction_deg, -360.0, 720.0),
                       "onset": _range("wind.onset_m", onset_m, 0.0, 1e5)}
        self.drawn: dict[str, float] = {}

    def reset(self, rng: np.random.Generator) -> None:
        super().reset(rng)
        self.drawn = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in self.ranges.items()}
        self._params = GustWind(shape="bump", **self.drawn).params


@register("wind", "sum")
class SumWind(_Wind):
    """Sum of several wind models, e.g. ``{"model": "sum", "models": ["jet_stream", "dryden"]}``.

    ``models`` lists model names, mappings (``{"model": "gust", ...}``) or wind model objects;
    nested sums are flattened. ``reset(rng)`` gives each child its own generator from
    a generator seeded from ``rng``'s stream, so one child's draws do not depend on another's. Compiled callers: ``wind_ned``
    with ``params`` (re-read after ``reset``).
    """

    def __init__(self, models: Sequence = ()) -> None:
        if isinstance(models, (str, Mapping)) or not isinstance(models, Sequence) or not models:
            raise ConfigError("wind.models", models, "a non-empty list of wind models")
        children: list[_Wind] = []
        for i, spec in enumerate(models):
            child = spec if isinstance(spec, _Wind) else make("wind", spec, key=f"wind.models[{i}]")
            children.extend(child.children if isinstance(child, SumWind) else [child])
        self.children = children
        self._params = None
        if all(c._params is not None for c in children):
            self._build()

    def _build(self) -> None:
        parts = [c.params for c in self.children]
        k = len(parts)
        start = 2 + 2 * k
        index = []
        for part in parts:
            index += [start, start + part.size]
            start += part.size
        self._params = np.concatenate([[float(CODE_SUM), float(k)], np.array(index, float), *parts])

    def reset(self, rng: np.random.Generator) -> None:
        super().reset(rng)
        seeds = rng.integers(0, 2**63, size=len(self.children))   # from rng's own stream: reproducible
        for child, child_rng in zip(self.children, (np.random.default_rng(int(k)) for k in seeds)):
            child.reset(child_rng)
        self._build()
