"""The score reward (the option ``reward_kind="score_v2"``): each step's reward is minus that step's causal
increment of protocol v2's headline ``score_v2`` (:mod:`lvgym.benchmark.flyability`), from the terms of
:mod:`.scoreterms`, so that minus an episode's return is the flight's ``score_v2``:

- every step: ``-(|pitch rate error| + |yaw rate error|) dt`` [rad] (the reward terms ``rate_pitch`` and
  ``rate_yaw``; ``rate_roll``, ``effort`` and ``effort_rate`` are 0);
- a step that ends the flight by a failure: minus ``failure_penalty_rad_per_s`` times the mission time left
  (the term ``failure``), as the default reward charges it;
- a step at which the gimbal command breaks the flyability rule (a TVC task): the same charge, and the
  episode ends there (terminated, ``info["termination"]`` the code :data:`UNFLYABLE`), as ``score_v2``
  charges an unflyable flight: its rate error up to that step plus the penalty for the mission left.

The rule as the benchmark applies it reads the whole flight; the reward applies it step by step on the same
running sums, bit for bit, with one difference. The **burst** part (a 2 s window of the command's rate) is
causal. The **budget** part compares the running sum of the squared rates with a budget proportional to the
flight's controlled steps ``n``, which a flight knows only at its end: the reward takes the ``n`` of the
whole mission (:func:`expected_controlled_steps`, the controller's schedule being the same for every row).
A flight that reaches the mission's end has exactly that ``n``, so minus its return is its ``score_v2`` to
the rounding of the sums. A flight that fails earlier has fewer controlled steps and a smaller budget: if its
command passed that smaller budget before the failure, ``score_v2`` charges it from that earlier step and the
reward did not (docs/rl.md gives the largest deviation over 200 validation flights).

The row's state (:func:`score_layout`) is the task rows' ``score`` block (:data:`~.signals.TaskData`), so
snapshots carry it.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from lvgym.packing import Field, Packed

from .layouts import REASONS, REWARD
from .options import REWARD_KINDS
from .scoreterms import (budget, burst_limit, command_rate, gimbal_command, mission_charge, rate_square, window_mean,
                         window_quorum, window_steps)
from .signals import TaskData, controller_on_k

__all__ = ["REWARD_KINDS", "UNFLYABLE", "ScoreReward", "expected_controlled_steps", "score_layout"]

#: the termination code of a break of the flyability rule (:data:`~.layouts.REASONS`)
UNFLYABLE = REASONS.index("gimbal command unflyable")
_PITCH, _YAW, _FAILURE = REWARD.index("rate_pitch"), REWARD.index("rate_yaw"), REWARD.index("failure")


@functools.lru_cache(maxsize=8)
def score_layout(window: int) -> Packed:
    """The score reward's state of one row for a burst window of ``window`` steps."""
    return Packed("score reward state", [
        Field("command", 2, "rad", "the gimbal command of the row's last step (pitch, yaw)"),
        Field("acted", 1, "-", "1 when the controller acted in the row's last step"),
        Field("square_sum", 1, "rad^2/s^2", "running sum of the rate squares of the controlled steps"),
        Field("controlled", 1, "-", "controlled steps so far"),
        Field("window_sums", window + 1, "rad^2/s^2",
              "square_sum after each of the last window + 1 steps: step k at (k + 1) mod (window + 1), 0 before"),
        Field("window_counts", window + 1, "-", "controlled after each of them, in the same places"),
    ])


def expected_controlled_steps(task: np.ndarray, tables: Any, n_steps: int, dt: float) -> int:
    """The controlled steps of a flight of ``n_steps`` control steps of ``dt`` [s] that reaches the mission's
    end: the steps ``k >= 1`` whose controller acted at ``k - 1`` and at ``k`` (it acts in step ``k`` when it
    is on at the step's start, ``k dt``: after ``controller_on_after_s`` and while an engine burns; the
    timeline's tables, the same for every row)."""
    on = np.array([controller_on_k(task, tables.t, tables.burning, k * dt) for k in range(int(n_steps))], dtype=bool)
    return int(np.count_nonzero(on[1:] & on[:-1]))


class ScoreReward:
    """The score reward of one task (module docstring): ``spec`` its :class:`~.spec.TaskSpec`,
    ``gimbal_limit_rad`` [rad], ``n_steps`` control steps of the mission, ``task`` and ``tables`` the
    functional env's parameters (the controller's schedule). :attr:`columns`: the width of each row's state."""

    def __init__(self, spec: Any, gimbal_limit_rad: float, n_steps: int, task: np.ndarray, tables: Any) -> None:
        self.dt = float(spec.control_dt_s)
        self.mission_time_s = float(spec.mission_time_s)
        self.penalty = float(spec.failure_penalty_rad_per_s)
        self.tvc = spec.control == "tvc"
        self.limit_rad = float(gimbal_limit_rad)
        rate_limit = math.radians(spec.gimbal_rate_limit_degps)
        self.window = window_steps(self.dt)
        self.quorum = window_quorum(self.window)
        self.layout = score_layout(self.window)
        #: controlled steps of a flight to the mission's end, and the budget of the rule's running sum
        self.expected = expected_controlled_steps(task, tables, n_steps, self.dt) if self.tvc else 0
        self.allowed = budget(rate_limit, self.expected)
        self.burst = burst_limit(rate_limit)
        self.columns = self.layout.size if self.tvc else 0

    def reset(self, ts: TaskData, rows: np.ndarray) -> None:
        """Fresh state for the rows ``rows`` (a reset)."""
        ts.score[rows] = 0.0

    def step(self, ts: TaskData, t: np.ndarray, action: np.ndarray) -> None:
        """Replace the reward and its terms of the step just flown by every row (after the compiled
        signals): ``t`` (B,) [s] the rows' flight time, ``action`` (B, 2) the actions sampled this step. A
        row that breaks the flyability rule ends (its termination code :data:`UNFLYABLE`)."""
        dt = self.dt
        e = np.nan_to_num(ts.rate_error[:, 1:3], nan=0.0)
        pitch, yaw = -(e[:, 0] * dt), -(e[:, 1] * dt)
        if self.tvc:
            broken = self._breaks(ts, action)
            ts.reason[broken] = UNFLYABLE
            ts.truncated[broken] = False
        charge = np.where(ts.reason != 0, mission_charge(self.penalty, self.mission_time_s, t), 0.0)
        terms = ts.terms
        terms[:] = 0.0
        terms[:, _PITCH], terms[:, _YAW], terms[:, _FAILURE] = pitch, yaw, -charge
        ts.reward[:] = pitch + yaw - charge

    def _breaks(self, ts: TaskData, action: np.ndarray) -> np.ndarray:
        """Advance every row's running sums by this step's command and say which rows break the rule at it
        (the budget of :attr:`expected` controlled steps, or a burst window ending here)."""
        lay, S, W = self.layout, ts.score, self.window
        i_acted, i_sum, i_count = lay.index("acted"), lay.index("square_sum"), lay.index("controlled")
        c = lay.slice("command")
        u = gimbal_command(np.reshape(action, (S.shape[0], -1))[:, :2], self.limit_rad)
        on = ts.on_step
        both = on & (S[:, i_acted] != 0.0)
        square = np.where(both, rate_square(command_rate(u, S[:, c], self.dt)), 0.0)
        total = S[:, i_sum] + square
        n = S[:, i_count] + both
        S[:, i_sum], S[:, i_count], S[:, c], S[:, i_acted] = total, n, u, on
        sums, counts = S[:, lay.slice("window_sums")], S[:, lay.slice("window_counts")]
        rows, k = np.arange(S.shape[0]), ts.steps - 1
        sums[rows, (k + 1) % (W + 1)] = total
        counts[rows, (k + 1) % (W + 1)] = n
        start = (k + 1 - W) % (W + 1)
        full = k >= W - 1                          # a whole window ends at this step
        short = ~full & ((ts.reason != 0) | ts.truncated)     # a flight shorter than a window: all of it
        s_w = np.where(full, total - sums[rows, start], total)
        n_w = np.where(full, n - counts[rows, start], n)
        mean = np.where(n_w >= self.quorum, window_mean(s_w, n_w), 0.0)
        return (total > self.allowed) | ((full | short) & (mean > self.burst))
