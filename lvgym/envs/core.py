"""One batch core under every face: B episodes of an :class:`~.functional.AscentFuncEnv` with their generators.

:class:`BatchCore` holds what changes (the rows' :data:`~.functional.AscentState` and one random generator
per row) and does, for every face, what a face would otherwise write again: the reset of chosen rows from
their generators, the step, the autoreset and the infos. The faces are thin, as brax's wrappers are over its
pipeline:

- :class:`~.ascent.AscentEnv` (``gymnasium.Env``): one row, no autoreset (``autoreset=None``);
- :class:`~.vector.AscentVectorEnv` (Gymnasium ``VectorEnv``): ``autoreset="next_step"`` (Gymnasium's
  ``NEXT_STEP``: the step after an episode's end resets that row, ignores its action and returns reward 0,
  not terminated, not truncated);
- :class:`~.sb3.AscentSB3VecEnv` (stable-baselines3 ``VecEnv``): ``autoreset="same_step"`` (a finished row
  resets within the step; its last observation is :attr:`StepResult.final_obs`).

Every row draws from its own generator only, in the order of :mod:`.functional`, so row ``i`` seeded ``s``
flies exactly the single env reset with seed ``s``.

Infos. A step's ``info`` is a dict of per-row arrays (:meth:`~.functional.AscentFuncEnv.transition_info`,
read off the state after the step; with ``next_step``, after the resets of that step, so a row that reset
holds its new episode's first values); :func:`row_info` takes row ``b`` of it as the single env's info dict
(Python scalars, a dict of reward terms, a list of events) and :func:`row_infos` every row at once.
:meth:`BatchCore.reset_info` is the per-row info of a reset (:data:`RESET_INFO_KEYS`).
"""

from __future__ import annotations

from collections import namedtuple
from collections.abc import Sequence
from typing import Any

import numpy as np

from .functional import AscentFuncEnv, AscentState
from .snapshot import EpisodeState, rng_state, set_rng_state

__all__ = ["AUTORESET", "BatchCore", "RESET_INFO_KEYS", "StepResult", "row_info", "row_infos", "select_rows"]

#: the autoreset conventions of :class:`BatchCore` (None: the rows never reset by themselves)
AUTORESET = (None, "next_step", "same_step")
#: the keys of a reset's info (:meth:`BatchCore.reset_info`; their values are those of ``transition_info``
#: at the same state)
RESET_INFO_KEYS = ("time", "cumulative_rate_error", "mass", "controller_on")
_NO_ROWS = np.zeros(0, dtype=np.int64)

#: one step of every row: ``obs`` (B, n_obs) float32, ``reward`` (B,), ``terminated`` (B,) bool, ``truncated``
#: (B,) bool, ``info`` (per-row arrays), ``reset`` the rows reset within the step (int array), ``final_obs``
#: (``same_step`` only, else None) the last observations of those rows (len(reset), n_obs) before their reset
StepResult = namedtuple("StepResult", ["obs", "reward", "terminated", "truncated", "info", "reset", "final_obs"])


def select_rows(rows: Any, n: int) -> np.ndarray:
    """Row indices ``rows`` (default all) of a batch of ``n`` rows, checked."""
    idx = np.arange(n) if rows is None else np.atleast_1d(np.asarray(rows, dtype=np.int64))
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        raise IndexError(f"rows {idx.tolist()} of a batch of {n} rows")
    return idx


def row_info(info: dict[str, Any], b: int) -> dict[str, Any]:
    """Row ``b`` of a batch info dict, as the single env's ``info``: scalars as Python numbers, the reward
    terms as a dict of floats, the events as a list; other entries as row ``b`` of their array."""
    out: dict[str, Any] = {}
    for key, value in info.items():
        if key == "reward_terms":
            out[key] = {k: float(v[b]) for k, v in value.items()}
        elif key == "events":
            out[key] = list(value[b])
        else:
            v = value[b]
            out[key] = v.item() if isinstance(v, np.generic) else v
    return out


def row_infos(info: dict[str, Any], batch: int) -> list[dict[str, Any]]:
    """Every row's :func:`row_info` of a batch info dict of ``batch`` rows, built column by column (one
    ``tolist`` per key instead of one look-up per key and row)."""
    columns: dict[str, list] = {}
    for key, value in info.items():
        if key == "reward_terms":
            names = list(value)
            columns[key] = [dict(zip(names, vals)) for vals in zip(*(value[k].tolist() for k in names))]
        elif key == "events":
            columns[key] = [list(e) for e in value]
        elif value.ndim == 1:
            columns[key] = value.tolist()
        else:
            columns[key] = list(value)
    keys = list(columns)
    return [dict(zip(keys, vals)) for vals in zip(*columns.values())] if keys else [{} for _ in range(batch)]


class BatchCore:
    """``num_rows`` episodes of ``func`` (see the module docstring). Attributes: ``func``, ``num_rows``,
    ``autoreset`` (one of :data:`AUTORESET`), ``state`` (None before the first :meth:`reset`), ``rngs`` (one
    ``numpy.random.Generator`` per row, None before its first reset), ``needs_reset`` ((B,) bool: with
    ``next_step``, the rows the next step resets)."""

    def __init__(self, func: AscentFuncEnv, num_rows: int, autoreset: str | None = None) -> None:
        if autoreset not in AUTORESET:
            raise ValueError(f"autoreset = {autoreset!r}: one of {AUTORESET}")
        self.func, self.num_rows, self.autoreset = func, int(num_rows), autoreset
        self.state: AscentState | None = None
        self.rngs: list[np.random.Generator | None] = [None] * self.num_rows
        self.needs_reset = np.zeros(self.num_rows, dtype=bool)

    # ------------------------------------------------------------------------------ reset
    def reset(self, rows: Any = None, rngs: Sequence[np.random.Generator] | None = None) -> None:
        """New episodes for the rows ``rows`` (default all), drawn from their generators (``rngs``, one per
        row, replaces them first). Before the first step every row must be reset (all at once)."""
        idx = select_rows(rows, self.num_rows)
        if rngs is not None:
            rngs = list(rngs)
            if len(rngs) != idx.size:
                raise ValueError(f"{len(rngs)} generators for {idx.size} rows")
            for b, g in zip(idx, rngs):
                self.rngs[b] = g
        if any(self.rngs[b] is None for b in idx):
            raise ValueError("a row without a generator: pass rngs= to its first reset")
        if self.state is None or idx.size == self.num_rows and np.array_equal(idx, np.arange(self.num_rows)):
            if idx.size != self.num_rows:
                raise RuntimeError("reset every row before resetting some")
            self.state = self.func.initial(self.rngs)
        else:
            self.state = self.func.reset(self.state, idx, [self.rngs[b] for b in idx])
        self.needs_reset[idx] = False

    def observation(self) -> np.ndarray:
        """The observation of every row (B, n_obs) float32 (a copy)."""
        return self.func.observation(self._checked())

    def reset_info(self) -> dict[str, np.ndarray]:
        """The per-row arrays of a reset's info (:data:`RESET_INFO_KEYS`) at the current state."""
        return self.func.state_info(self._checked())

    def _checked(self) -> AscentState:
        if self.state is None:
            raise RuntimeError("call reset() first")
        return self.state

    # ------------------------------------------------------------------------------ step
    def step(self, actions: Any, *, checked: bool = False) -> StepResult:
        """Every row one control period on with ``actions`` (B, ...) of the action space (``checked``: the
        caller has passed them through ``func.check_action`` already), then the autoreset."""
        func = self.func
        state = self._checked()
        a = np.asarray(actions) if checked else func.check_action(actions, self.num_rows)
        redo = np.flatnonzero(self.needs_reset) if self.autoreset == "next_step" else _NO_ROWS
        rngs = self.rngs if not redo.size else [None if r else g for g, r in zip(self.rngs, self.needs_reset)]
        state = func.transition(state, a, rngs, inplace=True, checked=True)
        reward = func.reward(None, a, state)
        terminated, truncated = func.terminal(state), func.truncation(state)
        final_obs = None
        if self.autoreset == "same_step":
            info = func.transition_info(None, a, state)
            obs = func.observation(state)
            redo = np.flatnonzero(terminated | truncated)
            if redo.size:
                final_obs = obs[redo]
                state = func.reset(state, redo, [self.rngs[b] for b in redo])
                obs[redo] = func.observation(state)[redo]
        else:
            if redo.size:                    # next_step: the rows that ended last step start again
                state = func.reset(state, redo, [self.rngs[b] for b in redo])
                reward[redo] = 0.0
                terminated[redo] = False
                truncated[redo] = False
            info = func.transition_info(None, a, state)
            obs = func.observation(state)
            if self.autoreset == "next_step":
                self.needs_reset = terminated | truncated
        self.state = state
        return StepResult(obs, reward, terminated, truncated, info, redo, final_obs)

    # ------------------------------------------------------------------------------ snapshots
    def get_state(self, rows: Any = None, extra: dict[str, list[Any]] | None = None) -> EpisodeState:
        """The whole state of the rows ``rows`` (default all) with the face's per-row ``extra``; with
        ``next_step`` it holds the autoreset flags too (see :mod:`.snapshot`)."""
        if self.state is None:
            raise RuntimeError("call reset() before get_state()")
        idx = select_rows(rows, self.num_rows)
        extra = dict(extra or {})
        if self.autoreset == "next_step":
            extra["needs_reset"] = [bool(self.needs_reset[b]) for b in idx]
        return EpisodeState(self.func.spec, self.func.take(self.state, idx), [rng_state(self.rngs[b]) for b in idx],
                            extra)

    def set_state(self, snap: EpisodeState, rows: Any = None) -> None:
        """Continue the rows ``rows`` (default all) from ``snap`` (as many rows, of the same options); the
        snapshot itself is not changed. Restoring some rows needs a state (a reset) first."""
        idx = select_rows(rows, self.num_rows)
        snap.check(self.func.spec, idx.size)
        if self.state is None or idx.size == self.num_rows and np.array_equal(idx, np.arange(self.num_rows)):
            if idx.size != self.num_rows:
                raise RuntimeError("call reset() before set_state() of some rows")
            self.state = self.func.take(snap.state)
        else:
            self.state = self.func.put(self.state, idx, snap.state)
        flags = snap.extra.get("needs_reset", [False] * idx.size)
        for i, b in enumerate(idx):
            if self.rngs[b] is None:
                self.rngs[b] = np.random.default_rng()
            set_rng_state(self.rngs[b], snap.rng[i])
            self.needs_reset[b] = bool(flags[i])
