"""The batched policy interface of the classical controllers, and its fallback.

A policy may have ``batch(n) -> BatchPolicy``: the same controller for ``n`` independent rows (episodes)
of a batched env, stepped together. A BatchPolicy has ``name``, ``reset(rows)`` (the rows ``rows`` start
an episode) and ``act(rows, observations, info) -> actions``: ``rows`` an int array, ``observations``
(len(rows), n_obs), ``info`` the batched env's info dict of all ``n`` rows (arrays with a leading axis n;
the policy reads ``info[key][rows]``; right after a reset it is the reset's info: ``time``,
``cumulative_rate_error``, ``mass``, ``controller_on``); the actions are (len(rows), 2) float32. Row ``b``'s
actions are the bits a policy object of its own gives, fed row ``b``'s observation and info.

The PID family, AAC and LQG run compiled kernels over all rows (:mod:`.pidbatch`, :mod:`.aacbatch`,
:mod:`.lqg`). A configuration the kernels do not know (a subclass that changes the law, an AAC on another
base) flies as :class:`RowCopies`: one copy of the policy per row, each in its own Python call.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

__all__ = ["RowCopies", "row_info"]


def row_info(info: dict[str, Any], b: int) -> dict[str, Any]:
    """Row ``b`` of a batched info dict as the single env's info (numbers as Python scalars)."""
    out: dict[str, Any] = {}
    for key, value in info.items():
        if isinstance(value, dict):
            out[key] = {k: _scalar(v[b]) for k, v in value.items()}
        elif key == "events":
            out[key] = list(value[b])
        else:
            out[key] = _scalar(value[b])
    return out


def _scalar(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


class RowCopies:
    """``n`` copies of ``policy`` (deep copies, one per row) behind the batched interface (the module
    docstring): each row's copy acts in its own Python call on its observation and :func:`row_info`."""

    def __init__(self, policy: Any, n: int) -> None:
        self.name = policy.name
        self.policies = [copy.deepcopy(policy) for _ in range(int(n))]

    def reset(self, rows: Any) -> None:
        for b in np.asarray(rows, dtype=np.int64).reshape(-1):
            self.policies[b].reset()

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.asarray(observations).reshape(rows.size, -1)
        out = np.empty((rows.size, 2), np.float32)
        for j, b in enumerate(rows):
            out[j] = self.policies[b].act(obs[j], row_info(info, int(b)))
        return out
