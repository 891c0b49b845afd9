"""Training with the command's rate charged: a dense reward term for a gimbal command that chatters.

Protocol v2 charges an unflyable flight as a failure (:mod:`lvgym.benchmark.flyability`): the policy's own
gimbal command ``u_k = clip(a_k, -1, 1) * gimbal_limit`` [rad] may not ask, over the controlled flight, an
RMS rate above a third of the servo's rate limit ``R`` (nor the whole of it over any 2 s). The env's
reward charges the gimbal's own rate (``effort_rate``), which the servo filters and limits, so a learned
correction that alternates at the control rate costs it almost nothing there, and the flight is then
charged in full by ``score_v2``. This wrapper adds, at every controlled step (the controller acted at this
step and at the one before, as the rule counts them), the rule's own quantity:

    r_k = (u_k - u_{k-1}) / dt                    [rad/s], pitch and yaw
    reward -= weight * mean_axis (r_k / R)^2 * dt

``weight`` [rad/s] has the unit of the failure penalty's rate (``failure_penalty_rad_per_s``, 0.1 on the
v1 envs): a flight that spends exactly the rule's budget (``(r / R)^2`` averaging 1/9) is charged
``weight / 9`` per second, so ``weight`` 0.9 charges it the failure penalty's rate. The command is the
action the env gets (a residual policy's mix, before the loop dispersion's gain and delay: what the flight
computer commands). It is a training device, like :mod:`.loadmargin`: the env's reward, validation and
evaluation are unchanged. The charge of each step is in the step's info, ``command_rate_charge``. The env's
score reward (``reward_kind="score_v2"``, :mod:`lvgym.envs.scorereward`) charges the same running sum only
where it breaks the rule (a failure's charge, and the episode ends); this charge warns before, at every step.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from lvgym.benchmark.scoring import FlightFacts, gimbal_command
from lvgym.errors import ConfigError, check_number

__all__ = ["CommandRate", "CommandRateVecEnv", "command_rate_options", "command_rate_venv"]


@dataclass(frozen=True)
class CommandRate:
    """``weight`` [rad/s] of the charge (0 to 100)."""

    weight: float

    def __post_init__(self) -> None:
        check_number("command_rate_charge", self.weight, lo=0.0, hi=100.0)


def command_rate_options(weight: float) -> dict[str, float] | None:
    """The record a run's config keeps (``None``: off, ``weight`` 0); checks the value."""
    if float(weight) == 0.0:
        return None
    return asdict(CommandRate(float(weight)))


class CommandRateVecEnv(VecEnvWrapper):
    """``venv`` (a batched lvgym TVC env, or one wrapping it) with the command-rate charge (module docstring)
    added to every row's reward; the control period, the gimbal limit and the servo's rate limit are the
    env's (:meth:`lvgym.benchmark.scoring.FlightFacts.for_env`)."""

    def __init__(self, venv: Any, charge: CommandRate) -> None:
        super().__init__(venv)
        facts = FlightFacts.for_env(venv)
        if not facts.gimbal_limit_rad > 0.0:
            raise ConfigError("command_rate_charge", charge.weight, "0 on an env without a gimbal (an RCS task)")
        self.charge = charge
        self.dt, self.limit_rad = facts.dt_s, facts.gimbal_limit_rad
        self.rate_limit_radps = facts.gimbal_rate_limit_radps
        self._last = np.zeros((self.num_envs, 2))          # the command of each row's previous step [rad]
        self._on = np.zeros(self.num_envs, dtype=bool)      # its controller acted at that step
        self._command = self._last

    def reset(self) -> np.ndarray:
        obs = self.venv.reset()
        self.reset_infos = self.venv.reset_infos           # what a residual wrapper above reads
        self._on[:] = False
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._command = gimbal_command(np.reshape(actions, (self.num_envs, -1))[:, :2], self.limit_rad)
        self.venv.step_async(actions)

    def step_wait(self) -> Any:
        obs, rewards, dones, infos = self.venv.step_wait()
        self.reset_infos = self.venv.reset_infos
        rewards = np.asarray(rewards, dtype=np.float32).copy()
        on = np.array([bool(info.get("controller_on", True)) for info in infos])
        rate = (self._command - self._last) / self.dt
        charge = np.where(on & self._on, self.charge.weight * np.mean((rate / self.rate_limit_radps) ** 2, axis=1)
                          * self.dt, 0.0)
        for i, info in enumerate(infos):
            info["command_rate_charge"] = float(charge[i])
        rewards -= charge.astype(np.float32)
        self._last = self._command.copy()
        self._on = on & ~np.asarray(dones, dtype=bool)          # an ended row starts afresh
        return obs, rewards, dones, infos


def command_rate_venv(venv: Any, charge: dict[str, Any] | None) -> Any:
    """``venv`` wrapped with the command-rate charge ``charge`` records (``None``: ``venv`` itself)."""
    return venv if not charge else CommandRateVecEnv(venv, CommandRate(**charge))
