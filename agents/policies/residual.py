"""Residual policies: a classical baseline flies, a learned policy adds a correction.

The action the env gets is ``clip(baseline(obs, info) + residual_scale * learned, -1, 1)`` (:func:`combine`): the
baseline's action (a policy of :data:`lvgym.benchmark.registry.POLICIES`, by default ``gs-pid-flex``, the PID
designed on the non-rigid v1 flight loop, ``lvgym.baselines.pid:smile_scheduled_pid`` with schedule
``smile_flex``) plus the learned action in [-1, 1] scaled by ``residual_scale`` (gimbal units: a scale of
0.2 lets the learned part move the gimbal by at most 20 % of its limit), clipped to the action space.
So a learned policy that outputs zero flies the baseline's episode exactly.

:class:`ResidualLaw` (with its one-row face :class:`ResidualPolicy`, the saved policy's adapter,
:func:`lvgym.agents.policies.sb3.load_policy`) flies the baseline's batch law and the learned law side by side,
as :class:`ResidualConfig` (what a saved run records) says. The baseline sees the env's own observation (with
``history`` it reads the newest sample by name); the learned policy sees the same observation. Training flies
the same mix through :mod:`lvgym.agents.wrappers.residual` (``train.py --residual``).
"""

from __future__ import annotations

import copy
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

import lvgym.baselines  # noqa: F401  (registers the baselines a residual policy flies on)
from lvgym.benchmark.batch import BatchLaw, RowFace, as_batch
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.runner import build_policy
from lvgym.errors import ConfigError, check_number

__all__ = ["DEFAULT_BASELINE", "ResidualConfig", "ResidualLaw", "ResidualPolicy", "combine"]

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


def combine(base: np.ndarray, learned: np.ndarray, scale: float) -> np.ndarray:
    """``clip(base + scale * learned, -1, 1)`` as float32 (rows or one action)."""
    mixed = np.asarray(base, dtype=np.float32) + np.float32(scale) * np.asarray(learned, dtype=np.float32)
    return np.clip(mixed, -1.0, 1.0).astype(np.float32)


class ResidualLaw(BatchLaw):
    """A learned policy on a baseline for ``n`` rows: the baseline's batch law (built by its registry factory
    on ``env``) and the learned law, mixed by :func:`combine`. ``learned``: a policy whose actions are the
    residual's (an :class:`lvgym.agents.policies.sb3.SB3Policy`, or its law); a learned law with ``note_applied`` is
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
