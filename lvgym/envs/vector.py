"""Batched environments over one :class:`~.core.AscentBatch`: a Gymnasium ``VectorEnv`` and an SB3 ``VecEnv``.

Both run the same batched code as the single env (one simulator, one compiled kernel over all rows);
row ``i`` seeded with ``seed + i`` is step for step the single env seeded with ``seed + i``.
:class:`AscentVectorEnv` autoresets on the next step (Gymnasium's default ``NEXT_STEP`` mode: the step
after an episode's end resets that row, ignores its action and returns reward 0);
:class:`AscentSB3VecEnv` follows stable-baselines3 (reset at once, the last observation in
``infos[i]["terminal_observation"]``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .ascent import DEFAULT_AERO_MACH, SlenderAscentEnv, _rows, make_spaces
from .core import AscentBatch
from .spec import TaskSpec



def _task(env_cls: type, options: dict[str, Any]) -> TaskSpec:
    options = dict(options)
    if env_cls is SlenderAscentEnv:
        length, diameter = options.pop("length", 8.5), options.pop("diameter", 0.3)
        if np.size(diameter) != 1:
            raise ValueError("diameter ranges are drawn per episode by the single SlenderAscent env only; "
                             "a vector env flies one geometry (make one vector env per diameter)")
        aero_mach = options.pop("aero_mach", DEFAULT_AERO_MACH)
        options["vehicle"] = ("slender", float(length), float(np.ravel(diameter)[0]),
                              None if aero_mach is None else float(aero_mach))
    return TaskSpec.build(env_cls.DEFAULTS, options)


class AscentVectorEnv(VectorEnv):
    """``num_envs`` rows of an ascent env class (``env_cls``) with the same options."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, env_cls: type, num_envs: int = 1, **options: Any) -> None:
        options.pop("render_mode", None)
        self.task = _task(env_cls, options)
        self.num_envs = int(num_envs)
        self.core = AscentBatch(self.task, self.num_envs)
        self.single_action_space, self.single_observation_space = make_spaces(self.task)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._rngs = [np.random.default_rng() for _ in range(self.num_envs)]
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None):
        if seed is None or isinstance(seed, int):
            seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
        self._rngs = [gym.utils.seeding.np_random(s)[0] for s in seeds]
        obs = self.core.reset_rows(np.arange(self.num_envs), self._rngs)
        self._needs_reset[:] = False
        return obs, {}

    def step(self, actions):
        actions = np.asarray(actions)
        redo = np.flatnonzero(self._needs_reset)
        obs, reward, terminated, truncated, info = self.core.step(actions.reshape(self.num_envs, -1), skip=redo)
        if redo.size:
            obs[redo] = self.core.reset_rows(redo, [self._rngs[b] for b in redo])
            reward[redo] = 0.0
            terminated[redo] = False
            truncated[redo] = False
        self._needs_reset = terminated | truncated
        return obs, reward, terminated, truncated, info


class AscentSB3VecEnv:
    """A stable-baselines3 ``VecEnv`` over an :class:`AscentBatch` (built lazily so that importing lvgym
    does not import stable-baselines3)."""

    def __new__(cls, env_cls: type, num_envs: int = 1, seed: int | None = None, **options: Any):
        from stable_baselines3.common.vec_env.base_vec_env import VecEnv

        class _Adapter(VecEnv):
            def __init__(self) -> None:
                self.task = _task(env_cls, options)
                self.core = AscentBatch(self.task, num_envs)
                action_space, obs_space = make_spaces(self.task)
                self.render_mode = None                      # the batched rows do not render
                super().__init__(num_envs, obs_space, action_space)
                self._seed = seed
                self._actions: np.ndarray | None = None
                self._rngs = [np.random.default_rng(None if seed is None else seed + i) for i in range(num_envs)]

            def reset(self):
                if self._seed is not None:
                    self._rngs = [gym.utils.seeding.np_random(self._seed + i)[0] for i in range(self.num_envs)]
                    self._seed = None
                return self.core.reset_rows(np.arange(self.num_envs), self._rngs)

            def step_async(self, actions) -> None:
                self._actions = np.asarray(actions)

            def step_wait(self):
                obs, reward, terminated, truncated, info = self.core.step(self._actions.reshape(self.num_envs, -1))
                done = terminated | truncated
                infos = _rows(info, self.num_envs)
                for b in np.flatnonzero(done):
                    infos[b]["terminal_observation"] = obs[b].copy()
                    infos[b]["TimeLimit.truncated"] = bool(truncated[b] and not terminated[b])
                if done.any():
                    rows = np.flatnonzero(done)
                    obs[rows] = self.core.reset_rows(rows, [self._rngs[b] for b in rows])
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
                                         "share one AscentBatch (self.core) and have no per-env objects")
                return [getattr(self, method_name)(*args, **kwargs) for _ in self._get_indices(indices)]

            def env_is_wrapped(self, wrapper_class, indices=None):
                return [False for _ in self._get_indices(indices)]

        return _Adapter()
