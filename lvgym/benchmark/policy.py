"""The policy interface shared by every controller the benchmark compares (PID baselines, learned agents).

A policy sees what a Gymnasium env returns and nothing else: the observation (SMILE's 14 entries by
default, named in order by the env's ``unwrapped.observation_layout``,
:data:`lvgym.envs.layouts.OBSERVATIONS`) and the ``info`` dict of the last step (an empty dict right after
a reset). It returns an action of the env's action space.

>>> policy = ZeroPolicy()
>>> policy.reset()
>>> policy.act(np.zeros(14, dtype=np.float32), {})
array([0., 0.], dtype=float32)
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Policy(Protocol):
    """``reset()`` at the start of every episode, then ``act(observation, info) -> action`` at every
    control step. ``name`` labels the policy in result tables."""

    name: str

    def reset(self) -> None: ...

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray: ...


class ZeroPolicy:
    """No control: the gimbal stays centred (``Box`` actions of zeros; ``rcs``: the no-pulse action 1)."""

    name = "zero"

    def __init__(self, n_actions: int = 2, discrete: bool = False) -> None:
        self.n_actions = int(n_actions)
        self.discrete = bool(discrete)

    def reset(self) -> None:
        pass

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if self.discrete:
            return np.ones(self.n_actions, dtype=np.int64)
        return np.zeros(self.n_actions, dtype=np.float32)

    def batch(self, n: int) -> ZeroBatch:
        """The same for ``n`` rows of a batched env (:mod:`.batch`)."""
        return ZeroBatch(self)


class ZeroBatch:
    """:class:`ZeroPolicy` for the rows of a batched env (the interface of :mod:`.batch`): every row's
    action is the policy's own."""

    def __init__(self, policy: ZeroPolicy) -> None:
        self.name = policy.name
        self._action = policy.act(np.zeros(0, np.float32), {})

    def reset(self, rows: Any) -> None:
        pass

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        return np.tile(self._action, (np.size(rows), 1))
