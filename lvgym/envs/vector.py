"""Batched environments over one :class:`~.functional.AscentFuncEnv`: a Gymnasium ``VectorEnv``.

It is the ``VectorEnv`` face of the batch core (:class:`~.core.BatchCore`), which the single env and
the stable-baselines3 ``VecEnv`` (:class:`lvgym.envs.sb3.AscentSB3VecEnv`) share (one simulator, one
compiled kernel over all rows); row ``i`` seeded with ``seed + i`` is step for step the single env seeded
with ``seed + i``. :class:`AscentVectorEnv` autoresets on the next step (Gymnasium's default ``NEXT_STEP``
mode: the step after an episode's end resets that row, ignores its action and returns reward 0; that
row's info entries are then those of its new episode's first state). The info is a dict of per-row arrays;
:func:`lvgym.envs.core.row_info` takes row ``b`` of it as the single env's info dict.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from lvgym.errors import ConfigError

from .ascent import SlenderAscentEnv
from .core import BatchCore, select_rows
from .functional import AscentFuncEnv, AscentState
from .snapshot import EpisodeState
from .spec import TaskSpec, check_reset_options
from .views import FuncViews


def batch_task(env_cls: type, options: dict[str, Any]) -> TaskSpec:
    """The task of ``num_envs`` rows of ``env_cls`` with ``options`` (one vehicle for all rows)."""
    options = dict(options)
    if issubclass(env_cls, SlenderAscentEnv):
        geometry, diameter = env_cls.geometry(options)        # the preset's geometry where not given
        if np.size(diameter) != 1:
            raise ConfigError("diameter", diameter, "one diameter [m]: ranges are drawn per episode by the single "
                              "SlenderAscent env only; a vector env flies one geometry (one vector env per diameter)")
        options["vehicle"] = geometry
    return TaskSpec.build(env_cls.PRESET, options, env_cls.KEYWORDS)


class AscentVectorEnv(FuncViews, VectorEnv):
    """``num_envs`` rows of an ascent env class (``env_cls``) with the same options: the ``VectorEnv`` face
    of a :class:`~.core.BatchCore` with ``next_step`` autoreset. The state of every row is
    ``self.state``; ``self.flight`` reads its simulator rows by name."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, env_cls: type, num_envs: int = 1, **options: Any) -> None:
        options.pop("render_mode", None)
        self.task = batch_task(env_cls, options)
        self.num_envs = int(num_envs)
        self.core = BatchCore(AscentFuncEnv(self.task), self.num_envs, autoreset="next_step")
        self.func = self.core.func
        self.single_action_space, self.single_observation_space = self.func.action_space, self.func.observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)

    @property
    def state(self) -> AscentState | None:
        """The rows' state (None before the first reset)."""
        return self.core.state

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None):
        """Reset every row (an int ``seed`` seeds row ``i`` with ``seed + i``); ``options`` takes no key
        (an unknown one raises, as for the single env)."""
        check_reset_options(options)
        if seed is None or isinstance(seed, int):
            seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
        self.core.reset(rngs=[gym.utils.seeding.np_random(s)[0] for s in seeds])
        return self.core.observation(), self.core.reset_info()

    def step(self, actions):
        if self.state is None:
            raise RuntimeError("call reset() before step()")
        out = self.core.step(actions)
        return out.obs, out.reward, out.terminated, out.truncated, out.info

    # ------------------------------------------------------------------------------ state as data
    def get_state(self, rows: Any = None) -> EpisodeState:
        """The whole state of the rows ``rows`` (default all), one :class:`~.snapshot.EpisodeState`
        (``.row(i)`` is row i alone, which a single env of the same options restores)."""
        n = select_rows(rows, self.num_envs).size
        return self.core.get_state(rows, {"variant": [0] * n, "rates": [[] for _ in range(n)]})

    def set_state(self, state: EpisodeState, rows: Any = None) -> None:
        """Continue the rows ``rows`` (default all) from ``state`` (the same number of rows; from
        :meth:`get_state`, or single envs' states of the same options)."""
        self.core.set_state(state, rows)
