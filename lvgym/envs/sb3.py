"""A stable-baselines3 ``VecEnv`` face of the batch core (:class:`~.core.BatchCore`; imports stable-baselines3).

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

from .core import BatchCore, row_infos  # noqa: E402
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
        self.core = BatchCore(AscentFuncEnv(self.task), int(num_envs), autoreset="same_step")
        self.func = self.core.func
        self.render_mode = None                      # the batched rows do not render
        super().__init__(int(num_envs), self.func.observation_space, self.func.action_space)
        self._seed = seed
        self._actions: np.ndarray | None = None
        self.core.rngs = [np.random.default_rng(None if seed is None else seed + i) for i in range(self.num_envs)]

    @property
    def state(self) -> AscentState | None:
        """The rows' state (None before the first reset)."""
        return self.core.state

    def reset(self) -> np.ndarray:
        for options in self._options:                # set_options(...): no key is taken (as the single env)
            check_reset_options(options)
        self._reset_options()
        if self._seed is not None:
            self.core.rngs = [gym.utils.seeding.np_random(self._seed + i)[0] for i in range(self.num_envs)]
            self._seed = None
        self.core.reset()
        self.reset_infos = row_infos(self.core.reset_info(), self.num_envs)
        return self.core.observation()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self.state is None or self._actions is None:
            raise RuntimeError("call reset() and step_async() before step_wait()")
        actions = self._actions
        if actions.ndim == 1 and self.task.control == "rcs":     # SB3 hands MultiDiscrete([3]) actions as (B,)
            actions = actions[:, None]
        out = self.core.step(actions)
        infos = row_infos(out.info, self.num_envs)
        if out.reset.size:
            fresh = row_infos(self.core.reset_info(), self.num_envs)
            for i, b in enumerate(out.reset):
                infos[b]["terminal_observation"] = out.final_obs[i]
                infos[b]["TimeLimit.truncated"] = bool(out.truncated[b] and not out.terminated[b])
                self.reset_infos[b] = fresh[b]
        return out.obs, out.reward.astype(np.float32), out.terminated | out.truncated, infos

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
