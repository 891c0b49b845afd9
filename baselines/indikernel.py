"""The compiled act of ``indi`` (:mod:`.indi`, incremental nonlinear dynamic inversion) for any number of rows: the
inner loop of :class:`.indi.INDILaw`, one row after the other, each row's operations its own (a batch of one gives
the bits of the same row of any batch, ``tests/test_policy_batch.py``). The blocks:

* :class:`INDIFilter`: the structural filter ``H`` of a schedule row (a second-order low-pass, a notch on the first
  bending mode and one on the slosh band), discretised as the PID family's filters are (Tustin, prewarped,
  :meth:`.filters.StructuralFilter.discrete`) and run by the same sections (:func:`.pidkernel.filter_update_k`);
* :class:`INDITable`: per schedule row its time, gains and the discrete filters (layout
  :data:`.pidkernel.COEFFS`: ``H`` for the gyro rate, the reference and the accelerometers; ``H`` and the
  synchronisation sections for the actuator position), and the control-power table over flight time;
* :class:`INDISetup`: the constants (control period, gimbal limit, mission time, sections in use, load-relief signs);
* :class:`INDIState`: each row's state, a packed vector (:data:`INDI_ROW`) and four filter rows
  (:data:`.pidkernel.FILTER_ROW`, two axes each): the gyro rate, the actuator position, the reference (axis 0)
  and the accelerometers.

The row layout::

{INDI_ROW}
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from lvgym.envs.layouts import G0
from lvgym.packing import Field, Packed

from .filters import StructuralFilter, _sections_tf
from .pidkernel import (COEFFS, FILTER_ROW, SECTIONS, clip_k, coefficients, filter_reset_k, filter_update_k,
                        interp_k, nearest_k)

__all__ = ["INDIFilter", "INDISetup", "INDIState", "INDITable", "INDI_ROW", "SIGNALS", "SyncSections", "indi_act_k",
           "indi_row_k", "new_state"]

AXES = 2
#: the filter rows of a row, in order: gyro rate, actuator position, reference (axis 0), accelerometers
SIGNALS = ("rate", "actuator", "reference", "accel")
S_RATE, S_ACT, S_REF, S_ACC = 0, 1, 2, 3

#: a row's law state
INDI_ROW = Packed("INDI row", [
    Field("rate_f", AXES, "rad/s", "the filtered gyro rate (rate error plus reference) of the last step, per axis"),
    Field("ref_f", 1, "rad/s", "the filtered pitch rate reference of the last step"),
    Field("running", 1, "-", "1: the filters run (since the controller switched on)"),
    Field("sched", 1, "-", "the schedule row whose filters are in use (-1: none yet)"),
    Field("accel_f", AXES, "rad/s^2", "the last filtered angular acceleration per axis"),
    Field("nu", AXES, "rad/s^2", "the last commanded angular acceleration per axis"),
    Field("gimbal", AXES, "rad", "the last command per axis"),
])
__doc__ = __doc__.format(INDI_ROW=INDI_ROW.table())
R = INDI_ROW.at
F = FILTER_ROW.at
#: entries of a filter's coefficients (a compiled constant)
N_COEFFS = COEFFS.size


@dataclass(frozen=True)
class INDIFilter:
    """The structural filter ``H`` [rad/s, -]: a second-order low-pass ``w_l^2 / (s^2 + 2 z_l w_l s + w_l^2)`` and
    notches ``(s^2 + 2 r z w s + w^2) / (s^2 + 2 z w s + w^2)`` on the first bending mode and on the slosh band
    (``*_radps`` None: that notch off), all of unit gain at zero frequency."""

    lowpass_radps: float
    lowpass_damping: float = 0.7
    bending_radps: float | None = None
    bending_damping: float = 0.5
    bending_depth: float = 0.02
    slosh_radps: float | None = None
    slosh_damping: float = 0.5
    slosh_depth: float = 0.1

    def __post_init__(self) -> None:
        for key in ("lowpass_radps", "lowpass_damping", "bending_radps", "bending_damping", "bending_depth",
                    "slosh_radps", "slosh_damping", "slosh_depth"):
            v = getattr(self, key)
            if v is None and key in ("bending_radps", "slosh_radps"):
                continue
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"filter.{key} = {v!r}: a finite number > 0")
            if key.endswith("depth") and v > 1.0:
                raise ValueError(f"filter.{key} = {v!r}: the notch's gain at its centre, in (0, 1]")

    def as_dict(self) -> dict[str, float | None]:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    @classmethod
    def from_dict(cls, data: dict, key: str = "filter") -> "INDIFilter":
        unknown = sorted(set(data) - set(cls.__dataclass_fields__))
        if unknown:
            from lvgym.errors import ConfigError
            raise ConfigError(f"{key}.{unknown[0]}", data[unknown[0]],
                              f"not a filter key; allowed: {', '.join(cls.__dataclass_fields__)}")
        return cls(**{k: (None if v is None else float(v)) for k, v in data.items()})

    def discrete(self, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """The sections in ``z`` at ``dt`` [s] (:meth:`.filters.StructuralFilter.discrete`: the low-pass, then
        each notch in use)."""
        out = [StructuralFilter(lowpass_radps=self.lowpass_radps, lowpass_damping=self.lowpass_damping).discrete(dt)[1]]
        for w, z, r in ((self.bending_radps, self.bending_damping, self.bending_depth),
                        (self.slosh_radps, self.slosh_damping, self.slosh_depth)):
            if w is not None:
                out.append(StructuralFilter(notch_radps=w, notch_damping=z, notch_depth=r).discrete(dt)[2])
        return out

    def tf(self, dt: float) -> Any:
        """The discrete filter as a python-control transfer function (design tools)."""
        return _sections_tf(self.discrete(dt), dt, "INDIFilter.tf")


@dataclass(frozen=True)
class SyncSections:
    """What the actuator position passes besides ``H``, so that it is in step with the angular acceleration (the
    synchronisation of Smeur, Chu & de Croon 2016): the gyro's anti-aliasing low-pass (``antialias_radps``,
    ``antialias_damping``: the IMU's, design data; 0: none) and the mean of the last two samples (``average``:
    the backward difference of the sampled rate is the mean acceleration over the last period, half a period
    behind the position sampled at its end)."""

    antialias_radps: float = 0.0
    antialias_damping: float = 1.0 / math.sqrt(2.0)
    average: bool = True

    def discrete(self, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
        out = []
        if self.antialias_radps > 0.0:
            out.append(StructuralFilter(lowpass_radps=self.antialias_radps,
                                        lowpass_damping=self.antialias_damping).discrete(dt)[1])
        if self.average:
            out.append((np.array([0.5, 0.5, 0.0]), np.array([1.0, 0.0, 0.0])))
        return out

    def tf(self, dt: float) -> Any:
        import control
        if not self.discrete(dt):
            return control.tf([1.0], [1.0], dt)
        return _sections_tf(self.discrete(dt), dt, "SyncSections.tf")


class _Sections:
    """Sections in series (``discrete(dt)`` only): what :func:`.pidkernel.coefficients` packs."""

    def __init__(self, sections: list[tuple[np.ndarray, np.ndarray]]) -> None:
        self.sections = sections

    def discrete(self, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
        return self.sections


class INDITable(NamedTuple):
    """A schedule of ``m`` rows: ``t`` (m,) [s] their flight times (ascending), ``gains`` (3, m) the rate
    [1/s], attitude [1/s] and load-relief [rad/s per m/s^2] gains, ``coeffs`` (2, m, COEFFS.size) the discrete
    ``H`` and ``H`` with the synchronisation sections, ``sections`` (2, m) how many sections of each are in use;
    ``power_t`` (p,) [s] and ``power`` (p,) [1/s^2] the control power over flight time (linear between, ends held)."""

    t: np.ndarray
    gains: np.ndarray
    coeffs: np.ndarray
    sections: np.ndarray
    power_t: np.ndarray
    power: np.ndarray


class INDISetup(NamedTuple):
    """The constants: ``dt`` [s], ``limit`` [rad] the gimbal limit, ``mission`` [s] (the observation's time
    fraction times it is the flight time), ``signs`` (2,) the load-relief signs per axis (:data:`.pid.ACCEL_SIGNS`),
    ``accel`` (the load relief on)."""

    dt: float
    limit: float
    mission: float
    signs: np.ndarray
    accel: bool


class INDIObs(NamedTuple):
    """Indices into an observation row: ``err`` (2,) rate errors, ``att`` (2,) attitude errors, ``acc`` (2,)
    accelerometers (``accel_z``, ``accel_y``), ``act`` (2,) actuator positions, ``on``, ``time`` (time fraction),
    ``ref`` the pitch rate reference."""

    err: np.ndarray
    att: np.ndarray
    acc: np.ndarray
    act: np.ndarray
    on: int
    time: int
    ref: int


class INDIState(NamedTuple):
    """The state of ``n`` rows: ``law`` (n, INDI_ROW.size), ``filters`` (n, 4, FILTER_ROW.size)."""

    law: np.ndarray
    filters: np.ndarray


def filter_coeffs(filt: INDIFilter, sync: SyncSections, dt: float) -> tuple[np.ndarray, int, int]:
    """``(coeffs (2, COEFFS.size), sections of H, sections of H with sync)`` of one schedule row."""
    h = filt.discrete(dt)
    hs = h + sync.discrete(dt)
    if len(hs) > SECTIONS:
        raise ValueError(f"{len(hs)} filter sections: the kernel runs at most {SECTIONS}")
    return np.stack([coefficients(_Sections(h), dt), coefficients(_Sections(hs), dt)]), len(h), len(hs)


def new_state(n: int) -> INDIState:
    """The state of ``n`` rows as after a reset (no schedule row in use yet; coefficient sums 1)."""
    filters = FILTER_ROW.pack({"bsum": 1.0, "asum": 1.0}, 4 * n).reshape(n, 4, -1)
    return INDIState(INDI_ROW.pack({"sched": -1.0}, n), filters)


@nb.njit(cache=True)
def indi_row_k(tb, su, oc, r, f, obs):
    """One act of a row (its law row ``r``, filter rows ``f`` (4, FILTER_ROW.size)) on its observation ``obs``:
    the commands [rad] into ``r[R.gimbal:]`` (the law of :mod:`.indi`)."""
    on = float(obs[oc.on]) >= 0.5
    t = float(obs[oc.time]) * su.mission
    i = nearest_k(tb.t, t)
    if i != r[R.sched]:                                   # another row's filters: their coefficients
        for s in range(4):
            which = 1 if s == S_ACT else 0
            for c in range(N_COEFFS):
                f[s, F.coeffs + c] = tb.coeffs[which, i, c]
        r[R.sched] = i
    if not on:
        r[R.running] = 0.0
        for ax in range(AXES):
            r[R.gimbal + ax], r[R.nu + ax], r[R.accel_f + ax] = 0.0, 0.0, 0.0
        return
    G = interp_k(t, tb.power_t, tb.power)
    k_rate, k_att, k_acc = tb.gains[0, i], tb.gains[1, i], tb.gains[2, i]
    nh, na = tb.sections[0, i], tb.sections[1, i]
    ref = float(obs[oc.ref]) if oc.ref >= 0 else 0.0
    start = r[R.running] == 0.0
    if start:                                             # switched on: every filter in the steady state of its input
        filter_reset_k(f[S_REF], 0, ref, nh)
    ref_f = filter_update_k(f[S_REF], 0, ref, nh)
    ref_dot = 0.0 if start else (ref_f - r[R.ref_f]) / su.dt
    r[R.ref_f] = ref_f
    for ax in range(AXES):
        e = float(obs[oc.err[ax]])
        rate = e + (ref if ax == 0 else 0.0)              # the gyro: the rate error plus the reference
        pos = float(obs[oc.act[ax]]) * su.limit           # the actuator position [rad]
        lr = 0.0
        if su.accel:
            lr = su.signs[ax] * G0 * float(obs[oc.acc[ax]])
        if start:
            filter_reset_k(f[S_RATE], ax, rate, nh)
            filter_reset_k(f[S_ACT], ax, pos, na)
            filter_reset_k(f[S_ACC], ax, lr, nh)
        rate_f = filter_update_k(f[S_RATE], ax, rate, nh)
        pos_f = filter_update_k(f[S_ACT], ax, pos, na)
        lr_f = filter_update_k(f[S_ACC], ax, lr, nh)
        acc = 0.0 if start else (rate_f - r[R.rate_f + ax]) / su.dt
        r[R.rate_f + ax] = rate_f
        rate_cmd = -k_att * float(obs[oc.att[ax]]) + k_acc * lr_f          # the outer loops' rate command
        nu = k_rate * (rate_cmd - e) + (ref_dot if ax == 0 else 0.0)       # commanded angular acceleration
        u = pos_f + (nu - acc) / G                                         # the increment on the position
        r[R.accel_f + ax], r[R.nu + ax] = acc, nu
        r[R.gimbal + ax] = clip_k(u, -su.limit, su.limit)
    r[R.running] = 1.0


@nb.njit(cache=True)
def indi_act_k(tb, su, oc, st, rows, obs, out):
    """The actions ``out`` (k, 2) float32 of the rows ``rows`` (k,) for their observations ``obs`` (k, n_obs):
    gimbal / limit in [-1, 1]."""
    law, filters = st.law, st.filters
    for j in range(rows.size):
        b = rows[j]
        r = law[b]
        indi_row_k(tb, su, oc, r, filters[b], obs[j])
        for ax in range(AXES):
            out[j, ax] = np.float32(clip_k(r[R.gimbal + ax] / su.limit, -1.0, 1.0))
