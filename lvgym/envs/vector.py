"""Batched environments over one :class:`~.functional.AscentFuncEnv`: a Gymnasium ``VectorEnv``.

It runs the same batched code as the single env (one simulator, one compiled kernel over all rows); row
``i`` seeded with ``seed + i`` is step for step the single env seeded with ``seed + i``.
:class:`AscentVectorEnv` autoresets on the next step (Gymnasium's default ``NEXT_STEP`` mode: the step
after an episode's end resets that row, ignores its action and returns reward 0). The stable-baselines3
``VecEnv`` over the same code is :class:`lvgym.envs.sb3.AscentSB3VecEnv`.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from lvgym.errors import ConfigError

from .ascent import SlenderAscentEnv
from .functional import AscentFuncEnv, AscentState
from .snapshot import EpisodeState, rng_state, set_rng_state
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


def _select(rows: Any, n: int) -> np.ndarray:
    idx = np.arange(n) if rows is None else np.atleast_1d(np.asarray(rows, dtype=np.int64))
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        raise IndexError(f"rows {idx.tolist()} of a vector env of {n} rows")
    return idx


class AscentVectorEnv(FuncViews, VectorEnv):
    """``num_envs`` rows of an ascent env class (``env_cls``) with the same options."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, env_cls: type, num_envs: int = 1, **options: Any) -> None:
        options.pop("render_mode", None)
        self.task = batch_task(env_cls, options)
        self.num_envs = int(num_envs)
        self.func = AscentFuncEnv(self.task)
        self.single_action_space, self.single_observation_space = self.func.action_space, self.func.observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.state: AscentState | None = None
        self._rngs: list[np.random.Generator] = []
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None):
        """Reset every row (an int ``seed`` seeds row ``i`` with ``seed + i``); ``options`` takes no key
        (an unknown one raises, as for the single env)."""
        check_reset_options(options)
        if seed is None or isinstance(seed, int):
            seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
        self._rngs = [gym.utils.seeding.np_random(s)[0] for s in seeds]
        self.state = self.func.initial(self._rngs)
        self.func.sim.data = self.state.sim
        self._needs_reset[:] = False
        return self.func.observation(self.state), self.func.state_info(self.state)

    def step(self, actions):
        if self.state is None:
            raise RuntimeError("call reset() before step()")
        func = self.func
        actions = np.asarray(actions)
        redo = np.flatnonzero(self._needs_reset)
        rngs = [None if r else g for g, r in zip(self._rngs, self._needs_reset)]
        self.state = func.transition(self.state, actions, rngs, inplace=True)
        info = func.transition_info(None, actions, self.state)
        reward = func.reward(None, actions, self.state)
        terminated, truncated = func.terminal(self.state), func.truncation(self.state)
        if redo.size:
            self.state = func.reset(self.state, redo, [self._rngs[b] for b in redo])
            reward[redo] = 0.0
            terminated[redo] = False
            truncated[redo] = False
        self.func.sim.data = self.state.sim
        self._needs_reset = terminated | truncated
        return func.observation(self.state), reward, terminated, truncated, info

    # ------------------------------------------------------------------------------ state as data
    def get_state(self, rows: Any = None) -> EpisodeState:
        """The whole state of the rows ``rows`` (default all), one :class:`~.snapshot.EpisodeState`
        (``.row(i)`` is row i alone, which a single env of the same options restores)."""
        if self.state is None:
            raise RuntimeError("call reset() before get_state()")
        idx = _select(rows, self.num_envs)
        return EpisodeState(self.task, self.func.take(self.state, idx), [rng_state(self._rngs[b]) for b in idx],
                            {"needs_reset": [bool(self._needs_reset[b]) for b in idx], "variant": [0] * idx.size,
                             "rates": [[] for _ in idx]})

    def set_state(self, state: EpisodeState, rows: Any = None) -> None:
        """Continue the rows ``rows`` (default all) from ``state`` (the same number of rows; from
        :meth:`get_state`, or single envs' states of the same options)."""
        if self.state is None:
            raise RuntimeError("call reset() before set_state()")
        idx = _select(rows, self.num_envs)
        state.check(self.task, idx.size)
        self.state = self.func.put(self.state, idx, state.state)
        for i, b in enumerate(idx):
            set_rng_state(self._rngs[b], state.rng[i])
            self._needs_reset[b] = bool(state.extra.get("needs_reset", [False] * idx.size)[i])
        self.func.sim.data = self.state.sim
