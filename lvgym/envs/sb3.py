"""A stable-baselines3 ``VecEnv`` over one :class:`~.functional.AscentFuncEnv` (imports stable-baselines3).

It follows stable-baselines3's conventions: a finished row resets at once, its last observation is in
``infos[i]["terminal_observation"]`` and ``infos[i]["TimeLimit.truncated"]`` says whether the mission
time ended it; ``reset_infos[i]`` is the info of row ``i``'s latest reset (as the single env's
``reset`` returns it). Row ``i`` seeded with ``seed + i`` is step for step the single env seeded with ``seed + i``.
``lvgym.envs.make_sb3_vec_env(env_id, num_envs, seed, **options)`` builds one by env id.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from lvgym.errors import require

require("stable_baselines3", "train", "the stable-baselines3 VecEnv of lvgym")

from stable_baselines3.common.vec_env.base_vec_env import VecEnv  # noqa: E402

from .ascent import _rows  # noqa: E402
from .functional import AscentFuncEnv, AscentState  # noqa: E402
from .spec import check_reset_options  # noqa: E402
from .vector import batch_task  # noqa: E402
from .views import FuncViews

__all__ = ["AscentSB3VecEnv"]


class AscentSB3VecEnv(FuncViews, VecEnv):
    """``num_envs`` rows of an ascent env class (``env_cls``) with the same options, seeded ``seed + i``."""

    def __init__(self, env_cls: type, num_envs: int = 1, seed: int | None = None, **options: Any) -> None:
        options.pop("render_mode", None)
        self.task = batch_task(env_cls, options)
        self.func = AscentFuncEnv(self.task)
        self.render_mode = None                      # the batched rows do not render
        super().__init__(int(num_envs), self.func.observation_space, self.func.action_space)
        self._seed = seed
        self._actions: np.ndarray | None = None
        self._rngs = [np.random.default_rng(None if seed is None else seed + i) for i in range(self.num_envs)]
        self.state: AscentState | None = None

    def reset(self) -> np.ndarray:
        for options in self._options:                # set_options(...): no key is taken (as the single env)
            check_reset_options(options)
        self._reset_options()
        if self._seed is not None:
            self._rngs = [gym.utils.seeding.np_random(self._seed + i)[0] for i in range(self.num_envs)]
            self._seed = None
        self.state = self.func.initial(self._rngs)
        self.func.sim.data = self.state.sim
        self.reset_infos = _rows(self.func.state_info(self.state), self.num_envs)
        return self.func.observation(self.state)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self.state is None or self._actions is None:
            raise RuntimeError("call reset() and step_async() before step_wait()")
        func = self.func
        actions = self._actions
        if actions.ndim == 1 and self.task.control == "rcs":     # SB3 hands MultiDiscrete([3]) actions as (B,)
            actions = actions[:, None]
        self.state = func.transition(self.state, actions, self._rngs, inplace=True)
        obs, reward = func.observation(self.state), func.reward(None, self._actions, self.state)
        terminated, truncated = func.terminal(self.state), func.truncation(self.state)
        done = terminated | truncated
        infos = _rows(func.transition_info(None, self._actions, self.state), self.num_envs)
        for b in np.flatnonzero(done):
            infos[b]["terminal_observation"] = obs[b].copy()
            infos[b]["TimeLimit.truncated"] = bool(truncated[b] and not terminated[b])
        if done.any():
            rows = np.flatnonzero(done)
            self.state = func.reset(self.state, rows, [self._rngs[b] for b in rows])
            self.func.sim.data = self.state.sim
            obs[rows] = func.observation(self.state)[rows]
            fresh = _rows(func.state_info(self.state), self.num_envs)
            for b in rows:
                self.reset_infos[b] = fresh[b]
        return obs, reward.astype(np.float32), done, infos

    def seed(self, seed: int | None = None):
        self._seed = seed
        return [None if seed is None else seed + i for i in range(self.num_envs)]

    def close(self) -> None:
        pass

    def get_attr(self, attr_name, indices=None):
        return [getattr(self, attr_name) for _ in self._get_indices(indices)]

    def set_attr(self, attr_name, value, indices=None) -> None:
        setattr(self, attr_name, value)

    def env_method(self, method_name, *args, indices=None, **kwargs):
        """The rows share one batch: the adapter's own method, called once per index."""
        if not callable(getattr(self, method_name, None)):
            raise AttributeError(f"the batched ascent VecEnv has no method {method_name!r}: its rows "
                                 "share one functional env (self.func) and have no per-env objects")
        return [getattr(self, method_name)(*args, **kwargs) for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False for _ in self._get_indices(indices)]
