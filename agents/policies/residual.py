"""Residual policies: a classical baseline flies, a learned policy adds a correction.

The action the env gets is ``clip(baseline(obs, info) + residual_scale * learned, -1, 1)``: the baseline's
action (a policy of :data:`lvgym.benchmark.registry.POLICIES`, by default ``gs-pid-flex``, the PID
designed on the non-rigid v1 flight loop, ``lvgym.baselines.pid:smile_scheduled_pid`` with schedule
``smile_flex``) plus the learned action in [-1, 1] scaled by ``residual_scale`` (gimbal units: a scale of
0.2 lets the learned part move the gimbal by at most 20 % of its limit), clipped to the action space.
So a learned policy that outputs zero flies the baseline's episode exactly.

The baseline is its batch law in training and in evaluation: :class:`ResidualRows` holds it for the env rows
and mixes the actions (:func:`combine`) for :class:`ResidualVecEnv` (an SB3 ``VecEnvWrapper`` over the batched
lvgym ``VecEnv``, what ``train.py --residual`` trains on) and :class:`ResidualEnv` (a Gymnasium wrapper of a
single env); :class:`ResidualLaw` (with its one-row face :class:`ResidualPolicy`, the saved policy's adapter,
:func:`lvgym.agents.policy.load_policy`) flies the baseline's law and the learned law side by side. The baseline sees the env's own observation (with ``history`` it reads the newest sample by
name); the learned policy sees the same observation.
"""

from __future__ import annotations

import copy
from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

import lvgym.baselines  # noqa: F401  (registers the baselines a residual policy flies on)
from lvgym.benchmark.batch import BatchLaw, RowFace, as_batch
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy
from lvgym.errors import ConfigError, check_number

__all__ = ["DEFAULT_BASELINE", "INFO_KEYS", "ResidualConfig", "ResidualEnv", "ResidualLaw", "ResidualPolicy",
           "ResidualRows",
           "ResidualVecEnv", "combine", "residual_options", "residual_venv", "stack_infos"]

DEFAULT_BASELINE = "gs-pid-flex"
#: registered policies that cannot be a residual's baseline (learned ones: the residual is on a classical law)
NOT_BASELINES = ("ppo",)


@dataclass(frozen=True)
class ResidualConfig:
    """``baseline``: a name of :data:`~lvgym.benchmark.registry.POLICIES` (not a learned one);
    ``scale`` [-]: gimbal units (fractions of the gimbal limit) per unit of learned action, in (0, 2]."""

    baseline: str = DEFAULT_BASELINE
    scale: float = 0.2

    def __post_init__(self) -> None:
        allowed = sorted(set(POLICIES) - set(NOT_BASELINES))
        if self.baseline not in allowed:
            raise ConfigError("residual.baseline", self.baseline, f"one of {allowed}")
        object.__setattr__(self, "scale", check_number("residual.scale", self.scale, 0.0, 2.0, lo_open=True))

    def to_dict(self) -> dict[str, Any]:
        """What a saved run records (``{"baseline": ..., "scale": ...}``)."""
        return asdict(self)

    @classmethod
    def from_meta(cls, meta: dict[str, Any]) -> ResidualConfig | None:
        """The residual set-up a saved policy's sidecar records, or None for a plain policy."""
        r = meta.get("residual")
        return None if not r else cls(**r)


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


def combine(base: np.ndarray, learned: np.ndarray, scale: float) -> np.ndarray:
    """``clip(base + scale * learned, -1, 1)`` as float32 (rows or one action)."""
    mixed = np.asarray(base, dtype=np.float32) + np.float32(scale) * np.asarray(learned, dtype=np.float32)
    return np.clip(mixed, -1.0, 1.0).astype(np.float32)


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


class ResidualLaw(BatchLaw):
    """A learned policy on a baseline for ``n`` rows: the baseline's batch law (built by its registry factory
    on ``env``) and the learned law, mixed by :func:`combine`. ``learned``: a policy whose actions are the
    residual's (an :class:`lvgym.agents.policy.SB3Policy`, or its law); a learned law with ``note_applied`` is
    told the action the env gets (its observation history records that one, as the env's does). The baseline
    starts its episode at the row's first step."""

    def __init__(self, learned: Any, config: ResidualConfig, env: Any, name: str | None = None, n: int = 1) -> None:
        self.config, self.env = config, env
        self.spec = POLICIES[config.baseline]
        self.source = learned
        self.name = name or getattr(learned, "name", "residual")
        self.allocate(n)

    def _rows(self, n: int) -> None:
        env, spec, source = self.env, self.spec, self.source
        self.baseline = as_batch(build_policy(spec, env), n, lambda: build_policy(spec, env))
        self.learned = as_batch(source, n, lambda: copy.deepcopy(source))
        self._fresh = np.ones(n, dtype=bool)

    def reset(self, rows: Any) -> None:
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        self.learned.reset(rows)
        self._fresh[rows] = True

    def act(self, rows: Any, observations: np.ndarray, info: Any) -> np.ndarray:
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        fresh = rows[self._fresh[rows]]
        if fresh.size:                               # the baseline starts its episode at the row's first step
            self.baseline.reset(fresh)
            self._fresh[fresh] = False
        base = np.asarray(self.baseline.act(rows, observations, info), dtype=np.float32)
        action = combine(base, np.reshape(self.learned.act(rows, observations, info), base.shape), self.config.scale)
        if hasattr(self.learned, "note_applied"):
            self.learned.note_applied(rows, action)
        return action


class ResidualPolicy(RowFace):
    """A learned policy on a baseline as a benchmark Policy: one row of :class:`ResidualLaw` (``act`` returns
    ``baseline + scale * learned``, built on ``env``)."""

    def __init__(self, learned: Any, config: ResidualConfig, env: Any, name: str | None = None) -> None:
        self.law = ResidualLaw(learned, config, env, name)
