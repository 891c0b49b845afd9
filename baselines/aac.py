"""Adaptive augmenting control (AAC) in the manner of the SLS flight control: a bounded multiplicative
forward-loop gain ``k_T`` per axis on a classical (PID-type) baseline, as benchmark policies.

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
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from lvgym.errors import ConfigError, check_bool, check_number

from .aacbatch import AACBatch
from .batch import RowCopies
from .pid import PIDPolicy, flex_pid, smile_scheduled_pid

__all__ = ["AACParams", "AdaptiveAugmentingPolicy", "AdaptiveGainLaw", "FLEX_AAC", "FirstOrderFilter", "flex_aac", "smile_aac"]


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


class FirstOrderFilter:
    """``w/(s+w)`` (``kind="low"``) or ``s/(s+w)`` (``"high"``), Tustin's transform pre-warped at ``w``,
    on arrays of channels: ``step(x) -> y``; ``restart()`` makes the next sample the first (the high-pass
    then outputs 0 for it, the low-pass starts from 0)."""

    def __init__(self, kind: str, cutoff_hz: float, dt: float, channels: int) -> None:
        if kind not in ("low", "high"):
            raise ValueError(f"kind = {kind!r}: 'low' or 'high'")
        w = 2.0 * math.pi * cutoff_hz
        k = w / math.tan(w * dt / 2.0)                # pre-warped 2/dt
        self.kind = kind
        self.pole = (k - w) / (k + w)                 # y[n] = pole y[n-1] + gain (x[n] +- x[n-1])
        self.gain = (w if kind == "low" else k) / (k + w)
        self.y = np.zeros(channels)
        self.x_prev = np.zeros(channels)
        self.fresh = True

    def restart(self) -> None:
        self.y[:] = 0.0
        self.x_prev[:] = 0.0
        self.fresh = True

    def step(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if self.kind == "high":
            prev = x if self.fresh else self.x_prev
            self.y = self.pole * self.y + self.gain * (x - prev)
        else:
            prev = np.zeros_like(x) if self.fresh else self.x_prev
            self.y = self.pole * self.y + self.gain * (x + prev)
        self.x_prev = x.copy()
        self.fresh = False
        return self.y.copy()


class AdaptiveGainLaw:
    """The adaptive law of the module docstring without a vehicle: ``step(u, rate_error, rate_ref, on)
    -> command``, arrays over the axes, in the base's units (gimbal rad)."""

    def __init__(self, params: AACParams, dt: float, limit: float, axes: int = 2) -> None:
        params.check_rate(dt)
        self.p, self.dt, self.limit, self.axes = params, float(dt), float(limit), int(axes)
        self.n_gains = axes if params.per_axis else 1
        self.p_ref = math.exp(-params.ref_model_radps * dt)
        self.e_lp = FirstOrderFilter("low", params.error_lp_hz, dt, axes)
        self.hp = FirstOrderFilter("high", params.damper_hp_hz, dt, axes)
        self.lp = FirstOrderFilter("low", params.damper_lp_hz, dt, axes)
        self.reset()

    def reset(self) -> None:
        self.k = np.ones(self.n_gains)
        self.w_m = 0.0                                # reference model's pitch rate [rad/s]
        self.on = False
        self.e = np.zeros(self.axes)                  # dead-zoned, filtered error [rad/s]
        self.y = np.zeros(self.axes)                  # spectral damper output [rad^2]
        for f in (self.e_lp, self.hp, self.lp):
            f.restart()

    def engage(self) -> None:
        """The loop switches on: filters restart (and k returns to 1 with ``reset_on_engage``)."""
        for f in (self.e_lp, self.hp, self.lp):
            f.restart()
        self.y[:] = 0.0
        self.e[:] = 0.0
        self.w_m = 0.0
        if self.p.reset_on_engage:
            self.k[:] = 1.0

    def gain_step(self, k: np.ndarray, e2: np.ndarray, y: np.ndarray) -> np.ndarray:
        """One exact (zero-order-hold) step of ``dk/dt = a e2 - b y (k - k_min) - c (k - 1)``, clipped. The
        decay ``exp(-r dt)`` is ``math.exp`` (the C library's), as the compiled batch
        (:mod:`.aacbatch`) computes it: numpy's own ``exp`` of float arrays differs from it in the last bit
        for a few per cent of arguments on CPUs with AVX-512."""
        p = self.p
        r = p.damper_gain * y + p.leak_rate
        drive = p.error_gain * e2 + p.damper_gain * y * p.k_min + p.leak_rate
        decay = np.array([math.exp(-v * self.dt) if v > 0.0 else 1.0 for v in np.ravel(r)]).reshape(np.shape(r))
        with np.errstate(divide="ignore", invalid="ignore"):
            k_inf = np.where(r > 0.0, drive / np.where(r > 0.0, r, 1.0), 0.0)
            k_new = np.where(r > 0.0, k_inf + (k - k_inf) * decay, k + drive * self.dt)
        return np.clip(k_new, p.k_min, p.k_max)

    def step(self, u: np.ndarray, rate_error: np.ndarray, rate_ref: np.ndarray, on: bool) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        if not on:
            self.on = False
            return np.zeros(self.axes)
        if not self.on:
            self.engage()
            self.on = True
        p = self.p
        ref = np.asarray(rate_ref, dtype=float)
        self.w_m = self.p_ref * self.w_m + (1.0 - self.p_ref) * float(ref[0])
        model = np.zeros(self.axes)
        model[0] = self.w_m
        e = (model - ref) - np.asarray(rate_error, dtype=float)
        e_f = self.e_lp.step(e)
        self.e = np.sign(e_f) * np.maximum(np.abs(e_f) - p.error_deadzone_radps, 0.0)
        e2, y = self.e ** 2, self.y
        if p.damper_deadzone_rad2 > 0.0:
            y = np.maximum(y - p.damper_deadzone_rad2, 0.0)
        if not p.per_axis:
            e2, y = np.array([e2.sum()]), np.array([y.sum()])
        self.k = self.gain_step(self.k, e2, y)
        command = np.clip(self.gains() * u, -self.limit, self.limit)
        self.y = self.lp.step(self.hp.step(command) ** 2)
        return command

    def gains(self) -> np.ndarray:
        """k_T of each axis."""
        return self.k if self.p.per_axis else np.repeat(self.k, self.axes)


class AdaptiveAugmentingPolicy:
    """AAC around a PID-type baseline policy ``base`` (a benchmark Policy with ``last_gimbal`` [rad] per
    axis after ``act``, ``dt`` [s] and ``limit`` [rad], as :class:`lvgym.baselines.pid.PIDPolicy` and its
    subclasses): the base flies as designed and its command is multiplied by ``k_T`` per axis.

    ``env``: the lvgym env (its observation layout: ``pitch_rate_error``, ``yaw_rate_error``,
    ``pitch_rate_reference``, ``controller_on``). ``record``: keep ``history`` (time, k_T per axis, the
    dead-zoned error, the spectral damper output) of the last episode.
    """

    def __init__(self, base: Any, *, env: Any, params: AACParams | None = None, name: str | None = None,
                 record: bool = False) -> None:
        task = env.unwrapped
        lay = task.observation_layout
        self.base = base
        self.params = params or AACParams()
        self.name = name or f"aac({getattr(base, 'name', 'base')})"
        self.dt = float(getattr(base, "dt", task.task.control_dt_s))
        self.limit = float(getattr(base, "limit", task.gimbal_limit))
        self._i_err = [lay.index("pitch_rate_error"), lay.index("yaw_rate_error")]
        self._i_ref = lay.index("pitch_rate_reference")
        self._i_on = lay.index("controller_on")
        self.law = AdaptiveGainLaw(self.params, self.dt, self.limit, axes=2)
        self.record = bool(record)
        self.history: list[tuple[float, ...]] = []
        self.last_gimbal = np.zeros(2)

    @property
    def k_T(self) -> np.ndarray:
        """The current forward-loop gain of each axis (pitch, yaw)."""
        return self.law.gains().copy()

    def reset(self) -> None:
        self.base.reset()
        self.law.reset()
        self.history = []
        self.last_gimbal = np.zeros(2)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        self.base.act(observation, info)
        u = np.asarray(self.base.last_gimbal, dtype=float)
        on = float(obs[self._i_on]) >= 0.5
        ref = np.array([obs[self._i_ref], 0.0])
        self.last_gimbal = self.law.step(u, obs[self._i_err], ref, on)
        if self.record:
            k = self.law.gains()
            self.history.append((float(info.get("time", math.nan)), float(on), *k, *self.law.e, *self.law.y))
        return np.clip(self.last_gimbal / self.limit, -1.0, 1.0).astype(np.float32)

    def batch(self, n: int) -> AACBatch | RowCopies:
        """The same controller for ``n`` rows of a batched env, stepped together (:mod:`.batch`): the compiled
        :class:`.aacbatch.AACBatch` on a PID-family base it knows (:meth:`.pid.PIDPolicy.batch`), else one
        copy of the policy per row. The batch keeps no ``history``."""
        known = type(self) is AdaptiveAugmentingPolicy and isinstance(self.base, PIDPolicy) and self.base._batchable()
        return AACBatch(self, n) if known else RowCopies(self, n)

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


def flex_aac(env: Any, name: str = "aac", record: bool = False, schedule: str | None = None, quiet: bool = False,
             **params: Any) -> AdaptiveAugmentingPolicy:
    """``aac``: AAC on ``gs-pid-flex`` (:func:`.pid.flex_pid`: the vehicle's flex schedule, its quiet one with
    ``quiet``, or ``schedule``) with :data:`FLEX_AAC`; keywords of :class:`AACParams` override them."""
    _check_keywords(params)
    return AdaptiveAugmentingPolicy(flex_pid(env, schedule=schedule, quiet=quiet), env=env, params=AACParams(**{**FLEX_AAC, **params}), name=name,
                                    record=record)
