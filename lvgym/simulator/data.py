"""The simulator's state as data: every row's arrays in one :class:`SimData` value.

A :class:`~.core.Simulator` holds the constants of a flight (the vehicle, its timeline, the
environment models, the rail, the servo); everything that changes during an episode lives in a
``SimData``, a namedtuple of arrays with one row per vehicle of the batch, which the compiled step
receives as one argument. Copying the rows of a ``SimData`` (:func:`take`) and writing them back
(:func:`put`) captures and restores the simulator exactly.

==============  ================  =====================================================================
field           shape             meaning
==============  ================  =====================================================================
``t``           (B,)              time of each row [s]
``x``           (B, n_x)          dynamics state (:data:`lvgym.dynamics.layout.STATE`)
``p``           (B, n_p)          dynamics parameters in force (:data:`lvgym.dynamics.layout.PARAMS`)
``ctx``         (B, n_ctx)        context (:data:`.layouts.CONTEXT` header, then the models' blocks)
``scale``       (B, n_p)          dispersions: a row flies ``timeline params * scale + offset``
``offset``      (B, n_p)
``x_cg0``       (B,)              CG station at the start [m] (the rail constraint's reference)
``failed``      (B,) bool         the state turned non-finite; the row is no longer integrated
``rail_state``  (B, n_rail)       motion on the pad and rail (:data:`.layouts.RAIL_STATE`)
``actuator``    (B, n_act)        command, gimbal, gimbal rate, effort (:data:`.layouts.ACTUATOR`)
``conditions``  (B, n_cond)       flight conditions at ``t`` (:data:`.layouts.CONDITIONS`)
``imu``         (B, n_imu)        IMU filter states (:data:`.layouts.IMU_STATE`; zero without an IMU)
==============  ================  =====================================================================
"""

from __future__ import annotations

from collections import namedtuple
from typing import Any

import numpy as np

from .layouts import ACTUATOR, CONDITIONS, IMU_STATE, RAIL_STATE

__all__ = ["SimData", "allocate", "put", "take", "widen"]

SimData = namedtuple("SimData", ["t", "x", "p", "ctx", "scale", "offset", "x_cg0", "failed", "rail_state", "actuator",
                                 "conditions", "imu"])


def allocate(batch: int, n_x: int, n_p: int, n_ctx: int = 0) -> SimData:
    """Zeroed rows (``failed`` False, ``scale`` 1) of a batch of ``batch`` vehicles."""
    B = int(batch)
    return SimData(t=np.zeros(B), x=np.zeros((B, n_x)), p=np.zeros((B, n_p)), ctx=np.zeros((B, n_ctx)),
                   scale=np.ones((B, n_p)), offset=np.zeros((B, n_p)), x_cg0=np.zeros(B),
                   failed=np.zeros(B, dtype=bool), rail_state=RAIL_STATE.zeros(B), actuator=ACTUATOR.zeros(B),
                   conditions=CONDITIONS.zeros(B), imu=IMU_STATE.zeros(B))


def widen(data: SimData, n_ctx: int) -> SimData:
    """``data`` with a context at least ``n_ctx`` wide (zero-padded at the end; the same value when it is)."""
    have = data.ctx.shape[1]
    if n_ctx <= have:
        return data
    ctx = np.zeros((data.ctx.shape[0], n_ctx))
    ctx[:, :have] = data.ctx
    return data._replace(ctx=ctx)


def take(data: SimData, rows: Any = None) -> SimData:
    """A copy of the rows ``rows`` (default: all) of ``data``."""
    if rows is None:
        return SimData(*(a.copy() for a in data))
    rows = np.atleast_1d(np.asarray(rows, dtype=np.int64))
    return SimData(*(a[rows].copy() for a in data))


def put(data: SimData, rows: Any, src: SimData) -> SimData:
    """Write the rows of ``src`` into the rows ``rows`` of ``data`` (in place; the context is widened
    first when ``src``'s is wider, so the returned value may be a new ``SimData`` sharing the other
    arrays). Rows of ``src`` narrower than ``data`` are zero-padded."""
    rows = np.atleast_1d(np.asarray(rows, dtype=np.int64))
    if len(src.t) != rows.size:
        raise ValueError(f"{len(src.t)} rows of data for {rows.size} rows")
    for name in SimData._fields:
        a, b = getattr(data, name), getattr(src, name)
        if name != "ctx" and a.shape[1:] != b.shape[1:]:
            raise ValueError(f"SimData.{name}: rows of shape {b.shape[1:]} for a simulator of {a.shape[1:]} "
                             "(a state of another vehicle or model?)")
    data = widen(data, src.ctx.shape[1])
    for name in SimData._fields:
        a, b = getattr(data, name), getattr(src, name)
        if name == "ctx":
            a[rows] = 0.0
            a[rows, :b.shape[1]] = b
        else:
            a[rows] = b
    return data
