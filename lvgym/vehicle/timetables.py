"""Tables over flight time that replace what lvgym computes from the geometry (the vehicle file's ``tables``),
for a vehicle known by its published design data rather than by its parts.

::

    tables:
      mass_properties: kestrel_mass.csv      # or inline rows [t s, mass kg, cg station m, Ixx, Iyy(, Izz) kg m^2]
      modes:                                 # one entry per bending mode, the first mode first
        - table: [[0, 11.0, 0.01], [60, 12.5, 0.01], [118, 16.0, 0.02]]   # [t s, frequency Hz, damping ratio]
        - table: kestrel_mode2.csv           # columns t, hz, zeta (then slope_gimbal, then slope_imu)
          imu_station: -3.0                  # [m] where slope_imu is (required with that column)

``mass_properties`` replaces the rigid-equivalent stack's mass, CG station and inertia at every row of the
timeline (Izz = Iyy when the column is left out; the CG on the axis, the inertia diagonal); with slosh
pendulums, the rigid body B is the table's stack minus the pendulums at rest (:func:`~.massmodel.body_minus_pendulums`),
so the totals are the table's. Each ``modes`` entry replaces the beam's frequency [Hz] and damping ratio of
that mode; the mode shape stays the beam's, scaled as a whole (one factor per mode and row, at the gimbal,
the slosh hinges, the sensors and the aeroelastic strips alike) to the ``slope_gimbal`` column when it is
given [1/(m sqrt(kg)), mass-normalised: a slope sigma per unit generalised mass M_k is sigma / sqrt(M_k)].
A ``slope_imu`` column [1/(m sqrt(kg))] at ``imu_station`` [m] then scales what the sensors read of that
mode (the shapes at every sensor station, by the ratio at ``imu_station``), so the gimbal-to-gyro gain of the
mode is the table's ``slope_gimbal * slope_imu`` while the dynamics keep one shape.

Rows are linear between them and held beyond the first and the last. Times are non-decreasing; a time given
twice is a jump (the row before the event, then the row after it), allowed only within
:data:`JUMP_SNAP_S` of a separation or the fairing jettison, and moved onto that event's time. The mass never
increases, and its drop between rows (jumps aside) must be what the engines burn by their mass flow within
:data:`FLOW_RTOL` of the propellant burnt over the table plus :data:`FLOW_ATOL_SHARE` of the first mass
(:func:`~.checks.check_tables`). A CSV file has a header line naming the columns (``#`` lines are comments), its
path relative to the vehicle file's folder. Every bad value names the file, the line, the key path, the value
and what is allowed.
"""

from __future__ import annotations

import csv
import hashlib
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.errors import ConfigError

from .reader import Reader

__all__ = ["FLOW_ATOL_SHARE", "FLOW_RTOL", "JUMP_SNAP_S", "MASS_COLUMNS", "MODE_COLUMNS", "TimeTable",
           "VehicleTables", "before_rows", "file_digests", "read_tables", "snap_jumps", "stack_at", "tables_beside"]

#: the columns of ``mass_properties``, the last optional (Izz = Iyy)
MASS_COLUMNS = ("t", "mass", "cg", "Ixx", "Iyy", "Izz")
#: the columns of a ``modes`` entry, the last two optional (``slope_imu`` only after ``slope_gimbal``)
MODE_COLUMNS = ("t", "hz", "zeta", "slope_gimbal", "slope_imu")
#: the share of the propellant the engines burn over the table's span by which its mass drop may differ
FLOW_RTOL = 0.02
#: and the share of the table's first mass on top (published masses are rounded) [-]
FLOW_ATOL_SHARE = 1e-3
#: how far [s] a jump may lie from the separation or jettison it is moved onto
JUMP_SNAP_S = 1.0
MAX_TIME = 1e5             # [s]
MAX_STACK_MASS = 1e8       # [kg]
MAX_INERTIA = 1e13         # [kg m^2]
MAX_LENGTH = 1000.0        # [m]
MAX_HZ = 1000.0            # [Hz]
MAX_SLOPE = 1e3            # [1/(m sqrt(kg))]


@dataclass(frozen=True)
class TimeTable:
    """Rows over flight time: ``t`` (n,) [s] non-decreasing (a time twice: a jump), ``values`` (n, m) in the
    units of ``columns`` (without ``t``); ``key`` its key path in the vehicle file, ``source`` the file its
    rows came from (the vehicle file or a CSV) and ``lines`` the line of each row there (None: inline);
    ``imu_station`` [m] the station of a mode table's ``slope_imu`` column (None without it)."""

    key: str
    columns: tuple[str, ...]
    t: np.ndarray
    values: np.ndarray
    source: str | None = None
    lines: tuple[int, ...] | None = None
    imu_station: float | None = None

    @property
    def jumps(self) -> np.ndarray:
        """The times [s] given twice."""
        return self.t[:-1][np.diff(self.t) == 0.0]

    def at(self, t: Any, before: Any = False) -> np.ndarray:
        """The rows (B, m) at the times ``t`` (B,) [s]: linear between the rows, held beyond; at a jump the
        row after it, or the row before it where ``before`` (B,) is true."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        before = np.broadcast_to(np.asarray(before, dtype=bool), t.shape)
        n = self.t.size
        i = np.where(before, np.searchsorted(self.t, t, side="left"), np.searchsorted(self.t, t, side="right")) - 1
        i = np.clip(i, 0, n - 2)
        span = self.t[i + 1] - self.t[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(span > 0.0, (t - self.t[i]) / np.where(span > 0.0, span, 1.0), 1.0)
        w = np.clip(w, 0.0, 1.0)[:, None]
        return (1.0 - w) * self.values[i] + w * self.values[i + 1]

    def column(self, name: str, t: Any, before: Any = False) -> np.ndarray:
        """The column ``name`` at the times ``t`` (:meth:`at`)."""
        return self.at(t, before)[:, self.columns.index(name) - 1]

    def error(self, row: int, allowed: str) -> ConfigError:
        """A :class:`ConfigError` naming row ``row`` (its line in a CSV file), its numbers and ``allowed``."""
        value = [float(self.t[row]), *self.values[row].tolist()]
        return ConfigError(f"{self.key}[{row}]", value, allowed, self.source,
                           None if self.lines is None else self.lines[row])


@dataclass(frozen=True)
class VehicleTables:
    """The vehicle file's ``tables``: ``mass_properties`` (columns :data:`MASS_COLUMNS`, Izz filled in) or None,
    ``modes`` one table per bending mode from the first (columns :data:`MODE_COLUMNS`, with or without the
    slopes)."""

    mass_properties: TimeTable | None = None
    modes: tuple[TimeTable, ...] = ()


# ---------------------------------------------------------------------------- reading
def tables_beside(data: Any, folder: Path) -> list[str]:
    """Resolve, in place, the relative CSV paths of the parsed vehicle file ``data``'s ``tables`` against
    ``folder`` (the YAML file's); the paths of its table files (absolute ones as given)."""
    tables = data.get("tables") if isinstance(data, dict) else None
    if not isinstance(tables, dict):
        return []
    nodes = [(tables, "mass_properties")]
    modes = tables.get("modes")
    nodes += [(m, "table") for m in (modes if isinstance(modes, list) else []) if isinstance(m, dict)]
    files = []
    for node, name in nodes:
        value = node.get(name)
        if isinstance(value, str) and value:
            node[name] = value if Path(value).is_absolute() else str(folder / value)
            files.append(node[name])
    return files


def file_digests(files: list[str]) -> tuple[tuple[str, bytes | None], ...]:
    """``(path, digest of its bytes or None when unreadable)`` of each file: a vehicle read before is read
    again when one of its table files changed."""
    out = []
    for f in files:
        try:
            out.append((f, hashlib.blake2b(Path(f).read_bytes(), digest_size=16).digest()))
        except OSError:
            out.append((f, None))
    return tuple(out)


def read_tables(r: Reader) -> VehicleTables | None:
    """The vehicle file's ``tables`` (module docstring), None when absent."""
    sub = r.child("tables", None)
    if sub is None:
        return None
    mass = None
    if sub.raw("mass_properties", None) is not None:
        mass = _read_table(sub, "mass_properties", MASS_COLUMNS, 5)
        if mass.values.shape[1] == 4:                         # Izz = Iyy
            mass = replace(mass, columns=MASS_COLUMNS, values=np.column_stack([mass.values, mass.values[:, 3]]))
        _check_mass(mass)
    modes = []
    for i, mr in enumerate(sub.children("modes", [])):
        table = _read_table(mr, "table", MODE_COLUMNS, 3)
        imu = mr.number("imu_station", None, lo=-MAX_LENGTH, hi=0.0)
        if (imu is None) != (table.values.shape[1] < 4):
            raise mr.error("imu_station", imu, "a station [m] <= 0 with a slope_imu column (the fifth), and "
                           "only with it")
        table = replace(table, imu_station=imu)
        _check_modes(table, i)
        modes.append(table)
        mr.done()
    sub.done()
    return VehicleTables(mass, tuple(modes))


def _read_table(r: Reader, name: str, columns: tuple[str, ...], least: int) -> TimeTable:
    """Rows of the first ``least`` or more of ``columns`` inline or from a CSV file (its path relative to
    the vehicle file's folder, :func:`lvgym.vehicle.config.load_vehicle` resolves it), times checked."""
    value = r.raw(name)
    key = r.key(name)
    widths = range(least, len(columns) + 1)
    shape = f"rows [{', '.join(columns[:least])}" + "".join(f"(, {c}" for c in columns[least:]) \
        + ")" * (len(columns) - least) + "]"
    if isinstance(value, str):
        table = _read_csv(key, value, columns, least, r.source)
    elif isinstance(value, list) and value:
        rows = []
        for k, row in enumerate(value):
            ok = isinstance(row, list) and len(row) in widths and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in row)
            if not ok or (rows and len(row) != len(rows[0])):
                raise ConfigError(f"{key}[{k}]", row, f"{shape}: finite numbers, every row as wide as the first",
                                  r.source)
            rows.append([float(x) for x in row])
        a = np.array(rows)
        table = TimeTable(key, columns[:a.shape[1]], a[:, 0].copy(), a[:, 1:].copy(), r.source)
    else:
        raise ConfigError(key, value, f"{shape} inline, or the path of a CSV file of those columns", r.source)
    _check_times(table)
    return table


def _read_csv(key: str, path_text: str, columns: tuple[str, ...], least: int, vehicle_source: str | None
              ) -> TimeTable:
    """A table from the CSV file ``path_text``: a header naming the first ``least`` or more of ``columns``,
    then one row of finite numbers per line."""
    path = Path(path_text)
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            lines = [(n, row) for n, row in enumerate(csv.reader(fh), 1)
                     if row and "".join(row).strip() and not row[0].lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        why = "there is no such file" if isinstance(exc, FileNotFoundError) else str(exc)
        raise ConfigError(key, path_text, f"an existing, readable CSV file (relative to the vehicle file's folder; "
                          f"{why})", vehicle_source) from None
    src = path.name
    if not lines:
        raise ConfigError(key, path_text, f"a header line naming the columns {list(columns)}", src)
    header = [h.strip() for h in lines[0][1]]
    if header not in [list(columns[:n]) for n in range(least, len(columns) + 1)]:
        raise ConfigError(f"{key} header", header, f"the columns {list(columns[:least])}, then (optional, in order) "
                          f"{list(columns[least:])}", src, lines[0][0])
    data = np.empty((len(lines) - 1, len(header)))
    for k, (n, row) in enumerate(lines[1:]):
        try:
            numbers = [float(x) for x in row]
        except ValueError:
            numbers = [math.nan]
        if len(numbers) != len(header) or not all(math.isfinite(x) for x in numbers):
            raise ConfigError(f"{key}[{k}]", ",".join(row), f"{len(header)} finite numbers, one per column {header}",
                              src, n)
        data[k] = numbers
    return TimeTable(key, tuple(header), data[:, 0].copy(), data[:, 1:].copy(), src,
                     tuple(n for n, _ in lines[1:]))


def _check_times(table: TimeTable) -> None:
    """Two rows or more; times in [0, MAX_TIME], non-decreasing, a time at most twice and not at the ends."""
    t = table.t
    if t.size < 2:
        raise ConfigError(table.key, t.size, "at least two rows", table.source,
                          None if table.lines is None else table.lines[0])
    for k in range(t.size):
        if not 0.0 <= t[k] <= MAX_TIME:
            raise table.error(k, f"a time in [0, {MAX_TIME:g}] s first")
        if k and t[k] < t[k - 1]:
            raise table.error(k, f"times non-decreasing: {t[k]:g} s comes after {t[k - 1]:g} s")
        if k > 1 and t[k] == t[k - 2]:
            raise table.error(k, f"a time at most twice (a jump: the row before, then the row after); "
                              f"{t[k]:g} s is given three times")
    if t[1] == t[0] or t[-1] == t[-2]:
        row = 1 if t[1] == t[0] else t.size - 1
        raise table.error(row, "a jump (a time twice) between two other rows, not at the first or last time")


def _check_mass(table: TimeTable) -> None:
    v = table.values
    for k in range(v.shape[0]):
        mass, cg, J = v[k, 0], v[k, 1], v[k, 2:]
        if not 0.0 < mass <= MAX_STACK_MASS:
            raise table.error(k, f"a mass in (0, {MAX_STACK_MASS:g}] kg (second column)")
        if not -MAX_LENGTH <= cg <= 0.0:
            raise table.error(k, f"a CG station in [{-MAX_LENGTH:g}, 0] m, aft of the nose tip (third column)")
        if not np.all((J > 0.0) & (J <= MAX_INERTIA)):
            raise table.error(k, f"moments of inertia Ixx, Iyy, Izz in (0, {MAX_INERTIA:g}] kg m^2")
        if np.any(J > J.sum() - J + 1e-6 * J.max()):
            raise table.error(k, "moments of inertia a body can have: each at most the sum of the other two")
        if k and mass > v[k - 1, 0]:
            raise table.error(k, f"a mass that never increases: {mass:g} kg after {v[k - 1, 0]:g} kg")


def _check_modes(table: TimeTable, i: int) -> None:
    v = table.values
    for k in range(v.shape[0]):
        if not 0.0 < v[k, 0] <= MAX_HZ:
            raise table.error(k, f"mode {i + 1}'s frequency in (0, {MAX_HZ:g}] Hz (second column)")
        if not 0.0 <= v[k, 1] <= 1.0:
            raise table.error(k, "a damping ratio in [0, 1] (third column)")
        for j, where in ((2, "the gimbal"), (3, "the IMU")):
            if v.shape[1] > j and not (v[k, j] != 0.0 and abs(v[k, j]) <= MAX_SLOPE):
                raise table.error(k, f"a mass-normalised slope at {where}, non-zero, at most {MAX_SLOPE:g} in size "
                                  f"[1/(m sqrt(kg))] ({'fourth' if j == 2 else 'fifth'} column)")


def snap_jumps(table: TimeTable, events: list[float]) -> TimeTable:
    """``table`` with each jump moved onto the separation or jettison time in ``events`` [s] within
    :data:`JUMP_SNAP_S` of it (a :class:`ConfigError` when there is none, or the move would pass a row)."""
    t = table.t.copy()
    for k in np.flatnonzero(np.diff(table.t) == 0.0):
        near = [e for e in events if abs(e - t[k]) <= JUMP_SNAP_S]
        if not near:
            listed = ", ".join(f"{e:.3f}" for e in events) or "none"
            raise table.error(int(k), f"a jump (a time twice) within {JUMP_SNAP_S:g} s of a separation or the fairing "
                              f"jettison (the vehicle's: {listed} s)")
        e = min(near, key=lambda x: abs(x - t[k]))
        if not t[k - 1] < e < t[k + 2]:
            raise table.error(int(k), f"a jump that moves onto the event at {e:.4f} s without passing a row")
        t[k] = t[k + 1] = e
    return replace(table, t=t)


# ---------------------------------------------------------------------------- applied
def before_rows(t: np.ndarray) -> np.ndarray:
    """Which rows of the timeline times ``t`` (n,) [s] are the row before an event (the time repeats next)."""
    t = np.asarray(t, dtype=float)
    return np.append(t[:-1] == t[1:], False)


def stack_at(mass: TimeTable, t: Any, before: Any = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The table's stack at the times ``t`` (B,) [s]: mass (B,) [kg], CG (B, 3) [m] on the axis and
    inertia (B, 3, 3) [kg m^2] about it, diagonal."""
    v = mass.at(t, before)
    cg = np.zeros((v.shape[0], 3))
    cg[:, 0] = v[:, 1]
    J = np.zeros((v.shape[0], 3, 3))
    J[:, 0, 0], J[:, 1, 1], J[:, 2, 2] = v[:, 2], v[:, 3], v[:, 4]
    return v[:, 0].copy(), cg, J
