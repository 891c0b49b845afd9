"""Controllers as batch laws: the one interface every shipped controller implements, its one-row face, and the
one adapter for a user's per-row policy.

A **batch law** (:class:`BatchPolicy`) acts for the rows (episodes) of a batched env: ``name``,
``reset(rows)`` (the rows ``rows`` start an episode) and ``act(rows, observations, info) -> actions``, with
``rows`` an int array, ``observations`` ``(len(rows), n_obs)``, ``info`` the batched env's info dict of all its
rows (arrays with a leading axis of the rows; the law reads ``info[key][rows]``; right after a reset it is the
reset's info) and the actions ``(len(rows), n_a)``. A row's actions depend on that row's observations and info
only, so a batch of one gives the bits of the same row of any batch.

The shipped controllers subclass :class:`BatchLaw` (state allocated per row by ``_rows(n)``, ``batch(n)`` the
same law for ``n`` fresh rows) and are used one row at a time through their :class:`RowFace`: the benchmark's
:class:`~.policy.Policy` (``reset()``, ``act(observation, info)``) over a batch of one, as
:class:`~lvgym.envs.ascent.AscentEnv` is a face over one row of :class:`~lvgym.envs.core.BatchCore`. A face's
``batch(n)`` is its law for ``n`` rows. A compiled kernel is the law's inner loop where the law has one.

A user's policy needs only the :class:`~.policy.Policy` interface: without ``batch`` it flies through
:class:`PerRow`, one policy object per row, each fed its row's observation and the single env's info
(:func:`row_info`) in its own Python call, with the same records (a batch only saves the calls).

>>> import numpy as np
>>> from lvgym.benchmark.policy import ZeroPolicy
>>> rows = as_batch(ZeroPolicy(), 3)
>>> rows.reset(np.arange(3))
>>> rows.act(np.array([0, 2]), np.zeros((2, 14), np.float32), {"time": np.zeros(3)})
array([[0., 0.],
       [0., 0.]], dtype=float32)
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterator, Mapping
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from lvgym.envs.core import row_info

if TYPE_CHECKING:
    from .policy import Policy

__all__ = ["ROW", "BatchLaw", "BatchPolicy", "OneRowInfo", "PerRow", "RowFace", "as_batch", "own_rows", "row_info"]

#: the rows of a batch of one
ROW = np.zeros(1, dtype=np.int64)


@runtime_checkable
class BatchPolicy(Protocol):
    """``reset(rows)`` when the rows ``rows`` start an episode, then ``act(rows, observations, info) ->
    actions`` at every control step of those rows (the module docstring). ``name`` labels the policy."""

    name: str

    def reset(self, rows: np.ndarray) -> None: ...

    def act(self, rows: np.ndarray, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray: ...


class BatchLaw:
    """The base of the shipped controllers: a law for :attr:`n` rows (the module docstring). A subclass
    implements ``act(rows, observations, info)``; a law with state allocates each row's state in ``_rows(n)``
    (called through :meth:`allocate` by the constructor, ``__init__(n)`` or the subclass's own, and by
    :meth:`batch`; the constants stay shared) and sets it back in ``reset(rows)``."""

    name: str = "law"
    n: int = 0

    def __init__(self, n: int = 1) -> None:
        self.allocate(n)

    def allocate(self, n: int) -> None:
        """Make the state of ``n`` rows (``n >= 1``), all as after a reset."""
        if int(n) < 1:
            raise ValueError(f"policy {self.name!r}: n = {n!r} rows: at least one")
        self.n = int(n)
        self._rows(self.n)

    def _rows(self, n: int) -> None:
        """Make the state of ``n`` rows (a law without state: nothing)."""

    def batch(self, n: int) -> BatchLaw:
        """The same law (its constants shared) for ``n`` rows, each as after a reset."""
        law = copy.copy(self)
        law.allocate(n)
        return law

    def reset(self, rows: Any) -> None:
        """The rows ``rows`` start an episode (a law without state: nothing to forget)."""

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """The actions (len(rows), n_a) of the rows ``rows`` for their observations (len(rows), n_obs) and the
        batched ``info`` of all the law's rows."""
        raise NotImplementedError


class OneRowInfo(Mapping):
    """The single env's info dict (Python numbers, a dict of reward terms, a list of events) read as a batched
    info of one row: each value on access as an array with a leading axis of one (the reward terms a dict of
    such arrays, the events a list of one list). A Python float holds a float64 exactly, so a law reads the
    same numbers as from the batched env's info."""

    __slots__ = ("_info",)

    def __init__(self, info: Mapping[str, Any]) -> None:
        self._info = info

    def __getitem__(self, key: str) -> Any:
        value = self._info[key]
        if key == "events":
            return [list(value)]
        if isinstance(value, Mapping):
            return {k: np.asarray([v]) for k, v in value.items()}
        return np.asarray([value])

    def __contains__(self, key: object) -> bool:
        return key in self._info

    def __iter__(self) -> Iterator[str]:
        return iter(self._info)

    def __len__(self) -> int:
        return len(self._info)


class RowFace:
    """One row of a batch law (``law``, for one row) behind the benchmark's :class:`~.policy.Policy`
    interface: ``reset()`` and ``act(observation, info) -> action`` are the law's on its row 0 (the single env's
    info read as one row, :class:`OneRowInfo`), ``batch(n)`` is the law for ``n`` fresh rows. The shipped
    controllers' classes (``PIDPolicy``, ``LQGPolicy``, ...) are such faces; a subclass that overrides ``act``
    or ``reset`` changes the law, so it flies as :class:`PerRow`."""

    law: BatchLaw

    def __getattr__(self, key: str) -> Any:
        """The law's attributes read through the face (its constants: ``dt``, ``limit``, ``schedule``, ...)."""
        if key == "law" or key.startswith("__"):
            raise AttributeError(key)
        return getattr(self.law, key)

    @property
    def name(self) -> str:
        return self.law.name

    @name.setter
    def name(self, value: str) -> None:
        self.law.name = value

    def reset(self) -> None:
        self.law.reset(ROW)

    def act(self, observation: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        obs = np.asarray(observation)
        return self.law.act(ROW, obs.reshape(1, *obs.shape), OneRowInfo(info))[0]

    def _overridden(self) -> bool:
        kind = type(self)
        return kind.act is not RowFace.act or kind.reset is not RowFace.reset

    def batch(self, n: int) -> BatchPolicy:
        """The same controller for ``n`` rows of a batched env: its law (``PerRow`` of copies when a subclass
        changed the law)."""
        if self._overridden():
            return PerRow(self, n, lambda: copy.deepcopy(self))
        return self.law.batch(n)


class PerRow:
    """A policy without ``batch`` behind the batched interface (the one adapter for a user's per-row policy):
    one policy object per row, the first ``first`` and the others built by ``make()`` (its factory, or a copy)
    when their row first flies; each acts in its own Python call on its row's observation and the single
    env's info of that row (:func:`row_info`)."""

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
        for b in np.asarray(rows, dtype=np.int64).reshape(-1).tolist():
            self._policy(b).reset()

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.asarray(observations)
        return np.asarray([np.asarray(self._policy(b).act(obs[j], row_info(info, b)))
                           for j, b in enumerate(rows.tolist())])


def as_batch(policy: Policy, n: int, make: Callable[[], Policy] | None = None) -> BatchPolicy:
    """``policy`` for ``n`` rows: its own ``batch(n)``, else :class:`PerRow` (``policy`` for the first row,
    ``make()`` builds the others)."""
    batch = getattr(policy, "batch", None)
    return batch(int(n)) if callable(batch) else PerRow(policy, n, make)


def own_rows(policy: Policy) -> BatchPolicy:
    """``policy`` itself as a batch of one row, its own state flying (a face's law; else :class:`PerRow`
    around the object): what :func:`~.runner.play_episode` flies, so that the object holds the flight
    afterwards (an AAC's history, an MPC's solver counts)."""
    if isinstance(policy, RowFace) and not policy._overridden():
        return policy.law
    return PerRow(policy, 1)
