"""Structural filters of a TVC loop: a lead-lag, a second-order low-pass and a notch, in series, each
designed in continuous time and discretised at the control rate by the bilinear (Tustin) transform,
prewarped at its own characteristic frequency (so the discrete notch and low-pass sit exactly at their
design frequencies).

The sections, all of unit gain at zero frequency (so they do not change the loop's low-frequency gain
and a filter started in steady state passes a constant through unchanged):

* lead-lag ``(s / w_z + 1) / (s / w_p + 1)`` (``lead_zero_radps``, ``lead_pole_radps``; equal: off);
* low-pass ``w_l^2 / (s^2 + 2 z_l w_l s + w_l^2)`` (``lowpass_radps``, ``lowpass_damping``);
* notch ``(s^2 + 2 r z_n w_n s + w_n^2) / (s^2 + 2 z_n w_n s + w_n^2)`` (``notch_radps``, width
  ``notch_damping`` z_n, ``notch_depth`` r = the gain at ``w_n``; 1: off).

:class:`StructuralFilter` holds the parameters (frozen, validated); the PID family's compiled law runs
the discrete filter sample by sample (direct form II transposed per section, :mod:`.pidkernel`), with
coefficients that may change between samples (a scheduled filter); :meth:`StructuralFilter.tf` is the same
discrete filter as a python-control transfer function, for the linear design and the tests.

:class:`FilterSeries` is several structural filters in series (a second notch for the second bending
mode, a slosh notch, ...): the same interface (:meth:`~FilterSeries.continuous`,
:meth:`~FilterSeries.discrete`, :meth:`~FilterSeries.tf`), its sections those of its filters in order,
so the law runs either. In a gain schedule's YAML a row's ``filter`` is one mapping (a
:class:`StructuralFilter`) or a list of mappings (a :class:`FilterSeries`, applied first to last):
:func:`filter_from_yaml`, :func:`filter_to_yaml`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from lvgym.errors import ConfigError, require

__all__ = ["StructuralFilter", "FilterSeries", "FILTER_KEYS", "Filter", "filter_count",
           "filter_from_yaml", "filter_to_yaml"]


@dataclass(frozen=True)
class StructuralFilter:
    """Continuous parameters of the filter chain [rad/s and -]; the defaults are all sections off
    except a low-pass at 150 rad/s (about the Nyquist frequency of 50 Hz control)."""

    lead_zero_radps: float = 10.0
    lead_pole_radps: float = 10.0
    lowpass_radps: float = 150.0
    lowpass_damping: float = 0.7
    notch_radps: float = 70.0
    notch_damping: float = 0.3
    notch_depth: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"{f.name} = {v!r}: a finite number > 0")
        if not self.lowpass_damping <= 2.0 or not self.notch_damping <= 2.0:
            raise ValueError(f"lowpass_damping = {self.lowpass_damping!r}, notch_damping = {self.notch_damping!r}: "
                             "dampings in (0, 2]")
        if not self.notch_depth <= 1.0:
            raise ValueError(f"notch_depth = {self.notch_depth!r}: the notch's gain at its centre, in (0, 1]")

    @classmethod
    def from_dict(cls, data: dict) -> "StructuralFilter":
        unknown = set(data) - set(FILTER_KEYS)
        if unknown:
            raise ValueError(f"filter keys {sorted(unknown)}: allowed are {list(FILTER_KEYS)}")
        return cls(**{k: float(v) for k, v in data.items()})

    def as_dict(self) -> dict[str, float]:
        return {k: float(getattr(self, k)) for k in FILTER_KEYS}

    def continuous(self) -> list[tuple[list[float], list[float], float]]:
        """The sections as (numerator, denominator, prewarp frequency [rad/s]) in ``s``."""
        wz, wp = self.lead_zero_radps, self.lead_pole_radps
        wl, zl = self.lowpass_radps, self.lowpass_damping
        wn, zn, r = self.notch_radps, self.notch_damping, self.notch_depth
        return [([1.0 / wz, 1.0], [1.0 / wp, 1.0], math.sqrt(wz * wp)),
                ([wl * wl], [1.0, 2.0 * zl * wl, wl * wl], wl),
                ([1.0, 2.0 * r * zn * wn, wn * wn], [1.0, 2.0 * zn * wn, wn * wn], wn)]

    def discrete(self, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """The sections in ``z`` at the sampling period ``dt`` [s] (Tustin, prewarped), each as
        (b, a) of length 3 with ``a[0] = 1`` (a first-order section ``(b0 z + b1) / (z + a1)`` as
        ``(b0, b1, 0), (1, a1, 0)``). A prewarp frequency at or above the Nyquist frequency is clamped
        just below it."""
        out = []
        for b, a, w0 in self.continuous():
            w0 = min(w0, 0.95 * math.pi / dt)
            k = w0 / math.tan(0.5 * w0 * dt)             # s = k (z - 1) / (z + 1)
            n = max(len(b), len(a))                      # both at the section's degree
            b, a = [0.0] * (n - len(b)) + list(b), [0.0] * (n - len(a)) + list(a)
            bz, az = _bilinear(b, k), _bilinear(a, k)
            out.append((bz / az[0], az / az[0]))
        return out

    def tf(self, dt: float) -> Any:
        """The discrete filter chain as a python-control transfer function at ``dt`` [s] (a design tool's
        view: needs python-control, ``pip install 'lvgym[control]'``; flying the filter does not)."""
        return _sections_tf(self.discrete(dt), dt, "StructuralFilter.tf")


FILTER_KEYS = tuple(f.name for f in fields(StructuralFilter))


@dataclass(frozen=True)
class FilterSeries:
    """Structural filters applied in series, first to last (``filters``: one or more
    :class:`StructuralFilter`); its sections are its filters' sections in that order, so it has their
    interface and the PID law runs it. Each filter has unit gain at zero frequency, so the series
    does too."""

    filters: tuple[StructuralFilter, ...]

    def __post_init__(self) -> None:
        fs = tuple(self.filters) if isinstance(self.filters, (list, tuple)) else self.filters
        if not isinstance(fs, tuple) or not fs or not all(isinstance(f, StructuralFilter) for f in fs):
            raise ConfigError("filter", self.filters, "one or more structural filters in series")
        object.__setattr__(self, "filters", fs)

    def __len__(self) -> int:
        return len(self.filters)

    def __iter__(self):
        return iter(self.filters)

    def __getitem__(self, i: int) -> StructuralFilter:
        return self.filters[i]

    @classmethod
    def from_dict(cls, data: list, key: str = "filter") -> "FilterSeries":
        """From a list of filter mappings (:meth:`StructuralFilter.from_dict` each; ``key``: the list's name
        in an error)."""
        if not isinstance(data, (list, tuple)) or not data:
            raise ConfigError(key, data, "a non-empty list of filter mappings (keys: "
                              f"{', '.join(FILTER_KEYS)})")
        if any(isinstance(d, (list, tuple)) for d in data):
            raise ConfigError(key, data, "a list of filter mappings (a flat list, no list in it)")
        return cls(tuple(filter_from_yaml(d, f"{key}[{i}]") for i, d in enumerate(data)))

    def as_dict(self) -> list[dict[str, float]]:
        """The YAML form: a list of the filters' mappings."""
        return [f.as_dict() for f in self.filters]

    def continuous(self) -> list[tuple[list[float], list[float], float]]:
        """Every filter's sections in ``s``, in series order (:meth:`StructuralFilter.continuous`)."""
        return [sec for f in self.filters for sec in f.continuous()]

    def discrete(self, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """Every filter's sections in ``z`` at ``dt`` [s], in series order (:meth:`StructuralFilter.discrete`)."""
        return [sec for f in self.filters for sec in f.discrete(dt)]

    def tf(self, dt: float) -> Any:
        """The series as a python-control transfer function at ``dt`` [s]: the product of the filters'."""
        return _sections_tf(self.discrete(dt), dt, "FilterSeries.tf")


#: a row's structural filtering: one filter or several in series
Filter = StructuralFilter | FilterSeries


def filter_count(filt: Filter | None) -> int:
    """How many structural filters ``filt`` holds in series (0 for None)."""
    return 0 if filt is None else len(filt) if isinstance(filt, FilterSeries) else 1


def filter_from_yaml(data: Any, key: str = "filter") -> Filter:
    """A schedule row's ``filter`` entry: a mapping gives a :class:`StructuralFilter`, a list of mappings a
    :class:`FilterSeries` (``key``: the entry's name in an error)."""
    if isinstance(data, (list, tuple)):
        return FilterSeries.from_dict(list(data), key)
    if not isinstance(data, dict):
        raise ConfigError(key, data, f"a filter mapping (keys: {', '.join(FILTER_KEYS)}) or a list of them")
    unknown = sorted(set(data) - set(FILTER_KEYS))
    if unknown:
        raise ConfigError(f"{key}.{unknown[0]}", data[unknown[0]],
                          f"not a filter key; allowed: {', '.join(FILTER_KEYS)}")
    try:
        return StructuralFilter.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise ConfigError(key, data, f"a valid structural filter ({exc})") from None


def filter_to_yaml(filt: Filter) -> dict[str, float] | list[dict[str, float]]:
    """The YAML form of ``filt``: a mapping for one filter, a list of mappings for a series."""
    return filt.as_dict()


def _sections_tf(sections: list[tuple[np.ndarray, np.ndarray]], dt: float, feature: str) -> Any:
    """The product of the discrete ``sections`` as a python-control transfer function at ``dt`` [s]."""
    require("control", "control", feature)
    import control

    g = control.tf([1.0], [1.0], dt)
    for b, a in sections:
        g = g * control.tf(b, a, dt)
    return g


def _bilinear(c: list[float], k: float) -> np.ndarray:
    """A polynomial in ``s`` of degree 1 or 2 with ``s = k (z - 1) / (z + 1)``, times ``(z + 1)^degree``:
    its coefficients in ``z`` (padded to length 3)."""
    if len(c) == 2:
        c0, c1 = c
        return np.array([c0 * k + c1, c1 - c0 * k, 0.0])
    c0, c1, c2 = c
    kk = k * k
    return np.array([c0 * kk + c1 * k + c2, 2.0 * (c2 - c0 * kk), c0 * kk - c1 * k + c2])
