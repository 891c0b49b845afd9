"""The structural q-alpha limit a task flies with: the vehicle file's own (constant or over the flight,
:mod:`lvgym.vehicle.limits`) or the option ``qalpha_limit_pa_deg``, and its entries in the task parameters
(layout :data:`.layouts.TASK`; the signals kernel reads them with :func:`.signals.qalpha_limit_k`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from lvgym.errors import ConfigError
from lvgym.vehicle.limits import MAX_ROWS, OVER, QAlphaLimit

from .options import LimitOptions

__all__ = ["qalpha_task_entries", "resolve_qalpha_limit"]


def resolve_qalpha_limit(spec: Any, vehicle: Any) -> QAlphaLimit:
    """The limit of ``spec``'s task on ``vehicle``: the vehicle file's ``qalpha_limit`` when it gives one, else
    the option ``qalpha_limit_pa_deg``. Both set is refused: which one would hold?"""
    own = getattr(vehicle, "qalpha_limit", None)
    if own is None:
        return QAlphaLimit.constant(spec.qalpha_limit_pa_deg)
    default = LimitOptions().qalpha_limit_pa_deg
    if spec.qalpha_limit_pa_deg != default:
        raise ConfigError("qalpha_limit_pa_deg", spec.qalpha_limit_pa_deg,
                          f"its default ({default:g}) when the vehicle file gives its own qalpha_limit "
                          f"({vehicle.source}); change the file's, or drop it to set the option")
    return own


def qalpha_task_entries(limit: QAlphaLimit) -> dict[str, Any]:
    """The TASK entries of ``limit``: ``qalpha_limit`` (the constant, or the table's first limit),
    ``qalpha_over`` (0 constant, 1 over Mach, 2 over time), ``qalpha_n`` and the table ``qalpha_x``,
    ``qalpha_y`` (padded with zeros to :data:`~lvgym.vehicle.limits.MAX_ROWS`)."""
    xs, ys = np.zeros(MAX_ROWS), np.zeros(MAX_ROWS)
    n = len(limit.table)
    xs[:n], ys[:n] = np.array(limit.table).T
    over = 0.0 if limit.is_constant else 1.0 + OVER.index(limit.over)
    return {"qalpha_limit": limit.table[0][1], "qalpha_over": over, "qalpha_n": float(n), "qalpha_x": xs,
            "qalpha_y": ys}
