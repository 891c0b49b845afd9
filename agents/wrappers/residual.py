"""The residual training wrappers: the env flies ``clip(baseline + scale * learned, -1, 1)``
(:func:`lvgym.agents.policies.residual.combine`) while the learned policy trains on its own action.

The baseline is its batch law in training as in evaluation: :class:`ResidualRows` holds it for the env rows and
mixes the actions for :class:`ResidualVecEnv` (an SB3 ``VecEnvWrapper`` over the batched lvgym ``VecEnv``, what
``train.py --residual`` trains on) and :class:`ResidualEnv` (a Gymnasium wrapper of a single env). A saved
residual run flies through :class:`lvgym.agents.policies.residual.ResidualPolicy`.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from lvgym.benchmark.batch import as_batch
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy
from lvgym.errors import ConfigError

from ..policies.residual import ResidualConfig, combine

__all__ = ["INFO_KEYS", "ResidualEnv", "ResidualRows", "ResidualVecEnv", "residual_options", "residual_venv",
           "stack_infos"]


def residual_options(baseline: str | None, scale: float) -> dict[str, Any] | None:
    """``train.py``'s ``--residual`` and ``--residual-scale`` as a run records them (None: not residual);
    a bad value is a ConfigError naming the option."""
    if baseline in (None, "none"):
        return None
    try:
        return ResidualConfig(baseline, scale).to_dict()
    except ConfigError as exc:
        raise ConfigError("--residual" if exc.key.endswith("baseline") else "--residual-scale", exc.value,
                          exc.allowed) from None


def residual_venv(venv: Any, residual: dict[str, Any] | None) -> Any:
    """``venv`` (the batched lvgym SB3 VecEnv) wrapped residual as ``residual`` records, or itself."""
    return venv if residual is None else ResidualVecEnv(venv, ResidualConfig(**residual))


#: the info keys a baseline's batch reads from the stacked infos (:func:`stack_infos`): a reset's info has
#: these and no more (lvgym.baselines.batch)
INFO_KEYS = ("time", "cumulative_rate_error", "mass", "controller_on")


def stack_infos(infos: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """The per-row ``infos`` (one dict per row, as an SB3 ``VecEnv`` gives them) as a batched info dict:
    each of :data:`INFO_KEYS` that every row has, as an array with a leading axis of the rows."""
    return {k: np.array([i[k] for i in infos]) for k in INFO_KEYS if all(k in i for i in infos)}


class ResidualRows:
    """The baseline's batch law for the env rows (built by its registry factory on ``env``, a single or batched
    lvgym env; a policy without one flies through :class:`lvgym.benchmark.batch.PerRow`) and the baseline
    action of each row for its coming step (:attr:`base`, (rows, n_a) float32)."""

    def __init__(self, config: ResidualConfig, env: Any, rows: int) -> None:
        if not hasattr(env.action_space, "low"):
            raise ValueError("a residual policy needs a Box (TVC) action space")
        self.config = config
        spec = POLICIES[config.baseline]
        self.batch = as_batch(build_policy(spec, env), int(rows), lambda: build_policy(spec, env))
        n_a = int(np.prod(env.action_space.shape[-1:]))
        self.base = np.zeros((int(rows), n_a), np.float32)

    def reset(self, rows: Any, obs: np.ndarray, infos: list[dict[str, Any]]) -> None:
        """Rows ``rows`` start an episode whose first observation is ``obs[b]`` and info ``infos[b]``."""
        rows = np.asarray(list(rows), dtype=int)
        self.batch.reset(rows)
        self.advance(rows, obs, infos)

    def advance(self, rows: Any, obs: np.ndarray, infos: list[dict[str, Any]]) -> None:
        """Rows ``rows`` went one step on: their baselines act on the new observation (``infos``: every
        row's info)."""
        rows = np.asarray(list(rows), dtype=int)
        if rows.size:
            self.base[rows] = self.batch.act(rows, obs[rows], stack_infos(infos))

    def apply(self, learned: np.ndarray) -> np.ndarray:
        """The env's actions for the learned actions ``learned`` (rows, n_a)."""
        return combine(self.base, np.reshape(learned, self.base.shape), self.config.scale)


class ResidualVecEnv(VecEnvWrapper):
    """The batched lvgym SB3 ``VecEnv`` (:class:`lvgym.envs.sb3.AscentSB3VecEnv`, wrapped directly: it
    reads its ``reset_infos``) with residual actions: ``step(learned)`` flies ``baseline + scale * learned``."""

    def __init__(self, venv: Any, config: ResidualConfig) -> None:
        super().__init__(venv)
        self.rows = ResidualRows(config, venv, venv.num_envs)

    def reset(self) -> np.ndarray:
        obs = self.venv.reset()
        self.rows.reset(range(self.num_envs), obs, self.venv.reset_infos)
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self.venv.step_async(self.rows.apply(actions))

    def step_wait(self):
        obs, reward, done, infos = self.venv.step_wait()
        self.rows.advance(np.flatnonzero(~done), obs, infos)
        self.rows.reset(np.flatnonzero(done), obs, self.venv.reset_infos)
        return obs, reward, done, infos


class ResidualEnv(gym.Wrapper):
    """A single lvgym env with residual actions (the same :class:`ResidualRows`, one row)."""

    def __init__(self, env: gym.Env, config: ResidualConfig) -> None:
        super().__init__(env)
        self.rows = ResidualRows(config, env, 1)

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self.rows.reset([0], obs[None], [info])
        return obs, info

    def step(self, action: Any):
        obs, reward, terminated, truncated, info = self.env.step(self.rows.apply(action)[0])
        self.rows.advance([0], obs[None], [info])
        return obs, reward, terminated, truncated, info
