"""The compiled step of adaptive augmenting control (:mod:`.aac`) for any number of rows: the inner loop of
:class:`.aac.AACLaw`, after its base law has acted.

:func:`aac_act_k` takes each row's base command and steps the adaptive law of the module docstring of
:mod:`.aac`: the reference model, the error's low-pass and dead zone, the exact step of ``k_T``
(:func:`gain_step_k`, ``math.exp``), the command ``clip(k_T u)``, the spectral damper. The blocks:
:class:`AACConsts` (the law's constants) and each row's state packed by :data:`AAC_ROW`. The three
first-order filters of a row (:func:`first_order`) restart and step together (one ``fresh`` flag per row)::

{AAC_ROW}
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from lvgym.packing import Field, Packed

from .pidkernel import AXES, P, clip_k, pid_row_k

__all__ = ["AACConsts", "AAC_ROW", "aac_act_k", "aac_pid_act_k", "dead_zone", "first_order", "gain_step_k"]

#: a row of the adaptive law (per axis: pitch, yaw)
AAC_ROW = Packed("adaptive law row", [
    Field("k", AXES, "-", "k_T per axis (a shared gain in the first entry)"),
    Field("w_m", 1, "rad/s", "the reference model's pitch rate"),
    Field("on", 1, "-", "1: engaged"),
    Field("fresh", 1, "-", "1: the filters' next sample is their first"),
    Field("e_y", AXES, "rad/s", "the error low-pass's output"),
    Field("e_x", AXES, "rad/s", "the error low-pass's last input"),
    Field("hp_y", AXES, "rad", "the spectral damper's high-pass output"),
    Field("hp_x", AXES, "rad", "the spectral damper's high-pass last input (the command sent)"),
    Field("lp_y", AXES, "rad^2", "the spectral damper's output y"),
    Field("lp_x", AXES, "rad^2", "the spectral damper's low-pass last input"),
    Field("gimbal", AXES, "rad", "the last command sent"),
])

__doc__ = __doc__.format(AAC_ROW=AAC_ROW.table())

A = AAC_ROW.at


def first_order(kind: str, cutoff_hz: float, dt: float) -> tuple[float, float]:
    """``(pole, gain)`` of the first-order filter ``w/(s+w)`` (``kind="low"``) or ``s/(s+w)`` (``"high"``) at
    ``cutoff_hz`` [Hz], Tustin's transform pre-warped at ``w`` for the period ``dt`` [s]:
    ``y[n] = pole y[n-1] + gain (x[n] + x[n-1])`` (low) or ``gain (x[n] - x[n-1])`` (high). A restart makes the
    next sample the first: the low-pass starts from 0 (the previous input 0), the high-pass outputs 0."""
    if kind not in ("low", "high"):
        raise ValueError(f"kind = {kind!r}: 'low' or 'high'")
    w = 2.0 * math.pi * cutoff_hz
    k = w / math.tan(w * dt / 2.0)                    # pre-warped 2/dt
    return (k - w) / (k + w), (w if kind == "low" else k) / (k + w)


def dead_zone(e: np.ndarray, dz: float) -> np.ndarray:
    """``sign(e) max(|e| - dz, 0)`` [rad/s]: the error the law's ``a e^2`` term sees."""
    return np.sign(e) * np.maximum(np.abs(e) - dz, 0.0)


class AACConsts(NamedTuple):
    """The constants of the adaptive law (:mod:`.aac`): the bounds of ``k_T``, the rates ``a`` (error),
    ``b`` (damper), ``c`` (leakage), the dead zones ``e_dz`` [rad/s] and ``y_dz`` [rad^2], ``dt`` [s], the
    gimbal ``limit`` [rad], the reference model's ``p_ref``, ``per_axis``, ``reset_on_engage``, and each
    filter's ``pole`` and ``gain`` (error low-pass ``e_``, damper high-pass ``hp_`` and low-pass ``lp_``)."""

    k_min: float
    k_max: float
    a: float
    b: float
    c: float
    e_dz: float
    y_dz: float
    dt: float
    limit: float
    p_ref: float
    per_axis: bool
    reset_on_engage: bool
    e_pole: float
    e_gain: float
    hp_pole: float
    hp_gain: float
    lp_pole: float
    lp_gain: float


@nb.njit(cache=True, inline="always")
def gain_step_k(law, k, e2, y):
    """One exact (zero-order-hold) step of ``dk/dt = a e2 - b y (k - k_min) - c (k - 1)`` over ``law.dt``,
    clipped to ``[k_min, k_max]``; the decay ``exp(-r dt)`` is ``math.exp`` (the C library's)."""
    r = law.b * y + law.c
    drive = law.a * e2 + law.b * y * law.k_min + law.c
    if r > 0.0:
        k_inf = drive / r
        k_new = k_inf + (k - k_inf) * math.exp(-r * law.dt)
    else:
        k_new = k + drive * law.dt
    return clip_k(k_new, law.k_min, law.k_max)


@nb.njit(cache=True, inline="always")
def _dead_zone_sq(e_f, dz):
    """``(sign(e_f) max(|e_f| - dz, 0))^2`` as numpy computes it."""
    m = abs(e_f) - dz
    if not (m >= 0.0 or np.isnan(m)):
        m = 0.0
    s = 1.0 if e_f > 0.0 else (-1.0 if e_f < 0.0 else (0.0 if e_f == 0.0 else e_f))
    e = s * m
    return e * e


@nb.njit(cache=True, inline="always")
def _damped(law, y):
    """The damper output beyond its dead zone (``max(y - y_dz, 0)``; ``y`` without one)."""
    if law.y_dz > 0.0:
        v = y - law.y_dz
        return v if (v >= 0.0 or np.isnan(v)) else 0.0
    return y


@nb.njit(cache=True, inline="always")
def _law_row(law, w, u0, u1, ref, re0, re1, on):
    """One step of the law row ``w`` on the base's commands ``u0``, ``u1`` [rad], the pitch rate reference
    ``ref`` and the rate errors ``re0``, ``re1`` [rad/s]: the commands sent into ``w[A.gimbal:]``
    (the adaptive law of :mod:`.aac`)."""
    if not on:
        w[A.on] = 0.0
        w[A.gimbal], w[A.gimbal + 1] = 0.0, 0.0
        return
    if w[A.on] == 0.0:                                 # engagement: the filters restart
        for ax in range(AXES):
            w[A.e_y + ax], w[A.e_x + ax], w[A.hp_y + ax], w[A.hp_x + ax] = 0.0, 0.0, 0.0, 0.0
            w[A.lp_y + ax], w[A.lp_x + ax] = 0.0, 0.0
            if law.reset_on_engage:
                w[A.k + ax] = 1.0
        w[A.fresh], w[A.w_m] = 1.0, 0.0
        w[A.on] = 1.0
    w[A.w_m] = law.p_ref * w[A.w_m] + (1.0 - law.p_ref) * ref
    fresh = w[A.fresh] != 0.0
    e = (w[A.w_m] - ref) - re0                         # the reference model and reference of pitch only
    prev = 0.0 if fresh else w[A.e_x]
    ef0 = law.e_pole * w[A.e_y] + law.e_gain * (e + prev)
    w[A.e_y], w[A.e_x] = ef0, e
    e = (0.0 - 0.0) - re1
    prev = 0.0 if fresh else w[A.e_x + 1]
    ef1 = law.e_pole * w[A.e_y + 1] + law.e_gain * (e + prev)
    w[A.e_y + 1], w[A.e_x + 1] = ef1, e
    e20, e21 = _dead_zone_sq(ef0, law.e_dz), _dead_zone_sq(ef1, law.e_dz)
    y0, y1 = _damped(law, w[A.lp_y]), _damped(law, w[A.lp_y + 1])
    if law.per_axis:
        w[A.k] = gain_step_k(law, w[A.k], e20, y0)
        w[A.k + 1] = gain_step_k(law, w[A.k + 1], e21, y1)
    else:
        w[A.k] = gain_step_k(law, w[A.k], e20 + e21, y0 + y1)
    for ax in range(AXES):
        k = w[A.k + ax] if law.per_axis else w[A.k]
        cmd = clip_k(k * (u0 if ax == 0 else u1), -law.limit, law.limit)
        prev = cmd if fresh else w[A.hp_x + ax]
        h = law.hp_pole * w[A.hp_y + ax] + law.hp_gain * (cmd - prev)
        w[A.hp_y + ax], w[A.hp_x + ax] = h, cmd
        sq = h * h
        prev = 0.0 if fresh else w[A.lp_x + ax]
        w[A.lp_y + ax] = law.lp_pole * w[A.lp_y + ax] + law.lp_gain * (sq + prev)
        w[A.lp_x + ax] = sq
        w[A.gimbal + ax] = cmd
    w[A.fresh] = 0.0


@nb.njit(cache=True)
def aac_act_k(law, oc, rows_law, rows, u, obs, out):
    """The actions ``out`` (k, 2) float32 of the rows ``rows`` (k,): each row's base commands ``u[j]`` [rad]
    scaled by its adaptive law (``law``; its row of ``rows_law``, layout :data:`AAC_ROW`) on its observation
    ``obs[j]`` (``oc``: the rate errors, the pitch rate reference, the controller flag); gimbal / limit,
    clipped."""
    err = oc.err
    for j in range(rows.size):
        w, o = rows_law[rows[j]], obs[j]
        _law_row(law, w, u[j, 0], u[j, 1], float(o[oc.ref]), float(o[err[0]]), float(o[err[1]]),
                 float(o[oc.on]) >= 0.5)
        for ax in range(AXES):
            out[j, ax] = np.float32(clip_k(w[A.gimbal + ax] / law.limit, -1.0, 1.0))


@nb.njit(cache=True)
def aac_pid_act_k(tb, su, oc_pid, st, law, oc, rows_law, rows, obs, value, out):
    """:func:`aac_act_k` around the PID family's law in one call: each row of ``rows`` steps its PID
    (:func:`.pidkernel.pid_row_k` on ``tb``, ``su``, ``oc_pid``, the state ``st``, the scheduling values
    ``value``) and then its adaptive law (``law``, ``oc``, ``rows_law``) on the PID's command, the actions into
    ``out`` (k, 2) float32: the same numbers as :meth:`.pid.PIDLaw.act` followed by :func:`aac_act_k`."""
    err = oc.err
    pid, filters = st.pid, st.filters
    for j in range(rows.size):
        b = rows[j]
        r, w, o = pid[b], rows_law[b], obs[j]
        pid_row_k(tb, su, oc_pid, r, filters[b], o, value[b])
        _law_row(law, w, r[P.gimbal], r[P.gimbal + 1], float(o[oc.ref]), float(o[err[0]]), float(o[err[1]]),
                 float(o[oc.on]) >= 0.5)
        for ax in range(AXES):
            out[j, ax] = np.float32(clip_k(w[A.gimbal + ax] / law.limit, -1.0, 1.0))
