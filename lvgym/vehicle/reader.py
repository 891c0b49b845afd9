"""Checked reading of nested YAML mappings: every error names the file, the key path, the value and the rule.

:class:`Reader` wraps one mapping at a key path. Its typed getters (``number``, ``text``, ``vector3``,
``inertia``, ``table``, ``child``, ``children``) remember which keys were read; :meth:`Reader.done`
then rejects every key that was not, so a typo (``fill_raito``) is an error instead of a silently
ignored option. A missing required key next to a near spelling of it, or an unknown key near an allowed
one, says which (``did you mean 'fill_ratio'?``, by :mod:`difflib`).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from lvgym.errors import MISSING, ConfigError

REQUIRED = MISSING
#: the largest distance of a station from the nose tip [m]
STATION_LIMIT = 1000.0


class Reader:
    """Typed access to one mapping of a configuration file.

    Parameters
    ----------
    data:
        The mapping (from ``yaml.safe_load``).
    path:
        Key path of this mapping, e.g. ``"stages[0].tanks[1]"`` (``""`` at the top).
    source:
        File name shown in errors.
    """

    def __init__(self, data: Any, path: str = "", source: str | None = None):
        if not isinstance(data, Mapping):
            raise ConfigError(path or "<top>", data, "must be a mapping of keys to values", source)
        self.data = data
        self.path = path
        self.source = source
        self._used: set[str] = set()

    # -- plumbing -------------------------------------------------------------------------------
    def key(self, name: str) -> str:
        """Full key path of ``name`` in this mapping."""
        return f"{self.path}.{name}" if self.path else name

    def error(self, name: str, value: Any, allowed: str) -> ConfigError:
        """A :class:`ConfigError` for key ``name`` of this mapping."""
        return ConfigError(self.key(name), value, allowed, self.source)

    def raw(self, name: str, default: Any = REQUIRED) -> Any:
        """The value of ``name`` unchecked; ``default`` if absent (an error if required)."""
        self._used.add(name)
        value = self.data.get(name)
        if value is None:
            if default is REQUIRED:
                near = difflib.get_close_matches(name, [str(k) for k in self.data if k != name], n=1, cutoff=0.7)
                hint = f" (the mapping has {near[0]!r}: did you mean {name!r}?)" if near else ""
                raise self.error(name, MISSING, f"required{hint}")
            return default
        return value

    def done(self) -> None:
        """Reject every key that no getter read."""
        keys = {str(k): k for k in self.data}
        unknown = sorted(set(keys) - self._used)
        if unknown:
            allowed = ", ".join(sorted(self._used)) or "no keys"
            near = difflib.get_close_matches(unknown[0], sorted(self._used), n=1, cutoff=0.7)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise self.error(unknown[0], self.data[keys[unknown[0]]], f"unknown key; allowed here: {allowed}{hint}")

    # -- typed getters --------------------------------------------------------------------------
    def number(self, name: str, default: Any = REQUIRED, *, lo: float | None = None,
               hi: float | None = None, lo_open: bool = False, hi_open: bool = False) -> float:
        """A finite real number in ``[lo, hi]`` (``(lo, ...`` with ``lo_open``)."""
        value = self.raw(name, default)
        if value is None:
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.error(name, value, "must be a finite number")
        value = float(value)
        low_bad = lo is not None and (value <= lo if lo_open else value < lo)
        high_bad = hi is not None and (value >= hi if hi_open else value > hi)
        if low_bad or high_bad:
            left = "(" if lo_open else "["
            right = ")" if hi_open else "]"
            lo_s = "-inf" if lo is None else f"{lo:g}"
            hi_s = "inf" if hi is None else f"{hi:g}"
            raise self.error(name, value, f"must be in {left}{lo_s}, {hi_s}{right}")
        return value

    def integer(self, name: str, default: Any = REQUIRED, *, lo: int | None = None, hi: int | None = None) -> int:
        """An integer in ``[lo, hi]``."""
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(name, value, "must be an integer")
        if lo is not None and value < lo:
            raise self.error(name, value, f"must be an integer >= {lo}" if hi is None else
                             f"must be an integer in [{lo}, {hi}]")
        if hi is not None and value > hi:
            raise self.error(name, value, f"must be an integer <= {hi}" if lo is None else
                             f"must be an integer in [{lo}, {hi}]")
        return value

    def flag(self, name: str, default: Any = REQUIRED) -> bool:
        """``true`` or ``false``."""
        value = self.raw(name, default)
        if not isinstance(value, bool):
            raise self.error(name, value, "must be true or false")
        return value

    def text(self, name: str, default: Any = REQUIRED, *, choices: Sequence[str] | None = None) -> str:
        """A string, optionally one of ``choices``."""
        value = self.raw(name, default)
        if value is None:
            return value
        if not isinstance(value, str) or not value:
            raise self.error(name, value, "must be a non-empty string")
        if choices is not None and value not in choices:
            raise self.error(name, value, f"must be one of {list(choices)}")
        return value

    def station(self, name: str, default: Any = REQUIRED) -> np.ndarray:
        """A point in body axes from the nose tip [m]: a station ``x`` (on the axis) or ``[x, y, z]``;
        ``x`` must be zero or negative."""
        value = self.raw(name, default)
        if value is None:
            return value
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            value = [value, 0.0, 0.0]
        vec = self._floats(name, value, 3)
        if vec[0] > 0.0:
            raise self.error(name, value, "stations are measured aft of the nose tip: x must be <= 0")
        if vec[0] < -STATION_LIMIT or np.any(np.abs(vec[1:]) > STATION_LIMIT):
            raise self.error(name, value, f"coordinates within {STATION_LIMIT:g} m of the nose tip")
        return vec

    def inertia(self, name: str, default: Any = REQUIRED) -> np.ndarray:
        """An inertia tensor about the part's own CG [kg m^2]: ``[Ixx, Iyy, Izz]`` or a 3x3 matrix;
        symmetric and positive semi-definite."""
        value = self.raw(name, default)
        if value is None:
            return value
        flat = self._floats(name, value, None)
        if flat.size == 3:                       # diagonal: symmetric, its moments the diagonal sorted
            J = np.diag(flat)
            moments = np.sort(flat)
        elif flat.size == 9:
            J = flat.reshape(3, 3)
            if not np.allclose(J, J.T, rtol=0.0, atol=1e-9 * max(1.0, np.abs(J).max())):
                raise self.error(name, value, "must be symmetric")
            moments = np.linalg.eigvalsh(J)
        else:
            raise self.error(name, value, "must be [Ixx, Iyy, Izz] or a 3x3 matrix")
        tol = 1e-9 * max(1.0, np.abs(J).max())
        if moments.min() < -tol:
            raise self.error(name, value, "must be positive semi-definite (no negative moments of inertia)")
        if moments[0] + moments[1] < moments[2] - max(tol, 1e-6 * moments[2]):
            raise self.error(name, value, "principal moments that a body can have: each at most the sum of the "
                             f"other two (these are {', '.join(f'{m:g}' for m in moments)})")
        return J

    def table(self, name: str, default: Any = REQUIRED, *, columns: int = 2,
              increasing_first: bool = True) -> np.ndarray:
        """Rows of ``columns`` numbers; the first column strictly increasing."""
        value = self.raw(name, default)
        if value is None:
            return value
        rows = self._floats(name, value, None)
        if rows.size == 0 or rows.size % columns:
            raise self.error(name, value, f"must be a list of [{', '.join(['x'] * columns)}] rows")
        rows = rows.reshape(-1, columns)
        if rows.shape[0] < 2:
            raise self.error(name, value, "needs at least two rows")
        if increasing_first and np.any(np.diff(rows[:, 0]) <= 0.0):
            bad = int(np.argmax(np.diff(rows[:, 0]) <= 0.0)) + 1
            raise self.error(f"{name}[{bad}]", value[bad],
                             "the first column (time) must be strictly increasing")
        return rows

    def pair(self, name: str, default: Any = REQUIRED, *, lo: float | None = None,
             hi: float | None = None) -> tuple[float, float]:
        """``[a, b]`` with ``lo <= a <= b <= hi``."""
        value = self.raw(name, default)
        vec = self._floats(name, value, 2)
        if vec[0] > vec[1] or (lo is not None and vec[0] < lo) or (hi is not None and vec[1] > hi):
            raise self.error(name, value, f"must be [low, high] with {lo} <= low <= high <= {hi}")
        return float(vec[0]), float(vec[1])

    def child(self, name: str, default: Any = REQUIRED) -> Reader | None:
        """The nested mapping ``name`` as a reader (``None`` if optional and absent)."""
        value = self.raw(name, default)
        if value is None:
            return None
        return Reader(value, self.key(name), self.source)

    def children(self, name: str, default: Any = REQUIRED) -> list[Reader]:
        """The list of mappings ``name`` as readers."""
        value = self.raw(name, default)
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.error(name, value, "must be a list")
        return [Reader(item, f"{self.key(name)}[{i}]", self.source) for i, item in enumerate(value)]

    def _floats(self, name: str, value: Any, size: int | None) -> np.ndarray:
        try:
            arr = np.asarray(value, dtype=float).ravel()
        except (TypeError, ValueError):
            raise self.error(name, value, "must be numbers") from None
        if not np.all(np.isfinite(arr)):
            raise self.error(name, value, "must be finite numbers")
        if size is not None and arr.size != size:
            raise self.error(name, value, f"must have {size} numbers")
        return arr
