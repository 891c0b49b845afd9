"""Training with the structural load's margin charged: a dense reward term for flying near the q-alpha limit.

Protocol v2's failures under faults and under the max-q gust are q-alpha exceedances by a few per cent (the
causal designs' failed flights peak at 250-265 kPa deg against SMILE's 250 kPa deg limit), and an episode
that ends there is charged only once, at its end (the env's ``failure`` term: the penalty rate times the
mission time left). A policy learning from that alone sees a rare, sparse signal. This wrapper adds, at
every control step, a charge for the load's ratio to its limit above a threshold:

    r = qalpha_pa_deg / qalpha_limit_pa_deg          (the step's info, lvgym.envs)
    reward -= weight * max(0, r - threshold) * control_dt_s

``weight`` [rad/s] has the unit of the failure penalty's rate (``failure_penalty_rad_per_s``, 0.1 on the
v1 envs): ``weight`` 1 charges a flight held at the limit 0.2 rad/s above a threshold of 0.8, twice the
failure penalty's rate. It is a training device, like the loop dispersion (:mod:`.loop_dispersion`): the
env's reward, validation and evaluation are unchanged, and what the policy is judged on is the score.
The charge of each step is in the step's info, ``load_margin_charge``. The env's score reward
(``reward_kind="score_v2"``) charges the load only where it crosses the limit, as the default reward does.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from lvgym.errors import ConfigError, check_number

__all__ = ["LoadMargin", "LoadMarginVecEnv", "load_margin_options", "load_margin_venv"]


@dataclass(frozen=True)
class LoadMargin:
    """``weight`` [rad/s] of the charge (0 to 100); ``threshold`` [-]: the load's ratio to its limit above
    which it is charged (0 to 1)."""

    weight: float
    threshold: float = 0.8

    def __post_init__(self) -> None:
        check_number("load_margin", self.weight, lo=0.0, hi=100.0)
        check_number("load_margin_threshold", self.threshold, lo=0.0, hi=1.0)


def load_margin_options(weight: float, threshold: float = 0.8) -> dict[str, float] | None:
    """The record a run's config keeps (``None``: off, ``weight`` 0); checks the values."""
    if float(weight) == 0.0:
        return None
    return asdict(LoadMargin(float(weight), float(threshold)))


class LoadMarginVecEnv(VecEnvWrapper):
    """``venv`` with the load-margin charge (module docstring) added to every row's reward; ``dt`` [s] is
    the control period."""

    def __init__(self, venv: Any, margin: LoadMargin, dt: float) -> None:
        super().__init__(venv)
        if not dt > 0.0:
            raise ConfigError("control_dt_s", dt, "a control period > 0 s")
        self.margin, self.dt = margin, float(dt)

    def reset(self) -> np.ndarray:
        return self.venv.reset()

    def step_wait(self) -> Any:
        obs, rewards, dones, infos = self.venv.step_wait()
        rewards = np.asarray(rewards, dtype=np.float32).copy()
        for i, info in enumerate(infos):
            limit = float(info.get("qalpha_limit_pa_deg", 0.0) or 0.0)
            if limit <= 0.0 or not np.isfinite(limit):
                continue
            ratio = float(info.get("qalpha_pa_deg", 0.0)) / limit
            charge = self.margin.weight * max(0.0, ratio - self.margin.threshold) * self.dt
            info["load_margin_charge"] = charge
            rewards[i] -= charge
        return obs, rewards, dones, infos


def load_margin_venv(venv: Any, margin: dict[str, Any] | None, dt: float) -> Any:
    """``venv`` wrapped with the load-margin charge ``margin`` records (``None``: ``venv`` itself)."""
    return venv if not margin else LoadMarginVecEnv(venv, LoadMargin(**margin), dt)
