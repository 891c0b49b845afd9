"""Episode metrics for protocol v1: a headline score that charges failures, rate errors per flight phase,
what flexibility does, and a q-alpha constraint cost (protocol v0's metrics, :mod:`.metrics`, are frozen).

:class:`~.rows.RowsLog` collects an episode's steps from the ``info`` dicts of the env's steps and
:class:`FlightFacts` holds the task's options; :func:`flight_metrics` gives, in SI units and radians:

==========================  ======  =================================================================
score                       rad     ``rate_error_rad`` plus, for a failed episode, ``failure_penalty_rad_per_s``
                                    (the env's reward rate, 0.1 rad/s by default) times the mission time
                                    left: a failure at t is charged as if the rest of the flight had that
                                    rate error, so that failing early never scores better than flying
rate_error_rad              rad     cumulative pitch + yaw rate error up to the end of the episode (the
                                    thesis's criterion, as in v0)
rate_error_<phase>_rad      rad     the same within each phase (``PHASES``, they add up to the whole):
                                    ``max_q`` from the first to the last step before the first burnout with
                                    the dynamic pressure at least ``MAX_Q_FRACTION`` of its peak, ``boost``
                                    the rest of the flight up to that burnout, ``coast`` from it to the
                                    next ignition, ``upper`` after that ignition (0 for a phase not flown)
peak_eta                    sqrt(kg) m  largest |modal coordinate| of any mode and plane
peak_slosh_deg              deg     largest pendulum angle from the body axis (pendulums with mass)
gyro_minus_body_rate_rad    rad     ``int (|g_pitch - w_pitch| + |g_yaw - w_yaw|) dt``: the rate the observation's
                                    gyro gives (``g``: its ``pitch_rate_error`` plus ``pitch_rate_reference``,
                                    its ``yaw_rate_error``) against the body rate ``w`` (``omega_bi_b``) at the
                                    end of each control step: the bending slope rate at the IMU, bias, noise
                                    and whatever sensor dynamics and delay the observation has; 0.0 when the
                                    observation is the ideal state (``IDEAL_OBSERVATIONS``: its rate *is* the
                                    body rate, nothing is measured)
gimbal_rate_limit_s         s       time at the gimbal rate limit (within 1 %)
qalpha_cost_s               s       time with q-alpha above ``QALPHA_COST_FRACTION`` of the structural limit,
                                    a constraint cost for safe RL (the termination stays at the limit)
failed, failure_reason      -       as v0
==========================  ======  =================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.envs.scoreterms import gimbal_command, mission_charge

__all__ = ["FlightColumns", "FlightFacts", "IDEAL_OBSERVATIONS", "MAX_Q_FRACTION", "PHASES", "QALPHA_COST_FRACTION",
           "flight_metrics", "gimbal_command"]

PHASES = ("boost", "max_q", "coast", "upper")
#: the max-q region: dynamic pressure at least this fraction of its peak before the first burnout [-]
MAX_Q_FRACTION = 0.8
#: q-alpha above this fraction of the structural limit counts towards the constraint cost [-]
QALPHA_COST_FRACTION = 0.8
#: observation options whose rates are the body's own (no gyro): ``gyro_minus_body_rate_rad`` is 0 there
IDEAL_OBSERVATIONS = ("state",)
#: observation entries that carry the gyro's view of the body rate [rad/s]
GYRO_ENTRIES = ("pitch_rate_error", "yaw_rate_error", "pitch_rate_reference")


@dataclass(frozen=True)
class FlightFacts:
    """The task's facts a flight's metrics need: ``dt_s`` control period, ``mission_time_s``,
    ``failure_penalty_rad_per_s``, ``qalpha_limit_pa_deg``, ``gimbal_rate_limit_radps`` (0: not counted),
    ``gyro_index``: the observation's indices of :data:`GYRO_ENTRIES` (None: an ideal-state observation, no gyro)
    and ``gimbal_limit_rad`` (0: no gimbal, an RCS task; else the actions are kept as gimbal commands for
    protocol v2's :mod:`.flyability`). Build them from an lvgym env with :meth:`for_env`; the flight's steps are
    kept by :class:`~.rows.RowsLog`."""

    dt_s: float
    mission_time_s: float
    failure_penalty_rad_per_s: float
    qalpha_limit_pa_deg: float
    gimbal_rate_limit_radps: float = 0.0
    gyro_index: tuple[int, int, int] | None = None
    gimbal_limit_rad: float = 0.0

    @classmethod
    def for_env(cls, env: Any) -> FlightFacts:
        u = env.unwrapped
        s = u.task
        gyro = None
        if s.observation not in IDEAL_OBSERVATIONS:
            gyro = tuple(u.observation_layout.index(name) for name in GYRO_ENTRIES)
        limit = float(u.gimbal_limit) if s.control == "tvc" else 0.0
        return cls(s.control_dt_s, s.mission_time_s, s.failure_penalty_rad_per_s, s.qalpha_limit_pa_deg,
                   math.radians(s.gimbal_rate_limit_degps), gyro, limit)


def _phase_masks(t: np.ndarray, qbar: np.ndarray, events: list[tuple[float, str]]) -> dict[str, np.ndarray]:
    """Boolean masks of the steps of each phase (a step belongs to the phase its end time is in)."""
    burnout = next((te for te, text in sorted(events) if "burnout" in text), math.inf)
    ignition = next((te for te, text in sorted(events) if "ignition" in text and te >= burnout), math.inf)
    first = t <= burnout
    peak = float(np.max(qbar[first])) if first.any() else 0.0
    high = first & (qbar >= MAX_Q_FRACTION * peak) & (peak > 0.0)
    if high.any():                                     # from the first to the last step above the fraction
        max_q = first & (t >= t[high][0]) & (t <= t[high][-1])
    else:
        max_q = np.zeros_like(first)
    return {"boost": first & ~max_q, "max_q": max_q, "coast": (t > burnout) & (t <= ignition), "upper": t > ignition}


def _peak(arrays: Any) -> float:
    """Largest absolute finite value of the recorded arrays (a list of one array per step, or their stack;
    0.0 for none: no mode, no pendulum with mass)."""
    if len(arrays) == 0:
        return 0.0
    try:
        x = np.abs(np.asarray(arrays, dtype=float)).ravel()
    except ValueError:                                 # shapes that change within the episode
        x = np.abs(np.concatenate([np.ravel(np.asarray(a, dtype=float)) for a in arrays]))
    x = x[np.isfinite(x)]
    return float(x.max()) if x.size else 0.0


@dataclass
class FlightColumns:
    """One episode as arrays, one entry per control step (a flight's row of :class:`~.rows.RowsLog`): ``time_s`` (N,) [s], ``rate_error_radps`` (N, 3) [rad/s], ``qbar_pa`` (N,)
    [Pa], ``qalpha_pa_deg`` (N,) [Pa deg], ``gimbal_rate_radps`` (N, n) [rad/s], ``gyro_minus_body_radps``
    (N, 2) [rad/s] or None (no gyro), ``eta`` (N, ...) and ``slosh_angles_rad`` (N, ...) (or lists of one
    array per step), ``events`` ((t [s], text) pairs) and ``termination``; for protocol v2's
    :mod:`.flyability`, ``command_rad`` (N, 2) [rad] the policy's gimbal command (its action clipped to
    [-1, 1] times the gimbal limit; None: no gimbal or not recorded) and ``controller_on`` (N,) whether the
    controller acted in the step (None: always); ``qalpha_limit_pa_deg`` (N,) the structural limit at each step
    (None: the log's constant one). Arrays C-contiguous as ``np.array`` of the steps makes
    them: :func:`flight_metrics` then sums them in the same order."""

    time_s: np.ndarray
    rate_error_radps: np.ndarray
    qbar_pa: np.ndarray
    qalpha_pa_deg: np.ndarray
    gimbal_rate_radps: np.ndarray
    gyro_minus_body_radps: np.ndarray | None
    eta: Any
    slosh_angles_rad: Any
    events: list[tuple[float, str]]
    termination: str
    command_rad: np.ndarray | None = None
    controller_on: np.ndarray | None = None
    qalpha_limit_pa_deg: np.ndarray | None = None


def flight_metrics(log: FlightFacts, c: FlightColumns) -> dict[str, Any]:
    """The v1 metrics of one episode (see the module docstring) of its steps ``c``, with the task's facts
    ``log``. ``rate_error_rad`` is summed as protocol v0's :func:`~.metrics.episode_metrics` sums it (per
    axis, then pitch + yaw), so the two agree bit for bit."""
    dt = float(log.dt_s)
    t, qbar, qalpha = c.time_s, c.qbar_pa, c.qalpha_pa_deg
    n = len(t)
    if n:
        rate = np.abs(np.asarray(c.gimbal_rate_radps, dtype=float)).reshape(n, -1)
        rate = rate.max(axis=1) if rate.shape[1] else np.zeros(n)
    else:
        rate = np.zeros(0)
    e = np.abs(np.nan_to_num(np.reshape(c.rate_error_radps, (n, 3)), nan=0.0))
    integral = e.sum(axis=0) * dt if n else np.zeros(3)
    out: dict[str, Any] = {"rate_error_rad": float(integral[1] + integral[2])}
    failed = bool(c.termination)
    t_end = float(t[-1]) if t.size else 0.0
    charge = mission_charge(log.failure_penalty_rad_per_s, log.mission_time_s, t_end) if failed else 0.0
    out["score"] = out["rate_error_rad"] + charge
    masks = _phase_masks(t, qbar, c.events) if t.size else {p: np.zeros(0, bool) for p in PHASES}
    pitch_yaw = e[:, 1] + e[:, 2]
    for name in PHASES:
        out[f"rate_error_{name}_rad"] = float(pitch_yaw[masks[name]].sum() * dt)
    out["peak_eta"] = _peak(c.eta)
    out["peak_slosh_deg"] = math.degrees(_peak(c.slosh_angles_rad))
    if log.gyro_index is not None and c.gyro_minus_body_radps is not None and len(c.gyro_minus_body_radps):
        g = np.abs(np.nan_to_num(np.asarray(c.gyro_minus_body_radps, dtype=float), nan=0.0))
        out["gyro_minus_body_rate_rad"] = float(g.sum() * dt)
    else:
        out["gyro_minus_body_rate_rad"] = 0.0
    lim = float(log.gimbal_rate_limit_radps)
    out["gimbal_rate_limit_s"] = float(np.sum(rate >= 0.99 * lim) * dt) if lim > 0 else 0.0
    limit = log.qalpha_limit_pa_deg if c.qalpha_limit_pa_deg is None else np.asarray(c.qalpha_limit_pa_deg, float)
    out["qalpha_cost_s"] = float(np.sum(np.nan_to_num(qalpha) > QALPHA_COST_FRACTION * limit) * dt)
    out["failed"] = failed
    out["failure_reason"] = c.termination
    return out
