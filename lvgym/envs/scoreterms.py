"""The per-step terms of protocol v2's score, written once: the benchmark sums them over a flown flight
(:mod:`lvgym.benchmark.scoring`, :mod:`lvgym.benchmark.flyability`) and the env's score reward charges them
step by step (:mod:`.scorereward`, the option ``reward_kind="score_v2"``). The envs layer holds them
because the benchmark sits above it and may import it, not the other way round.

Per control step ``k`` of a TVC task (docs/flyability.md has the rule's reasons):

- the policy's gimbal command ``u_k = clip(a_k, -1, 1) * gimbal_limit`` [rad] (pitch, yaw):
  :func:`gimbal_command`;
- its rate ``r_k = (u_k - u_{k-1}) / dt`` [rad/s]: :func:`command_rate`; the rule counts it at the
  *controlled* steps only (the controller acted at ``k - 1`` and at ``k``);
- its square, the mean over the axes ``mean_axis r_k^2`` [rad^2/s^2]: :func:`rate_square`;
- the **budget**: the running sum of the squares may not pass ``(RMS_FRACTION R)^2 n`` (``R`` the servo's
  rate limit [rad/s], ``n`` the flight's controlled steps): :func:`budget`;
- the **burst**: over a window of :func:`window_steps` steps (:data:`WINDOW_S`) with at least
  :func:`window_quorum` controlled steps, the mean square (:func:`window_mean`) may not pass
  ``(WINDOW_FRACTION R)^2``: :func:`burst_limit`;
- a failure, or a break of the rule, at flight time ``t`` is charged ``failure_penalty_rad_per_s`` times the
  mission time left: :func:`mission_charge`.

The rate error's own term, ``(|pitch rate error| + |yaw rate error|) dt``, is the env's ``rate_pitch`` and
``rate_yaw`` reward terms with their weights at 1 (:mod:`.signals`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["RMS_FRACTION", "WINDOW_FRACTION", "WINDOW_S", "budget", "burst_limit", "command_rate", "gimbal_command",
           "mission_charge", "rate_square", "window_mean", "window_quorum", "window_steps"]

#: the budget: the commanded rate's RMS over the controlled flight, as a fraction of the rate limit [-]
RMS_FRACTION = 1.0 / 3.0
#: the burst window [s] and the largest RMS of the commanded rate within it, as a fraction of the limit [-]
WINDOW_S = 2.0
WINDOW_FRACTION = 1.0


def gimbal_command(actions: Any, gimbal_limit_rad: float) -> np.ndarray:
    """The gimbal command [rad] of TVC ``actions`` (..., 2) [-]: clipped to [-1, 1] (as the env clips them)
    times the gimbal limit [rad]."""
    return np.clip(np.asarray(actions, dtype=float), -1.0, 1.0) * float(gimbal_limit_rad)


def command_rate(command_rad: np.ndarray, previous_rad: np.ndarray, dt: float) -> np.ndarray:
    """The commanded rate [rad/s] from the previous step's command to this one's (both [rad], same shape)
    over the control period ``dt`` [s]."""
    return (command_rad - previous_rad) / dt


def rate_square(rate_radps: np.ndarray) -> np.ndarray:
    """The commanded rate's square, the mean over the axes (the last axis) [rad^2/s^2]."""
    return np.mean(rate_radps ** 2, axis=-1)


def budget(rate_limit_radps: float, controlled_steps: Any) -> Any:
    """The budget [rad^2/s^2] of the running sum of :func:`rate_square` over ``controlled_steps`` steps."""
    return (RMS_FRACTION * rate_limit_radps) ** 2 * controlled_steps


def burst_limit(rate_limit_radps: float) -> float:
    """The largest mean of :func:`rate_square` over a burst window [rad^2/s^2]."""
    return (WINDOW_FRACTION * rate_limit_radps) ** 2


def window_steps(dt: float) -> int:
    """The burst window's length in control steps of ``dt`` [s] (at least one)."""
    return max(int(round(WINDOW_S / dt)), 1)


def window_quorum(steps: int) -> int:
    """The controlled steps a window of ``steps`` steps needs to count: half of them (at least one)."""
    return max(steps // 2, 1)


def window_mean(square_sum: Any, controlled: Any) -> Any:
    """The mean square over a window [rad^2/s^2]: the sum of its squares over its controlled steps (the caller
    counts a window only when ``controlled`` reaches :func:`window_quorum`)."""
    return square_sum / np.maximum(controlled, 1)


def mission_charge(penalty_rad_per_s: float, mission_time_s: float, t: Any) -> Any:
    """The charge [rad] of a flight that ends (fails, or breaks the rule) at flight time ``t`` [s]: the penalty
    rate [rad/s] times the mission time left [s] (none after the mission's end); a float for a scalar ``t``,
    an array for an array."""
    out = penalty_rad_per_s * np.maximum(np.subtract(mission_time_s, t), 0.0)
    return float(out) if np.ndim(out) == 0 else out
