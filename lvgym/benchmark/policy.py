"""The policy interface shared by every controller the benchmark compares (PID baselines, learned agents).

A policy sees what a Gymnasium env returns and nothing else: the observation (SMILE's 14 entries by
default, named in order by the env's ``unwrapped.observation_layout``,
:data:`lvgym.envs.layouts.OBSERVATIONS`) and the ``info`` dict of the last step (right after a reset, the
reset's). It returns an action of the env's action space. The shipped controllers are batch laws
(:mod:`.batch`) and this interface is their one-row face; a user's policy needs only this interface.

>>> policy = ZeroPolicy()
>>> policy.reset()
>>> policy.act(np.zeros(14, dtype=np.float32), {})
array([0., 0.], dtype=float32)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .batch import BatchLaw, RowFace


@runtime_checkable
class Policy(Protocol):
    """``reset()`` at the start of every episode, then ``act(observation, info) -> action`` at every
    control step. ``name`` labels the policy in result tables."""

    name: str

    def reset(self) -> None: ...

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray: ...


class ZeroLaw(BatchLaw):
    """No control for the rows of a batched env: every row's action is the gimbal centred (``Box`` actions of
    zeros) or, for ``discrete`` (``rcs``), the no-pulse action 1."""

    def __init__(self, n_actions: int = 2, discrete: bool = False, n: int = 1, name: str = "zero") -> None:
        self.name = name
        self.action = (np.ones(int(n_actions), dtype=np.int64) if discrete
                       else np.zeros(int(n_actions), dtype=np.float32))
        self.allocate(n)

    def _rows(self, n: int) -> None:
        pass

    def reset(self, rows: Any) -> None:
        pass

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        return np.tile(self.action, (np.size(rows), 1))


class ZeroPolicy(RowFace):
    """No control (:class:`ZeroLaw`, one row)."""

    name = "zero"

    def __init__(self, n_actions: int = 2, discrete: bool = False) -> None:
        self.law = ZeroLaw(n_actions, discrete)
        self.n_actions, self.discrete = int(n_actions), bool(discrete)
