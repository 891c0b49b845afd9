"""Gain schedules of the PID family (:mod:`.pid`): gains and channels per row of a monotonic scheduling
variable, read from and written to YAML.

A schedule (``baselines/schedules/<name>.yaml`` or a path) has a ``variable`` (``mass`` [kg], the default;
``time`` [s]; ``mach``), an ``interpolation`` (``linear``, the default; ``nearest``) and ``rows``, each with
the breakpoint (``mass_kg``, ``time_s`` or ``mach``) and:

* ``kp`` [rad of gimbal per rad/s], ``ki`` [rad per rad], ``kd`` [rad per rad/s^2], ``n`` [rad/s]
  (optional, default inf: an unfiltered derivative): the PID;
* ``filter`` (optional, in every row or none): the structural filtering of the error, one mapping of
  :class:`.filters.StructuralFilter` keys, or a list of such mappings applied in series
  (:class:`.filters.FilterSeries`: a second notch for the second bending mode, a slosh notch); every row
  with the same number of filters;
* ``accel_gain`` (optional, every row or none) [rad/s of rate command per m/s^2 of lateral specific
  force]: the accelerometer channel (load relief, the drift channel);
* ``attitude_gain`` (optional, every row or none) [rad/s of rate command per rad of attitude error]:
  the attitude channel.

For example, two filters per row (a notch on the first bending mode, then one on the second) and an
attitude channel::

    variable: time
    interpolation: nearest
    rows:
    - time_s: 3.0
      kp: 0.42
      ki: 0.68
      kd: 0.016
      attitude_gain: 0.5
      filter:
      - {lead_zero_radps: 8.4, lead_pole_radps: 1400.0, lowpass_radps: 126.0, lowpass_damping: 0.41,
         notch_radps: 59.7, notch_damping: 0.51, notch_depth: 0.022}
      - {lowpass_radps: 5000.0, notch_radps: 140.0, notch_damping: 0.2, notch_depth: 0.1}

Linear interpolation reads every gain and every filter parameter (of each filter of the series) linearly
between the rows, holding the end rows beyond the table; ``nearest`` takes the nearest row (switching at
the midpoints between breakpoints).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.errors import ConfigError
from lvgym.vehicle.yamlfile import read_yaml

from .filecache import read_once
from .filters import FILTER_KEYS, Filter, FilterSeries, StructuralFilter, filter_count, filter_from_yaml

__all__ = ["GainSchedule", "INTERPOLATIONS", "ROW_COLUMNS", "SCHEDULES", "VARIABLES", "VARIABLE_KEYS"]

SCHEDULES = Path(__file__).resolve().parent / "schedules"
VARIABLES = ("mass", "time", "mach")
#: the row key of each scheduling variable's breakpoint
VARIABLE_KEYS = {"mass": "mass_kg", "time": "time_s", "mach": "mach"}
#: how a schedule reads between breakpoints: linearly, or the nearest row (switching at the midpoints)
INTERPOLATIONS = ("linear", "nearest")
#: a schedule's columns of one number per row (the filters' parameters are the other columns)
ROW_COLUMNS = ("kp", "ki", "kd", "n", "accel_gain", "attitude_gain")
#: the optional channels, their units and meaning (validated alike: finite, >= 0, one per row)
CHANNELS = {"accel_gain": "rad/s per m/s^2", "attitude_gain": "rad/s per rad"}


@dataclass(frozen=True)
class GainSchedule:
    """PID gains at breakpoints of a monotonic scheduling variable, interpolated linearly (ends held) or
    read at the nearest row (module docstring). ``filters``: per row one :class:`.filters.StructuralFilter`
    or one :class:`.filters.FilterSeries` (a tuple of filters is made one), the same number of filters in
    every row; ``accel_gain`` [rad/s per m/s^2] and ``attitude_gain`` [rad/s per rad]: the optional
    channels, one gain per row."""

    variable: str
    points: tuple[float, ...]
    kp: tuple[float, ...]
    ki: tuple[float, ...]
    kd: tuple[float, ...]
    n: tuple[float, ...]
    meta: dict = field(default_factory=dict, compare=False)
    filters: tuple[Filter, ...] | None = None
    interpolation: str = "linear"
    #: load-relief gain per row [rad/s per m/s^2] (None: no accelerometer feedback)
    accel_gain: tuple[float, ...] | None = None
    #: attitude gain per row [rad/s per rad] (None: no attitude feedback)
    attitude_gain: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.variable not in VARIABLES:
            raise ValueError(f"variable = {self.variable!r}: one of {VARIABLES}")
        m = len(self.points)
        for key in ("kp", "ki", "kd", "n"):
            if len(getattr(self, key)) != m:
                raise ValueError(f"{key} has {len(getattr(self, key))} entries for {m} breakpoints")
        if m < 1:
            raise ValueError("a schedule needs at least one breakpoint")
        d = np.diff(np.asarray(self.points, float))
        if not (np.all(d > 0) or np.all(d < 0)):
            raise ValueError(f"breakpoints of {self.variable!r} = {list(self.points)}: must be strictly "
                             "monotonic (a lookup table needs a monotonic scheduling variable, thesis 6.3.1)")
        for key in ("kp", "ki", "kd"):
            if any(not (math.isfinite(v) and v >= 0) for v in getattr(self, key)):
                raise ValueError(f"{key} = {list(getattr(self, key))}: finite gains >= 0")
        if any(not v > 0 for v in self.n):
            raise ValueError(f"n = {list(self.n)}: filter coefficients > 0")
        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation = {self.interpolation!r}: one of {INTERPOLATIONS}")
        if self.filters is not None:
            object.__setattr__(self, "filters", _filter_rows(self.filters, m))
        for key, unit in CHANNELS.items():
            v = getattr(self, key)
            if v is None:
                continue
            try:
                gains = tuple(float(g) for g in v if not isinstance(g, (bool, str)))
            except (TypeError, ValueError):
                gains = ()
            if len(gains) != m or len(v) != m or any(not (math.isfinite(g) and g >= 0) for g in gains):
                raise ConfigError(key, list(v) if isinstance(v, (list, tuple)) else v,
                                  f"{m} finite gains >= 0 [{unit}], one per row")
            object.__setattr__(self, key, gains)

    @property
    def filter_count(self) -> int:
        """How many structural filters each row holds in series (0: none)."""
        return 0 if self.filters is None else filter_count(self.filters[0])

    @cached_property
    def filter_keys(self) -> tuple[str, ...]:
        """The columns of the filters' parameters: :data:`.filters.FILTER_KEYS` for one filter per row,
        ``<key>#<j>`` for the filter ``j`` of a series."""
        if self.filters is None:
            return ()
        if isinstance(self.filters[0], StructuralFilter):
            return FILTER_KEYS
        return tuple(f"{k}#{j}" for j in range(self.filter_count) for k in FILTER_KEYS)

    def _filter_column(self, key: str) -> list[float]:
        name, _, j = key.partition("#")
        rows = self.filters if not j else [f[int(j)] for f in self.filters]
        return [getattr(f, name) for f in rows]

    @cached_property
    def _table(self) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        """Breakpoints, the same sorted ascending, and every column (gains, filter keys) in that order:
        built once, so a lookup is one ``argmin`` or one ``np.interp`` per column (the same numbers)."""
        x = np.asarray(self.points, float)
        order = np.argsort(x)
        cols = {k: np.asarray(getattr(self, k), float)[order] for k in ROW_COLUMNS if getattr(self, k) is not None}
        cols.update({k: np.array(self._filter_column(k), float)[order] for k in self.filter_keys})
        return x, x[order], cols

    def _nearest(self, value: float) -> int:
        """Index (in :attr:`points` order) of the breakpoint nearest ``value``."""
        return int(np.argmin(np.abs(self._table[0] - value)))

    def _lookup(self, value: float, keys: tuple[str, ...]) -> list[float]:
        x, x_sorted, cols = self._table
        if self.interpolation == "nearest":
            i = self._nearest(value)
            return [float(getattr(self, k)[i]) if k in ROW_COLUMNS else float(self._filter_column(k)[i]) for k in keys]
        return [float(np.interp(value, x_sorted, cols[k])) for k in keys]

    def filter_at(self, value: float) -> Filter | None:
        """The structural filtering at ``value`` (each parameter read as the gains are), or None; of the
        rows' type (one filter, or a series of as many)."""
        if self.filters is None:
            return None
        if self.interpolation == "nearest":
            return self.filters[self._nearest(value)]
        v = self._lookup(value, self.filter_keys)
        k = len(FILTER_KEYS)
        parts = [StructuralFilter(**dict(zip(FILTER_KEYS, v[j * k:(j + 1) * k]))) for j in range(len(v) // k)]
        return parts[0] if isinstance(self.filters[0], StructuralFilter) else FilterSeries(tuple(parts))

    def accel_gain_at(self, value: float) -> float:
        """The load-relief gain [rad/s per m/s^2] at ``value`` (0 without one)."""
        return 0.0 if self.accel_gain is None else self._lookup(value, ("accel_gain",))[0]

    def attitude_gain_at(self, value: float) -> float:
        """The attitude gain [rad/s per rad] at ``value`` (0 without one)."""
        return 0.0 if self.attitude_gain is None else self._lookup(value, ("attitude_gain",))[0]

    def gains(self, value: float) -> tuple[float, float, float, float]:
        """(kp, ki, kd, n) at ``value`` of the scheduling variable."""
        return tuple(self._lookup(value, ("kp", "ki", "kd", "n")))

    # ------------------------------------------------------------------ files
    @classmethod
    def from_dict(cls, data: dict) -> "GainSchedule":
        rows = data["rows"]
        var = data.get("variable", "mass")
        if var not in VARIABLE_KEYS:
            raise ConfigError("variable", var, f"one of {', '.join(VARIABLE_KEYS)}")
        key = VARIABLE_KEYS[var]
        get = lambda k, default=None: tuple(float(r.get(k, default)) for r in rows)  # noqa: E731
        meta = {k: v for k, v in data.items() if k not in ("rows", "variable", "interpolation")}
        meta["rows"] = rows
        with_filter = [("filter" in r) for r in rows]
        if any(with_filter) and not all(with_filter):
            raise ConfigError("filter", [i for i, f in enumerate(with_filter) if not f],
                              "rows without a 'filter': in every row or none")
        filters = tuple(filter_from_yaml(r["filter"], f"rows[{i}].filter") for i, r in enumerate(rows)) \
            if all(with_filter) and rows else None
        channels = {}
        for name in CHANNELS:
            present = [(name in r) for r in rows]
            if any(present) and not all(present):
                raise ConfigError(name, [i for i, f in enumerate(present) if not f],
                                  "rows without it: in every row or none")
            channels[name] = tuple(_number(r[name], f"rows[{i}].{name}") for i, r in enumerate(rows)) \
                if all(present) and rows else None
        return cls(var, get(key), get("kp"), get("ki"), get("kd"), get("n", math.inf), meta, filters,
                   data.get("interpolation", "linear"), channels["accel_gain"], channels["attitude_gain"])

    def to_dict(self) -> dict[str, Any]:
        """The YAML form (:meth:`from_dict` reads it back to an equal schedule): the metadata, the variable,
        the interpolation and the rows; a row keeps the other keys its source row had (margins, notes)."""
        src = self.meta.get("rows")
        src = src if isinstance(src, list) and len(src) == len(self.points) else [{}] * len(self.points)
        rows = []
        for i, x in enumerate(self.points):
            row = {k: v for k, v in src[i].items() if k not in (VARIABLE_KEYS[self.variable], *ROW_COLUMNS, "filter")}
            row = {VARIABLE_KEYS[self.variable]: float(x), **{k: float(getattr(self, k)[i]) for k in ("kp", "ki", "kd")},
                   **({} if math.isinf(self.n[i]) else {"n": float(self.n[i])}), **row}
            for name in CHANNELS:
                if getattr(self, name) is not None:
                    row[name] = float(getattr(self, name)[i])
            if self.filters is not None:
                row["filter"] = self.filters[i].as_dict()
            rows.append(row)
        meta = {k: v for k, v in self.meta.items() if k != "rows"}
        return {**meta, "variable": self.variable, "interpolation": self.interpolation, "rows": rows}

    def save(self, path: str | Path, title: str | None = None) -> Path:
        """Write :meth:`to_dict` as YAML to ``path`` (a ``# title`` line first when given); returns the path."""
        import yaml

        p = Path(path)
        head = f"# {title}\n" if title else ""
        p.write_text(head + yaml.safe_dump(self.to_dict(), sort_keys=False, default_flow_style=None, width=120),
                     encoding="utf-8")
        return p

    @classmethod
    def load(cls, path: str | Path) -> "GainSchedule":
        """A schedule from a YAML file (a path, or the name of one in ``baselines/schedules``)."""
        p = Path(path)
        if not p.exists():
            p = SCHEDULES / (str(path) if str(path).endswith(".yaml") else f"{path}.yaml")

        def read(q: Path) -> "GainSchedule":
            return cls.from_dict(read_yaml(q)[0])            # libyaml, duplicate keys refused, errors name the file

        return read_once(p, read, "GainSchedule")                  # parsed once per process


def _number(v: Any, key: str) -> float:
    """A row's number ``v`` (the YAML's ``key``), refused when not one."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ConfigError(key, v, "a number")
    return float(v)


def _filter_rows(filters: Any, m: int) -> tuple[Filter, ...]:
    """The rows' filters as a tuple of one filter per row or one series per row (a row given as a list or
    tuple of filters becomes a series; a single filter among series becomes a series of one), checked: one
    entry per row, the same number of filters in every row."""
    rows = [FilterSeries(tuple(f)) if isinstance(f, (list, tuple)) else f for f in filters]
    if len(rows) != m:
        raise ConfigError("filter", f"{len(rows)} rows", f"one entry per row ({m} breakpoints)")
    bad = [f for f in rows if not isinstance(f, (StructuralFilter, FilterSeries))]
    if bad:
        raise ConfigError("filter", bad[0], "a StructuralFilter or a FilterSeries per row")
    if any(isinstance(f, FilterSeries) for f in rows):
        rows = [FilterSeries((f,)) if isinstance(f, StructuralFilter) else f for f in rows]
    counts = [filter_count(f) for f in rows]
    if len(set(counts)) > 1:
        raise ConfigError("filter", counts, "the same number of filters in every row (filters per row as listed)")
    return tuple(rows)
