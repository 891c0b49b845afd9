"""Adaptive augmenting control (AAC) in the manner of the SLS flight control: a bounded multiplicative
forward-loop gain ``k_T`` per axis on a classical baseline. One batch law, :class:`AACLaw`, on any base law
that keeps its rows' last gimbal commands (the PID family's :class:`.pid.PIDLaw`); its compiled inner loop in
:mod:`.aackernel`; :class:`AdaptiveAugmentingPolicy` is its one-row face.

What it follows: Orr and VanZwieten, "Robust, practical adaptive control for launch vehicles" (AIAA GNC
2012, NTRS 20120015662) and Wall, Orr and VanZwieten, "Space Launch System implementation of adaptive
augmenting control" (AAS 14-051); docs/adaptive-control.md says what of them was read and what is ours.

The law, per axis ``i`` (pitch, yaw), every control period ``dt`` while the loop is engaged::

    u_i      base policy's gimbal command [rad]            (the classical loop, untouched)
    w_m      reference model: w_m[n] = p_m w_m[n-1] + (1 - p_m) w_ref[n],  p_m = exp(-w_rm dt)
    e_i      = w_m - w_i = (w_m - w_ref) - (rate error)_i   the reference model's rate minus the gyro's [rad/s]
    e_f      = LP_e(e_i)                                    first-order low-pass, Tustin (keeps bending out)
    e_d      = sign(e_f) max(|e_f| - e_dz, 0)               error dead zone [rad/s]
    y_i      = LP_s(HP_s(d_i)^2)                            spectral damper of the gimbal command sent [rad^2]
    y_d      = max(y_i - y_dz, 0)                           its dead zone (ours; y_dz = 0: y_d = y_i)
    dk/dt    = a e_d^2 - b y_d (k - k_min) - c (k - 1)      error gain, spectral damper, leakage to 1
    d_i      = clip(k_i u_i, -limit, limit)                 the command sent

``k`` is integrated exactly over the period with ``e_d`` and ``y`` held (zero-order hold): with
``r = b y + c`` and ``k_inf = (a e_d^2 + b y k_min + c) / r``, ``k[n] = k_inf + (k[n-1] - k_inf) exp(-r dt)``
(``k[n-1] + a e_d^2 dt`` when ``r = 0``), then clipped to ``[k_min, k_max]``. The exact step never
overshoots, however stiff ``b y`` is. The filters are Tustin's, pre-warped at their cut-offs.

Order within a step (causal): the base acts on the observation; ``e`` comes from the same observation;
``k`` steps with that ``e`` and the spectral damper of the commands sent so far; the command is ``k u``;
the damper then takes the command in.

Off (the observation's ``controller_on`` below 0.5: before the controller starts and through the
staging coast): ``k`` is frozen and the filters are held; at every engagement the filters restart
(no transient from the switch) and, with ``reset_on_engage``, ``k`` starts again from 1 (a new flight
phase starts from the classical design).

Shared gain (``per_axis=False``): one ``k`` for both axes from ``e_pitch^2 + e_yaw^2`` and
``y_pitch + y_yaw``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError, check_bool, check_number
from lvgym.simulator.threads import Kernel

from .aackernel import AAC_ROW, AACConsts, aac_act_k, aac_pid_act_k, dead_zone, first_order
from .pid import PIDLaw, flex_pid, smile_scheduled_pid
from .pidkernel import ObsColumns

__all__ = ["AACLaw", "AACParams", "AdaptiveAugmentingPolicy", "FLEX_AAC", "flex_aac", "smile_aac"]


@dataclass(frozen=True)
class AACParams:
    """Parameters of the adaptive law (module docstring; docs/adaptive-control.md gives the reasons).

    Units: ``error_gain`` a [1/s per (rad/s)^2], ``damper_gain`` b [1/s per rad^2], ``leak_rate`` c [1/s],
    the dead zone [rad/s], the cut-offs [Hz], the reference model's bandwidth [rad/s]."""

    #: lower bound of k_T: -6 dB, inside the rigid loop's gain-reduction margin (docs/adaptive-control.md)
    k_min: float = 0.5
    #: upper bound of k_T: +6 dB, the rigid loop's design gain margin (~6.5 dB; docs/adaptive-control.md)
    k_max: float = 2.0
    #: a: rise rate of k_T per squared error beyond the dead zone [1/s / (rad/s)^2]
    error_gain: float = 3000.0
    #: error dead zone [rad/s] (about 0.86 deg/s): errors below it never raise k_T
    error_deadzone_radps: float = 0.015
    #: low-pass of the error [Hz]: the rigid-body band; the bending content of the gyro stays out of a e^2
    error_lp_hz: float = 2.0
    #: b: spectral damper gain [1/s / rad^2 of high-passed gimbal command]
    damper_gain: float = 2.0e4
    #: dead zone of the spectral damper [rad^2]: only the part of ``y`` above it lowers k_T (ours, not in the
    #: papers: the flight's own high-frequency content, staging and gusts, then costs nothing; 0: off)
    damper_deadzone_rad2: float = 0.0
    #: spectral damper high-pass [Hz]: about an octave above the loops' ~3.4 Hz crossover
    damper_hp_hz: float = 7.0
    #: spectral damper low-pass of the squared signal [Hz]: an octave below the high-pass
    damper_lp_hz: float = 3.5
    #: c: leakage back to 1 [1/s] (a 2 s time constant)
    leak_rate: float = 0.5
    #: bandwidth of the first-order reference model of the commanded pitch rate [rad/s]
    ref_model_radps: float = 20.0
    #: one k_T per axis (pitch, yaw), as SLS's per-axis gains; False: one shared gain
    per_axis: bool = True
    #: k_T back to 1 at every engagement of the loop (after the staging coast)
    reset_on_engage: bool = True

    def __post_init__(self) -> None:
        number = {"k_min": (0.0, 1.0, False), "k_max": (1.0, 10.0, False), "error_gain": (0.0, 1e9, False),
                  "error_deadzone_radps": (0.0, 1.0, False), "error_lp_hz": (0.0, 1e3, True),
                  "damper_gain": (0.0, 1e12, False), "damper_deadzone_rad2": (0.0, 1.0, False),
                  "damper_hp_hz": (0.0, 1e3, True),
                  "damper_lp_hz": (0.0, 1e3, True), "leak_rate": (0.0, 1e3, False),
                  "ref_model_radps": (0.0, 1e4, True)}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in number:
                lo, hi, lo_open = number[f.name]
                object.__setattr__(self, f.name, check_number(f"aac.{f.name}", v, lo, hi, lo_open=lo_open))
            else:
                check_bool(f"aac.{f.name}", v)
        if not self.k_min < 1.0:
            raise ConfigError("aac.k_min", self.k_min, "must be below 1 (the classical design's gain)")
        if not self.k_max > 1.0:
            raise ConfigError("aac.k_max", self.k_max, "must be above 1 (the classical design's gain)")

    def check_rate(self, dt: float) -> None:
        """Every cut-off below the Nyquist frequency of the control period ``dt`` [s]."""
        nyquist = 0.5 / dt
        for key in ("error_lp_hz", "damper_hp_hz", "damper_lp_hz"):
            if not getattr(self, key) < nyquist:
                raise ConfigError(f"aac.{key}", getattr(self, key),
                                  f"must be below the Nyquist frequency {nyquist:g} Hz of the {dt:g} s control period")

    def replace(self, **changes: Any) -> AACParams:
        """A copy with ``changes`` (validated)."""
        return AACParams(**{**asdict(self), **changes})


def consts(params: AACParams, dt: float, limit: float) -> AACConsts:
    """The law's constants for the control period ``dt`` [s] and the gimbal ``limit`` [rad] (the cut-offs
    checked against the Nyquist frequency)."""
    params.check_rate(dt)
    p = params
    e_pole, e_gain = first_order("low", p.error_lp_hz, dt)
    hp_pole, hp_gain = first_order("high", p.damper_hp_hz, dt)
    lp_pole, lp_gain = first_order("low", p.damper_lp_hz, dt)
    return AACConsts(p.k_min, p.k_max, p.error_gain, p.damper_gain, p.leak_rate, p.error_deadzone_radps,
                     p.damper_deadzone_rad2, float(dt), float(limit), math.exp(-p.ref_model_radps * dt),
                     bool(p.per_axis), bool(p.reset_on_engage), e_pole, e_gain, hp_pole, hp_gain, lp_pole, lp_gain)


class AACLaw(BatchLaw):
    """AAC (module docstring) for ``n`` rows around a ``base`` batch law that keeps each row's last gimbal
    command [rad] in ``base.gimbal`` (n, 2) after ``act``, as :class:`.pid.PIDLaw` does: the base flies as
    designed and its command is multiplied by ``k_T`` per axis. ``env``: the lvgym env (its observation layout:
    ``pitch_rate_error``, ``yaw_rate_error``, ``pitch_rate_reference``, ``controller_on``; its control period
    and gimbal limit unless the base has ``dt`` and ``limit``). :attr:`gimbal` (n, 2) [rad]: the commands sent."""

    def __init__(self, base: Any, *, env: Any, params: AACParams | None = None, name: str | None = None,
                 n: int = 1) -> None:
        if not (callable(getattr(base, "batch", None)) and hasattr(base, "gimbal")):
            raise ConfigError("aac base", type(base).__name__, "a batch law that keeps its rows' gimbal commands "
                              "(the PID family's PIDLaw, or a policy face over one)")
        task = env.unwrapped
        lay = task.observation_layout
        self.base = base
        self.params = params or AACParams()
        self.name = name or f"aac({getattr(base, 'name', 'base')})"
        self.dt = float(getattr(base, "dt", task.task.control_dt_s))
        self.limit = float(getattr(base, "limit", task.gimbal_limit))
        self.law = consts(self.params, self.dt, self.limit)
        none = np.full(2, -1, np.int64)
        self.oc = ObsColumns(np.asarray([lay.index("pitch_rate_error"), lay.index("yaw_rate_error")], np.int64), none,
                             int(lay.index("controller_on")), -1, int(lay.index("pitch_rate_reference")), none)
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.base = self.base.batch(n)
        self.rows = AAC_ROW.pack({"k": 1.0, "fresh": 1.0}, n)

    @property
    def gimbal(self) -> np.ndarray:
        return AAC_ROW.view(self.rows, "gimbal")

    def gains(self, rows: Any) -> np.ndarray:
        """``k_T`` (len(rows), 2) of each axis of the rows ``rows`` (a shared gain on both)."""
        k = AAC_ROW.view(self.rows, "k")[np.asarray(rows, dtype=np.int64).reshape(-1)]
        return k.copy() if self.params.per_axis else np.repeat(k[:, :1], 2, axis=1)

    def errors(self, rows: Any) -> np.ndarray:
        """The dead-zoned, filtered errors ``e_d`` (len(rows), 2) [rad/s] of the rows' last engaged step."""
        e = AAC_ROW.view(self.rows, "e_y")[np.asarray(rows, dtype=np.int64).reshape(-1)]
        return dead_zone(e, self.params.error_deadzone_radps)

    def damper(self, rows: Any) -> np.ndarray:
        """The spectral damper's output ``y`` (len(rows), 2) [rad^2] of the rows."""
        return AAC_ROW.view(self.rows, "lp_y")[np.asarray(rows, dtype=np.int64).reshape(-1)].copy()

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode: the base's reset, ``k_T`` 1 and the filters' restart."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        self.base.reset(w)
        self.rows[w] = AAC_ROW.pack({"k": 1.0, "fresh": 1.0})

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows``: the base acts, then the adaptive law scales
        its commands (:func:`.aackernel.aac_act_k`; around a :class:`.pid.PIDLaw`, both in one compiled call,
        :func:`.aackernel.aac_pid_act_k`)."""
        rows = np.ascontiguousarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations).reshape(rows.size, -1)
        out = np.empty((rows.size, 2), np.float32)
        base = self.base
        if type(base) is PIDLaw:        # the shipped bases: both laws in one compiled call
            value = np.ascontiguousarray(base.values(info), dtype=np.float64)
            base.prepare(rows, obs, value)
            _AAC_PID.keyed((obs.dtype, obs.flags.writeable), base.tb, base.su, base.oc, base.st, self.law, self.oc,
                     self.rows, rows, obs, value, out)
            return out
        base.act(rows, obs, info)
        u = np.ascontiguousarray(base.gimbal[rows], dtype=np.float64)
        aac_act_k(self.law, self.oc, self.rows, rows, u, obs, out)
        return out


class AdaptiveAugmentingPolicy(RowFace):
    """AAC around a baseline ``base`` (a policy face over a batch law that keeps its gimbal commands, as
    :class:`.pid.PIDPolicy` and :class:`.pid.GainScheduledPIDPolicy`, or such a batch law itself): one row of
    :class:`AACLaw`. ``record``: keep ``history`` (time, on, k_T per axis, the dead-zoned error, the spectral
    damper output) of the last episode (:meth:`trajectory`)."""

    def __init__(self, base: Any, *, env: Any, params: AACParams | None = None, name: str | None = None,
                 record: bool = False) -> None:
        law = getattr(base, "law", base)
        self.law = AACLaw(law, env=env, params=params, name=name or f"aac({getattr(base, 'name', 'base')})")
        self.record = bool(record)
        self.history: list[tuple[float, ...]] = []
        self._i_on = env.unwrapped.observation_layout.index("controller_on")

    @property
    def k_T(self) -> np.ndarray:
        """The current forward-loop gain of each axis (pitch, yaw)."""
        return self.law.gains([0])[0]

    @property
    def last_gimbal(self) -> np.ndarray:
        return self.law.gimbal[0].copy()

    def reset(self) -> None:
        super().reset()
        self.history = []

    def act(self, observation: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        action = super().act(observation, info)
        if self.record:
            on = float(np.asarray(observation)[self._i_on]) >= 0.5
            self.history.append((float(info.get("time", math.nan)), float(on), *self.law.gains([0])[0],
                                 *self.law.errors([0])[0], *self.law.damper([0])[0]))
        return action

    def batch(self, n: int) -> AACLaw:
        """The law for ``n`` rows (it keeps no ``history``)."""
        return self.law.batch(n)

    def trajectory(self) -> dict[str, np.ndarray]:
        """The recorded history as arrays: ``time``, ``on``, ``k`` (n, 2), ``e`` (n, 2), ``y`` (n, 2)."""
        h = np.array(self.history, dtype=float).reshape(-1, 8)
        return {"time": h[:, 0], "on": h[:, 1] > 0.5, "k": h[:, 2:4], "e": h[:, 4:6], "y": h[:, 6:8]}


# ---------------------------------------------------------------------------- presets
def _check_keywords(params: dict[str, Any]) -> None:
    """Refuse a keyword that is not a field of :class:`AACParams`, naming it and the allowed ones."""
    known = {f.name for f in fields(AACParams)}
    for key, value in params.items():
        if key not in known:
            raise ConfigError(f"aac.{key}", value, f"not a parameter of the adaptive law; one of {sorted(known)}")


def smile_aac(env: Any, schedule: str = "smile", name: str = "aac", record: bool = False,
              **params: Any) -> AdaptiveAugmentingPolicy:
    """AAC on the gain-scheduled PID of ``baselines/schedules/<schedule>.yaml`` (``gs-pid``: ``smile``)
    flying ``env``; keywords of :class:`AACParams` override the defaults. One PolicySpec line wires it:
    ``PolicySpec("aac", "lvgym.baselines.aac:smile_aac", (("name", "aac"), ("schedule", "smile")))``."""
    _check_keywords(params)
    base = smile_scheduled_pid(env, schedule, name=f"gs-pid-{schedule}")
    return AdaptiveAugmentingPolicy(base, env=env, params=AACParams(**params), name=name, record=record)


#: the law's parameters on ``gs-pid-flex`` (docs/adaptive-control.md, "On gs-pid-flex"; tuned on smile-v1's
#: validation seeds 0-9): the defaults with a spectral-damper dead zone, so that the flex design's own
#: high-frequency content (its lead, staging, gusts) does not lower k_T
FLEX_AAC = {"damper_deadzone_rad2": 3e-3}
#: the fused AAC and PID act, through its entry point (:meth:`lvgym.simulator.threads.Kernel.keyed`; key: the
#: observations' dtype and writability, the rest of its arguments' types fixed by :meth:`AACLaw.act`)
_AAC_PID = Kernel(aac_pid_act_k)


def flex_aac(env: Any, name: str = "aac", record: bool = False, schedule: str | None = None, quiet: bool = False,
             **params: Any) -> AdaptiveAugmentingPolicy:
    """``aac``: AAC on ``gs-pid-flex`` (:func:`.pid.flex_pid`: the vehicle's flex schedule, its quiet one with
    ``quiet``, or ``schedule``) with :data:`FLEX_AAC`; keywords of :class:`AACParams` override them."""
    _check_keywords(params)
    return AdaptiveAugmentingPolicy(flex_pid(env, schedule=schedule, quiet=quiet), env=env, params=AACParams(**{**FLEX_AAC, **params}), name=name,
                                    record=record)
