"""A vehicle's structural q-alpha limit, constant or a table over the flight (the vehicle file's
``qalpha_limit``).

The limit of dynamic pressure times total angle of attack [Pa deg] is the load a launcher's structure is
designed for, and it is seldom one number: a programme's load envelope falls where the fairing or an
interstage is weakest in its flight and rises where the structure is stronger or the loads are carried
otherwise. In a vehicle file it is either a number or a table over the Mach number or the flight time::

    qalpha_limit: 200000                                  # [Pa deg], the whole flight

    qalpha_limit:
      over: mach                                          # or: time [s]
      table: [[0.0, 300000], [1.2, 180000], [3.0, 250000]]  # [x, limit in Pa deg] rows, x strictly increasing

linear between the rows and held beyond the first and the last (2 to :data:`MAX_ROWS` rows). A vehicle that
gives one replaces the env's ``qalpha_limit_pa_deg`` (docs/vehicles.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .reader import Reader

__all__ = ["MAX_ROWS", "QAlphaLimit", "read_qalpha_limit"]

#: the most rows a limit table may have (the env carries them in its task parameters)
MAX_ROWS = 8
#: what a table may run over
OVER = ("mach", "time")
#: the largest limit a file may give [Pa deg]
MAX_LIMIT = 1e9


@dataclass(frozen=True)
class QAlphaLimit:
    """A q-alpha limit over the flight: ``over`` (``"mach"``, or ``"time"`` [s]) and ``table``, rows of
    (x, limit [Pa deg]) with x strictly increasing; a constant limit has ``over="mach"`` and one row."""

    over: str
    table: tuple[tuple[float, float], ...]

    @classmethod
    def constant(cls, limit_pa_deg: float) -> QAlphaLimit:
        """The same limit [Pa deg] over the whole flight."""
        return cls("mach", ((0.0, float(limit_pa_deg)),))

    @property
    def is_constant(self) -> bool:
        return len(self.table) == 1

    def at(self, mach: Any, time_s: Any) -> np.ndarray:
        """The limit [Pa deg] at the Mach number(s) ``mach`` and flight time(s) ``time_s`` [s]."""
        x = np.asarray(mach if self.over == "mach" else time_s, dtype=float)
        xs, ys = np.array(self.table).T
        return np.interp(x, xs, ys)


def read_qalpha_limit(r: Reader, name: str = "qalpha_limit") -> QAlphaLimit | None:
    """The vehicle file's ``name``: a number [Pa deg] or a mapping ``{over, table}`` (module docstring); None
    when absent. A bad value names the file, the key path, the value and what is allowed."""
    value = r.raw(name, None)
    if value is None:
        return None
    if not isinstance(value, dict):
        return QAlphaLimit.constant(r.number(name, lo=0.0, hi=MAX_LIMIT, lo_open=True))
    sub = r.child(name)
    over = sub.text("over", choices=OVER)
    rows = sub.table("table")
    if rows.shape[0] > MAX_ROWS:
        raise sub.error("table", sub.data["table"], f"2 to {MAX_ROWS} rows of [{over}, limit in Pa deg]")
    if np.any(rows[:, 1] <= 0.0) or np.any(rows[:, 1] > MAX_LIMIT):
        raise sub.error("table", sub.data["table"], f"limits in (0, {MAX_LIMIT:g}] Pa deg")
    if np.any(rows[:, 0] < 0.0):
        raise sub.error("table", sub.data["table"], f"{over} from 0 on")
    sub.done()
    return QAlphaLimit(over, tuple((float(a), float(b)) for a, b in rows))
