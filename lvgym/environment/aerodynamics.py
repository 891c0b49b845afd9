"""Aerodynamic coefficient tables and the aerodynamic force and moment (thesis section 3.2).

Two table models, chosen by name (``make("aerodynamics", ...)``; formats in docs/aerodynamics.md):
``axisymmetric``, the thesis's 3-DOF tables ``CA, CN, Cm`` over Mach and the total angle of attack
``alpha_t`` in [0, 180] deg, expanded to 6-DOF by axial symmetry (the normal force lies in the
crossflow plane, at roll orientation ``phi_a = atan2(v, w)``), and ``tables6``, full body-axis tables
``CA, CY, CN, Cl, Cm, Cn`` over Mach, alpha, beta and optionally altitude (Missile DATCOM style).
Both carry damping derivatives ``Cmq`` (the pitch-rate derivative; include ``Cmalpha_dot`` in it if you
have one: the Barrowman generator does not), ``Clp`` and, for ``tables6``, ``Cnr``
(per rad of ``omega L / (2 V)``; axisymmetric: ``Cnr = Cmq``), a reference area ``S`` [m^2], length
``L`` [m] and moment reference station ``x_ref`` [m] (x_b from the nose tip, <= 0).

With ``v_air_b = (u, v, w)`` the vehicle's velocity relative to the air, body axes, and
``qbar = rho V^2 / 2``: ``alpha = atan2(w, u)``, ``beta = atan2(v, sqrt(u^2 + w^2))``,
``alpha_t = atan2(sqrt(v^2 + w^2), u)``; ``f_b = qbar S (-CA, CY, -CN)`` (CA positive aft, CN
towards -z_b at positive alpha); moments ``qbar S L (Cl, Cm, Cn)`` about ``x_ref`` (Cm nose-up, a
stable vehicle has dCm/dalpha < 0), moved to the CG station: ``m_cg = m_ref + (x_ref - x_cg) e_x x
f_b``; damping ``rho V S L^2 / 4 (Clp p, Cmq q, Cnr r)``. ``axisymmetric`` tables give ``Cmq`` about
``x_ref`` and the kernel moves it to the CG with the table's own static slopes at its first non-zero angle
(``Cmq - 4 (D/L) Cm_alpha - 2 (D/L)^2 CN_alpha``, ``D = x_ref - x_cg``, strip theory); ``tables6``
damping derivatives are used as tabulated, so give them about the flight's mean CG. Axes are
clamped at the grid ends. Everything is zero, without NaN, at zero airspeed.

Compiled callers use :func:`aero_loads_k` with ``model.kernel_args()``, an ``AeroArrays(params, grid,
dims, table)``: ``params = [kind, S, L, x_ref]``; ``grid`` the axis vectors (Mach, angles in rad, altitude in m) end to
end; ``dims`` their lengths; ``table`` one row per grid point (C order), columns ``COLUMNS[kind]``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.errors import MISSING, ConfigError

from .aerokernels import (FLOW, KIND_AXISYMMETRIC, KIND_TABLES6, P_KIND, P_LREF, P_SREF, P_XREF,  # noqa: F401
                          AeroArrays, AeroAt, AirData, LoadsAt, TableAt, aero_loads_at, aero_loads_batch,
                          aero_loads_k, interp_at, interp_k)
from .registry import register

#: coefficient columns of the table of each kind, in kernel order
COLUMNS = {KIND_AXISYMMETRIC: ("CA", "CN", "Cm", "Cmq", "Clp"),
           KIND_TABLES6: ("CA", "CY", "CN", "Cl", "Cm", "Cn", "Clp", "Cmq", "Cnr")}
#: entries of the state vector written by the kernel (AeroState fields, same order)
STATE_FIELDS = FLOW.names
DAMPING = ("Cmq", "Clp", "Cnr")


# ------------------------------------------------------------------------------- CSV tables
def read_table_csv(path: str | Path, axes: tuple[str, ...], required: tuple[str, ...],
                   optional: tuple[str, ...] = (), optional_axes: tuple[str, ...] = ()
                   ) -> tuple[list[np.ndarray], dict[str, np.ndarray]]:
    """Read a coefficient table in long CSV format: a header line, then one row per grid point.

    Lines starting with ``#`` are comments. ``axes`` (e.g. ``mach, alpha_deg``) must form a full
    grid, every combination exactly once, in any row order; ``optional_axes`` may be absent.
    Returns the sorted axis vectors (as written, degrees stay degrees) and each coefficient column
    as an array of shape (len(axis_0), len(axis_1), ...). Raises ConfigError naming the file, the
    row and column, and the value for anything malformed.
    """
    src = str(path)
    try:
        with open(path, newline="") as fh:
            reader = csv.reader(fh)
            rows = [(reader.line_num, r) for r in reader if r and not r[0].lstrip().startswith("#")]
    except OSError as exc:
        raise ConfigError("table", src, f"a readable CSV file ({exc.strerror})") from None
    if not rows:
        raise ConfigError("header", MISSING, "a header line naming the columns", source=src)
    header = [h.strip() for h in rows[0][1]]
    allowed = axes + optional_axes + required + optional
    for name in header:
        if name not in allowed or header.count(name) > 1:
            raise ConfigError(f"column {name!r}", name, f"each once, one of {list(allowed)}", source=src)
    for name in axes + required:
        if name not in header:
            raise ConfigError(f"column {name!r}", MISSING, f"required; the file has {header}", source=src)
    data = np.empty((len(rows) - 1, len(header)))
    for n, (i, row) in enumerate(rows[1:]):
        if len(row) != len(header):
            raise ConfigError(f"line {i}", ",".join(row), f"{len(header)} values, one per column",
                              source=src)
        for j, raw in enumerate(row):
            try:
                data[n, j] = float(raw)
            except ValueError:
                data[n, j] = math.nan
            if not math.isfinite(data[n, j]):
                raise ConfigError(f"line {i}, column {header[j]!r}", raw.strip(), "a finite number",
                                  source=src)
    used_axes = [a for a in axes + optional_axes if a in header]
    grids = [np.unique(data[:, header.index(a)]) for a in used_axes]
    shape = tuple(len(g) for g in grids)
    index = tuple(np.searchsorted(g, data[:, header.index(a)]) for g, a in zip(grids, used_axes))
    flat = np.ravel_multi_index(index, shape) if shape else np.zeros(0, int)
    if len(data) != int(np.prod(shape)) or len(np.unique(flat)) != len(data):
        raise ConfigError("rows", len(data), f"a full grid: every combination of {shape} values of "
                          f"{used_axes} exactly once ({int(np.prod(shape))} rows)", source=src)
    columns = {}
    for name in required + optional:
        if name in header:
            col = np.empty(int(np.prod(shape)))
            col[flat] = data[:, header.index(name)]
            columns[name] = col.reshape(shape)
    return grids, columns


def _from_mapping(table: Mapping[str, Any], axes: tuple[str, ...], optional_axes: tuple[str, ...],
                  required: tuple[str, ...], optional: tuple[str, ...]
                  ) -> tuple[list[np.ndarray], dict[str, np.ndarray]]:
    """Grid vectors and coefficient arrays from a mapping (the in-memory form of a CSV table)."""
    for name in axes + required:
        if name not in table:
            raise ConfigError(f"table.{name}", MISSING, f"required; the mapping has {sorted(table)}")
    grids = [np.asarray(table[k], float).ravel() for k in axes + optional_axes if k in table]
    shape = tuple(len(g) for g in grids)
    columns = {k: np.asarray(table[k], float) for k in required + optional if k in table}
    for name, col in columns.items():
        if col.shape != shape:
            raise ConfigError(f"table.{name}", col.shape, f"an array over the grid, shape {shape}")
    return grids, columns


def _real(key: str, value: Any, ok: Any, allowed: str) -> float:
    """``float(value)`` if finite and ``ok(value)``, else ConfigError(key, value, allowed)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and ok(x)):
        raise ConfigError(key, value, allowed)
    return x


# ------------------------------------------------------------------------------- models
@dataclass(frozen=True)
class AeroState:
    """Flow angles and flight condition of the loads call (arrays, () or (B,)), for recording:
    ``alpha``, ``beta``, ``alpha_total``, ``phi_aero`` [rad], ``mach`` [-], ``qbar`` [Pa],
    ``airspeed`` [m/s]."""

    alpha: np.ndarray
    beta: np.ndarray
    alpha_total: np.ndarray
    phi_aero: np.ndarray
    mach: np.ndarray
    qbar: np.ndarray
    airspeed: np.ndarray


class AeroTables:
    """Common face of the table models: parameters for the kernel and the batched ``loads`` call.

    Attributes ``params`` (``[kind, S, L, x_ref]``), ``grid``, ``dims``, ``table`` are the flat
    arrays :func:`aero_loads_k` takes (see :meth:`kernel_args`); ``axes`` the grid vectors in SI.
    """

    kind: float
    axis_names: tuple[str, ...]

    def _setup(self, axes: list[np.ndarray], columns: Mapping[str, np.ndarray], ref_area: Any,
               ref_length: Any, x_ref: Any, source: str | None) -> None:
        s = _real("ref_area", ref_area, lambda x: x > 0.0, "a reference area [m^2] > 0")
        length = _real("ref_length", ref_length, lambda x: x > 0.0, "a reference length [m] > 0")
        xr = _real("x_ref", x_ref, lambda x: x <= 0.0, "a station [m] from the nose tip, <= 0")
        self.source = source
        self.axes = [np.ascontiguousarray(a, dtype=np.float64) for a in axes]
        self.ref_area, self.ref_length, self.x_ref = s, length, xr
        self.params = np.array([self.kind, s, length, xr])
        self.grid = np.concatenate(self.axes)
        self.dims = np.array([len(a) for a in self.axes], dtype=np.int64)
        shape = tuple(self.dims)
        table = np.zeros((int(np.prod(shape)), len(COLUMNS[self.kind])))
        for j, name in enumerate(COLUMNS[self.kind]):
            col = np.asarray(columns.get(name, 0.0), dtype=np.float64)
            table[:, j] = np.broadcast_to(col, shape).ravel()
        if not np.all(np.isfinite(table)):
            raise ConfigError("table", "non-finite coefficient", "finite numbers", source=source)
        self.table = table

    def kernel_args(self) -> AeroArrays:
        """The :data:`~.aerokernels.AeroArrays` ``(params, grid, dims, table)`` for :func:`aero_loads_k` /
        :func:`aero_loads_batch`."""
        return AeroArrays(self.params, self.grid, self.dims, self.table)

    def coefficients(self, *point: float) -> dict[str, float]:
        """Interpolated coefficients at one grid point ``(mach, angles [rad], ...)``."""
        out = np.zeros(self.table.shape[1])
        q = np.zeros(len(self.dims))
        q[:len(point)] = point
        interp_k(self.grid, self.dims, self.table, q, out)
        return dict(zip(COLUMNS[self.kind], out.tolist()))

    def loads(self, v_air_b: Any, omega_bi_b: Any, rho: Any, speed_of_sound: Any, x_cg: Any,
              altitude: Any = 0.0) -> tuple[np.ndarray, np.ndarray, AeroState]:
        """Aerodynamic force ``f_b`` [N] and moment about the CG ``m_b`` [N m], body frame.

        ``v_air_b`` [m/s] (3,) or (B, 3): vehicle velocity relative to the air, body axes;
        ``omega_bi_b`` [rad/s] like it; ``rho`` [kg/m^3], ``speed_of_sound`` [m/s], ``x_cg`` [m]
        (CG station) and ``altitude`` [m] scalars or (B,). Returns ``f_b``, ``m_b`` shaped like
        ``v_air_b`` and an :class:`AeroState`.
        """
        v = np.asarray(v_air_b, dtype=np.float64)
        b = 1 if v.ndim == 1 else v.shape[0]

        def rows(a: Any, width: int | None) -> np.ndarray:
            a = np.asarray(a, dtype=np.float64)
            shape = (b,) if width is None else (b, width)
            return np.ascontiguousarray(np.broadcast_to(a, shape))

        f, m, s = np.zeros((b, 3)), np.zeros((b, 3)), np.zeros((b, len(STATE_FIELDS)))
        aero_loads_batch(rows(v, 3), rows(omega_bi_b, 3), rows(rho, None), rows(speed_of_sound, None),
                         rows(x_cg, None), rows(altitude, None), self.kernel_args(), f, m, s)
        if v.ndim == 1:
            return f[0], m[0], AeroState(*[s[0, k] for k in range(s.shape[1])])
        return f, m, AeroState(*[s[:, k] for k in range(s.shape[1])])

    def __repr__(self) -> str:
        axes = ", ".join(f"{n}[{len(a)}]" for n, a in zip(self.axis_names, self.axes))
        return (f"{type(self).__name__}({axes}, S={self.ref_area:g} m2, L={self.ref_length:g} m, "
                f"x_ref={self.x_ref:g} m)")


def _damping(columns: dict[str, np.ndarray], options: dict[str, Any], source: str | None) -> None:
    for name, value in options.items():
        if value is None:
            continue
        if name in columns:
            raise ConfigError(name.lower(), value, f"given both as an option and as column {name!r} "
                              f"of the table; give it once", source=source)
        columns[name] = np.float64(_real(name.lower(), value, lambda x: True,
                                         "a finite number [1/rad] (damping is negative)"))


@register("aerodynamics", "axisymmetric")
class AxisymmetricAero(AeroTables):
    """3-DOF tables ``CA, CN, Cm`` (and optionally ``Cmq``, ``Clp``) over Mach and total angle of
    attack, expanded to 6-DOF by axial symmetry. Kernel :func:`aero_loads_k`, kind 0.

    Parameters
    ----------
    table:
        CSV file (columns ``mach, alpha_deg, CA, CN, Cm`` and optionally ``Cmq, Clp``; ``alpha_deg``
        is the total angle of attack from 0 to at most 180 deg) or a mapping with the grid vectors
        ``mach`` and ``alpha_deg`` and arrays of shape (n_mach, n_alpha) per coefficient.
    ref_area, ref_length:
        Reference area [m^2] and length [m] of the coefficients.
    x_ref:
        Moment reference station of ``Cm`` [m], <= 0.
    cmq, clp:
        Constant pitch (Cmq + Cmalpha_dot) and roll damping derivatives [1/rad], if the table has
        no such column.
    """

    kind = KIND_AXISYMMETRIC
    axis_names = ("mach", "alpha_total")

    def __init__(self, table: str | Path | Mapping[str, Any], ref_area: float, ref_length: float,
                 x_ref: float = 0.0, cmq: float | None = None, clp: float | None = None) -> None:
        cols = COLUMNS[self.kind]
        if isinstance(table, Mapping):
            source = None
            grids, columns = _from_mapping(table, ("mach", "alpha_deg"), (), cols[:3], cols[3:])
        else:
            source = str(table)
            grids, columns = read_table_csv(table, ("mach", "alpha_deg"), cols[:3], cols[3:])
        mach, alpha_deg = grids
        if mach[0] < 0.0 or np.any(np.diff(mach) <= 0):
            raise ConfigError("column 'mach'", float(mach[0]), "increasing Mach numbers >= 0",
                              source=source)
        if alpha_deg[0] != 0.0 or alpha_deg[-1] > 180.0 or np.any(np.diff(alpha_deg) <= 0):
            raise ConfigError("column 'alpha_deg'", [float(alpha_deg[0]), float(alpha_deg[-1])],
                              "increasing total angles of attack from exactly 0 to at most 180 deg",
                              source=source)
        for name in ("CN", "Cm"):
            bad = np.abs(columns[name][:, 0]) > 1e-9
            if np.any(bad):
                raise ConfigError(f"column {name!r} at alpha_deg = 0", float(columns[name][bad, 0][0]),
                                  "0: an axisymmetric vehicle has no normal force or pitching "
                                  "moment at zero total angle of attack", source=source)
        _damping(columns, {"Cmq": cmq, "Clp": clp}, source)
        self._setup([mach, np.radians(alpha_deg)], columns, ref_area, ref_length, x_ref, source)

    def to_csv(self, path: str | Path, comment: str = "") -> None:
        """Write the tables in the CSV format this class reads (``alpha_deg`` in degrees)."""
        mach, alpha = self.axes
        with open(path, "w", newline="") as fh:
            for line in comment.splitlines():
                fh.write(f"# {line}\n")
            out = csv.writer(fh, lineterminator="\n")
            out.writerow(("mach", "alpha_deg") + COLUMNS[self.kind])
            for i, row in enumerate(self.table):
                out.writerow([f"{mach[i // len(alpha)]:.6g}", f"{math.degrees(alpha[i % len(alpha)]):.6g}"]
                             + [f"{x:.8g}" for x in row])

    def to_tables6(self, alpha_deg: Any, beta_deg: Any) -> Tables6Aero:
        """The same aerodynamics as full 6-DOF tables on the given alpha and beta grids [deg]."""
        a, b = np.meshgrid(np.radians(alpha_deg), np.radians(beta_deg), indexing="ij")
        u, v, w = np.cos(a) * np.cos(b), np.sin(b), np.sin(a) * np.cos(b)
        alpha_t, phi = np.arctan2(np.hypot(v, w), u), np.arctan2(v, w)
        sp, cp = np.sin(phi), np.cos(phi)
        c = np.array([[list(self.coefficients(m, t).values()) for t in alpha_t.ravel()]
                      for m in self.axes[0]]).reshape((len(self.axes[0]),) + a.shape + (5,))
        cols = {"CA": c[..., 0], "CY": -c[..., 1] * sp, "CN": c[..., 1] * cp, "Cm": c[..., 2] * cp,
                "Cn": -c[..., 2] * sp, "Cl": 0.0 * c[..., 0], "Cmq": c[..., 3], "Cnr": c[..., 3],
                "Clp": c[..., 4]}
        table = {"mach": self.axes[0], "alpha_deg": np.asarray(alpha_deg, float),
                 "beta_deg": np.asarray(beta_deg, float)} | cols
        return Tables6Aero(table, self.ref_area, self.ref_length, self.x_ref)


@register("aerodynamics", "tables6")
class Tables6Aero(AeroTables):
    """Full 6-DOF body-axis tables over Mach, alpha, beta and optionally altitude. Kernel
    :func:`aero_loads_k`, kind 1 (an absent altitude axis is one point: no dependence).

    ``table`` is a CSV file with columns ``mach, alpha_deg, beta_deg`` (optionally ``alt_m``),
    ``CA, CY, CN, Cl, Cm, Cn`` and optionally ``Clp, Cmq, Cnr``, or a mapping with the grid vectors
    (``mach``, ``alpha_deg``, ``beta_deg``, optionally ``alt_m``) and arrays over that grid.
    ``alpha_deg`` within [-180, 180], ``beta_deg`` within [-90, 90]. Other parameters as
    :class:`AxisymmetricAero`, plus the constant yaw damping ``cnr`` [1/rad].
    """

    kind = KIND_TABLES6
    axis_names = ("mach", "alpha", "beta", "altitude")

    def __init__(self, table: str | Path | Mapping[str, Any], ref_area: float, ref_length: float,
                 x_ref: float = 0.0, cmq: float | None = None, clp: float | None = None,
                 cnr: float | None = None) -> None:
        cols = COLUMNS[self.kind]
        names = ("mach", "alpha_deg", "beta_deg")
        if isinstance(table, Mapping):
            source = None
            grids, columns = _from_mapping(table, names, ("alt_m",), cols[:6], cols[6:])
        else:
            source = str(table)
            grids, columns = read_table_csv(table, names, cols[:6], cols[6:], ("alt_m",))
        if len(grids) == 3:
            grids.append(np.zeros(1))
            columns = {k: c[..., None] for k, c in columns.items()}
        limits = {"mach": (0.0, math.inf), "alpha_deg": (-180.0, 180.0), "beta_deg": (-90.0, 90.0),
                  "alt_m": (-math.inf, math.inf)}
        for name, g in zip(names + ("alt_m",), grids):
            lo, hi = limits[name]
            if g[0] < lo or g[-1] > hi or np.any(np.diff(g) <= 0):
                raise ConfigError(f"column {name!r}", [float(g[0]), float(g[-1])],
                                  f"increasing values within [{lo}, {hi}]", source=source)
        _damping(columns, {"Cmq": cmq, "Clp": clp, "Cnr": cnr}, source)
        axes = [grids[0], np.radians(grids[1]), np.radians(grids[2]), grids[3]]
        self._setup(axes, columns, ref_area, ref_length, x_ref, source)
