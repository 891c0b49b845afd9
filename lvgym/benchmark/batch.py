"""The batched policy interface: one object acts for many rows (episodes) of a batched env.

A :class:`~.policy.Policy` may have ``batch(n) -> BatchPolicy``: the same policy for ``n`` independent rows,
stepped together. A :class:`BatchPolicy` has ``name``, ``reset(rows)`` (the rows ``rows`` start an episode)
and ``act(rows, observations, info) -> actions``: ``rows`` an int array, ``observations`` (len(rows),
n_obs), ``info`` the batched env's info dict of all ``n`` rows (arrays with a leading axis ``n``; the policy
reads ``info[key][rows]``; right after a reset it is the reset's info); the actions are (len(rows), n_a).
Row ``b``'s actions are the bits a policy object of its own gives, fed row ``b``'s observation and the
single env's info of that row (so the benchmark's records do not depend on how the rows are batched).

A policy without ``batch`` flies through :class:`RowPolicies`: one policy object per row, built by its
factory, each fed its row's observation and :func:`row_info`, in its own Python call (a user's policy keeps
working unchanged; a batch only saves the calls).

>>> import numpy as np
>>> from lvgym.benchmark.policy import ZeroPolicy
>>> rows = as_batch(ZeroPolicy(), 3)
>>> rows.reset(np.arange(3))
>>> rows.act(np.array([0, 2]), np.zeros((2, 14), np.float32), {"time": np.zeros(3)})
array([[0., 0.],
       [0., 0.]], dtype=float32)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np

from lvgym.envs.core import row_info as _row_info

from .policy import Policy

__all__ = ["BatchPolicy", "RowPolicies", "as_batch", "row_info"]


def row_info(info: dict[str, Any], b: int) -> dict[str, Any]:
    """Row ``b`` of a batched env's info dict, exactly as the single env gives it (numbers as Python
    scalars, the reward terms as a dict of floats, the events as a list)."""
    return _row_info(info, int(b))


@runtime_checkable
class BatchPolicy(Protocol):
    """``reset(rows)`` when the rows ``rows`` start an episode, then ``act(rows, observations, info) ->
    actions`` at every control step of those rows (the module docstring). ``name`` labels the policy."""

    name: str

    def reset(self, rows: np.ndarray) -> None: ...

    def act(self, rows: np.ndarray, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray: ...


class RowPolicies:
    """A policy without ``batch`` behind the batched interface: one policy object per row, the first
    ``first`` and the others built by ``make()`` (the policy's factory) when their row first flies; each
    acts in its own Python call on its row's observation and :func:`row_info`."""

    def __init__(self, first: Policy, n: int, make: Callable[[], Policy] | None = None) -> None:
        self.name = first.name
        self.n = int(n)
        self._make = make
        self.policies: list[Policy | None] = [first] + [None] * (self.n - 1)

    def _policy(self, b: int) -> Policy:
        p = self.policies[b]
        if p is None:
            if self._make is None:
                raise ValueError(f"policy {self.name!r}: {self.n} rows need a factory to build a policy per row")
            p = self.policies[b] = self._make()
        return p

    def reset(self, rows: Any) -> None:
        for b in np.asarray(rows, dtype=np.int64).reshape(-1):
            self._policy(int(b)).reset()

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.asarray(observations)
        return np.asarray([np.asarray(self._policy(b).act(obs[j], row_info(info, b)))
                           for j, b in enumerate(rows.tolist())])


def as_batch(policy: Policy, n: int, make: Callable[[], Policy] | None = None) -> BatchPolicy:
    """``policy`` for ``n`` rows: its own ``batch(n)``, else :class:`RowPolicies` (``policy`` for the first
    row, ``make()`` builds the others)."""
    batch = getattr(policy, "batch", None)
    return batch(int(n)) if callable(batch) else RowPolicies(policy, n, make)
