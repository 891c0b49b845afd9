"""Where a training run's wall time goes: the env's share against the learner's.

:class:`EnvClock` wraps the batched VecEnv (under ``VecMonitor`` and ``VecNormalize``, over a residual
wrapper, so a residual's baseline counts as env) and adds up the wall time spent in ``reset``,
``step_async`` and ``step_wait`` [s]. The rest of a run's wall time is the learner: the policy's forward
passes during the rollout, the gradient updates, the validations and the checkpoints.
:class:`lvgym.agents.training.callbacks.CheckpointCallback` logs ``time/env_share`` (env seconds over wall seconds since
the run started, resumed segments included, both counted from the start of learning: the first reset
and its kernel loading come before) after every rollout and records ``train_wall_s`` and
``env_wall_s`` in every checkpoint and validation, which is what ``lvgym curves``
(:mod:`lvgym.agents.training.curves`) plots the learning curve against.
"""

from __future__ import annotations

import time
from typing import Any

from stable_baselines3.common.vec_env import VecEnvWrapper

__all__ = ["EnvClock", "find_clock"]


class EnvClock(VecEnvWrapper):
    """A pass-through ``VecEnvWrapper`` that adds up the wall time spent in the env: :attr:`env_s` [s]."""

    def __init__(self, venv: Any) -> None:
        super().__init__(venv)
        self.env_s = 0.0

    def _timed(self, call: Any, *args: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return call(*args)
        finally:
            self.env_s += time.perf_counter() - t0

    def reset(self) -> Any:
        return self._timed(self.venv.reset)

    def step_async(self, actions: Any) -> None:
        self._timed(self.venv.step_async, actions)

    def step_wait(self) -> Any:
        return self._timed(self.venv.step_wait)


def find_clock(venv: Any) -> EnvClock | None:
    """The :class:`EnvClock` in a stack of VecEnv wrappers, or None."""
    while venv is not None:
        if isinstance(venv, EnvClock):
            return venv
        venv = getattr(venv, "venv", None)
    return None
