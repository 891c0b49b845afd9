"""Aerodynamic derivatives from a data sheet: rows over flight time of the nominal Mach number, the
normal-force slope, the centre of pressure and the axial force (``model: data_sheet``).

A launcher known by its published tables gives, over the flight's time, ``CN_alpha`` [1/rad], the centre of
pressure ``x_cp`` and ``CA`` along its nominal trajectory, with that trajectory's Mach number. The
coefficients are functions of the Mach number (and the angle of attack), not of the time: on a dispersed
flight the Mach number at a given time differs (docs/vehicles.md, schema gap 8), so each row is placed at its
Mach number and the model is an :class:`~.aerodynamics.AxisymmetricAero` table over Mach and the total angle
of attack ``alpha_t``, built from the rows:

* ``CN(M, alpha_t) = CN_alpha(M) sin(alpha_t)`` (``CN_alpha alpha_t`` at small angles; the sheet says nothing
  of large angles, and this extension keeps the force normal to the body and bounded);
* ``Cm(M, alpha_t) = CN(M, alpha_t) (x_cp(M) - x_ref) / L`` about ``x_ref`` (the normal force acting at the
  centre of pressure; ``x_cp`` aft of ``x_ref`` gives a restoring moment);
* ``CA(M, alpha_t) = CA(M)``; ``Cmq`` and ``Clp`` constants (``cmq``, ``clp``; zero when not given).

The rows are sorted by Mach number (linear between them, held beyond, as the kernel clamps its axes); two
rows at one Mach number are refused. ``table``: the rows inline, ``[[t s, mach, CN_alpha 1/rad, x_cp m, CA],
...]``, or a CSV file with the header ``t,mach,CN_alpha,x_cp,CA`` (a relative path from a vehicle file is
relative to that file's folder). The time column is checked (non-negative, increasing) and documents the
sheet; it does not enter the model. No strip distribution: ``aeroelastic`` is refused with this model, as
with the other tables.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.errors import ConfigError

from .aerodynamics import AxisymmetricAero
from .registry import register

__all__ = ["ALPHA_DEG", "COLUMNS", "DataSheetAero", "read_sheet"]

#: the columns of a data sheet's row, in order
COLUMNS = ("t", "mach", "CN_alpha", "x_cp", "CA")
#: the total angles of attack of the table [deg]: dense where a flight is, to 180
ALPHA_DEG = (0.0, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 150.0, 180.0)
_RANGES = {"t": (0.0, 1e5), "mach": (0.0, 50.0), "CN_alpha": (0.0, 100.0), "x_cp": (-1000.0, 0.0), "CA": (-5.0, 5.0)}


def read_sheet(table: str | Path | Sequence[Sequence[float]]) -> tuple[np.ndarray, str]:
    """The sheet's rows (n, 5) in :data:`COLUMNS` order and where they came from (the CSV path, or
    ``table`` for inline rows), every value checked: a ConfigError names the row, the column, the value and
    what is allowed."""
    if isinstance(table, (str, Path)):
        source = str(table)
        try:
            with open(table, newline="") as fh:
                lines = [r for r in csv.reader(line for line in fh if line.strip() and not line.startswith("#"))]
        except OSError as exc:
            raise ConfigError("table", source, f"a readable CSV file ({exc.strerror})") from None
        if not lines or tuple(c.strip() for c in lines[0]) != COLUMNS:
            raise ConfigError("table", source, f"a CSV file whose header is {','.join(COLUMNS)}")
        rows: list[Any] = lines[1:]
        where = [f"table {source}, line {k + 2}" for k in range(len(rows))]
    else:
        source, rows = "table", list(table) if isinstance(table, (list, tuple)) else []
        where = [f"table[{k}]" for k in range(len(rows))]
    if len(rows) < 2:
        raise ConfigError("table", source if isinstance(table, (str, Path)) else table,
                          f"at least 2 rows of [{', '.join(COLUMNS)}]")
    out = np.zeros((len(rows), len(COLUMNS)))
    for k, row in enumerate(rows):
        if not isinstance(row, (list, tuple)) or len(row) != len(COLUMNS):
            raise ConfigError(where[k], row, f"{len(COLUMNS)} numbers: {', '.join(COLUMNS)}")
        for j, name in enumerate(COLUMNS):
            lo, hi = _RANGES[name]
            try:
                value = float(row[j])
            except (TypeError, ValueError):
                value = math.nan
            if not (lo <= value <= hi) or (name == "CN_alpha" and value == 0.0):
                span = f"({lo:g}, {hi:g}] 1/rad" if name == "CN_alpha" else f"[{lo:g}, {hi:g}]"
                raise ConfigError(f"{where[k]}: {name}", row[j], f"a number in {span}")
            out[k, j] = value
    bad = np.flatnonzero(np.diff(out[:, 0]) <= 0.0)
    if bad.size:
        raise ConfigError(f"{where[bad[0] + 1]}: t", float(out[bad[0] + 1, 0]), "times increasing from row to row")
    by_mach = np.sort(out[:, 1])
    same = np.flatnonzero(np.diff(by_mach) <= 0.0)
    if same.size:
        raise ConfigError("table: mach", float(by_mach[same[0]]), "one row per Mach number (the coefficients "
                          "are functions of the Mach number: two rows at one Mach number would contradict)")
    return out, source


@register("aerodynamics", "data_sheet")
class DataSheetAero(AxisymmetricAero):
    """A data sheet's derivatives over flight time as an axisymmetric table over Mach (module docstring).

    ``table``: the rows or a CSV file; ``ref_area`` [m^2] and ``ref_length`` [m] the coefficients'
    references; ``x_ref`` [m] the moment reference station (<= 0; the nose tip by default); ``cmq``,
    ``clp`` constant damping derivatives [1/rad] (default 0)."""

    def __init__(self, table: str | Path | Sequence[Sequence[float]], ref_area: float, ref_length: float,
                 x_ref: float = 0.0, cmq: float | None = None, clp: float | None = None) -> None:
        rows, source = read_sheet(table)
        self.sheet = rows[np.argsort(rows[:, 1])]
        mach, cn_alpha, x_cp, ca = (self.sheet[:, j] for j in range(1, 5))
        alpha = np.radians(np.asarray(ALPHA_DEG))
        cn = cn_alpha[:, None] * np.sin(alpha)[None, :]
        refs_ok = all(isinstance(v, (int, float)) and math.isfinite(v) for v in (ref_length, x_ref)) and ref_length > 0
        # (bad references are refused by the table's own checks below, naming the key)
        cm = cn * ((x_cp - x_ref) / ref_length)[:, None] if refs_ok else np.zeros_like(cn)
        grid = {"mach": mach, "alpha_deg": np.asarray(ALPHA_DEG), "CA": np.repeat(ca[:, None], len(ALPHA_DEG), 1),
                "CN": cn, "Cm": cm}
        super().__init__(grid, ref_area, ref_length, x_ref, 0.0 if cmq is None else cmq, 0.0 if clp is None else clp)
        self.source = source
