"""Adaptive augmenting control for the rows of a batched env (:class:`AACBatch`): what
:meth:`.aac.AdaptiveAugmentingPolicy.batch` gives for an AAC on a PID-family base.

One compiled call (:func:`aac_act_k`) steps each row's base (:func:`.pidkernel.pid_row_k`) and then the
adaptive law of :class:`.aac.AdaptiveGainLaw` with the per-row policy's operations in its order: the
reference model, the error's low-pass and dead zone, the exact step of ``k_T`` (``math.exp``, as the
per-row law), the command ``clip(k_T u)``, the spectral damper. The blocks: :class:`AACLaw` (the law's
constants) and :class:`AACState` (each row's ``k_T``, reference model, filters), beside the base's blocks
of :mod:`.pidkernel`. The three first-order filters of a row restart and step together (one ``fresh``
flag per row).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from .pidbatch import PIDBatch
from .pidkernel import clip_k, pid_row_k

__all__ = ["AACBatch", "AACLaw", "AACState", "aac_act_k"]


class AACLaw(NamedTuple):
    """The constants of :class:`.aac.AdaptiveGainLaw`: the bounds of ``k_T``, the rates ``a`` (error),
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


class AACState(NamedTuple):
    """The law's state of ``n`` rows: ``k`` (n, 2) ``k_T`` per axis (a shared gain in column 0), ``w_m``
    (n,) the reference model's rate [rad/s], ``on`` (n,) engaged, ``fresh`` (n,) the filters' next sample
    is their first; per axis (n, 2): the error low-pass's output and last input (``e_y``, ``e_x``), the
    damper's high-pass (``hp_y``, ``hp_x``) and low-pass (``lp_y``: the damper output ``y``, ``lp_x``);
    ``gimbal`` (n, 2) [rad] the last command sent."""

    k: np.ndarray
    w_m: np.ndarray
    on: np.ndarray
    fresh: np.ndarray
    e_y: np.ndarray
    e_x: np.ndarray
    hp_y: np.ndarray
    hp_x: np.ndarray
    lp_y: np.ndarray
    lp_x: np.ndarray
    gimbal: np.ndarray


@nb.njit(cache=True)
def _gain_step(law, k, e2, y):
    """One exact step of ``dk/dt = a e2 - b y (k - k_min) - c (k - 1)``, clipped (:meth:`.aac.AdaptiveGainLaw.gain_step`)."""
    r = law.b * y + law.c
    drive = law.a * e2 + law.b * y * law.k_min + law.c
    if r > 0.0:
        k_inf = drive / r
        k_new = k_inf + (k - k_inf) * math.exp(-r * law.dt)
    else:
        k_new = k + drive * law.dt
    return clip_k(k_new, law.k_min, law.k_max)


@nb.njit(cache=True)
def _dead_zone_sq(e_f, dz):
    """``(sign(e_f) max(|e_f| - dz, 0))^2`` as numpy computes it."""
    m = abs(e_f) - dz
    if not (m >= 0.0 or np.isnan(m)):
        m = 0.0
    s = 1.0 if e_f > 0.0 else (-1.0 if e_f < 0.0 else (0.0 if e_f == 0.0 else e_f))
    e = s * m
    return e * e


@nb.njit(cache=True)
def _law_row(law, st, b, oc, obs, on):
    """One step of row ``b``'s adaptive law on its base's command ``st.gimbal`` (in: the base's; out: the
    command sent) (:meth:`.aac.AdaptiveGainLaw.step`)."""
    if not on:
        st.on[b] = False
        st.gimbal[b, 0], st.gimbal[b, 1] = 0.0, 0.0
        return
    if not st.on[b]:                                   # engagement: the filters restart
        st.e_y[b], st.e_x[b], st.hp_y[b], st.hp_x[b], st.lp_y[b], st.lp_x[b] = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        st.fresh[b] = True
        st.w_m[b] = 0.0
        if law.reset_on_engage:
            st.k[b] = 1.0
        st.on[b] = True
    ref = float(obs[oc.ref])
    st.w_m[b] = law.p_ref * st.w_m[b] + (1.0 - law.p_ref) * ref
    fresh = st.fresh[b]
    e2 = np.empty(2)
    y = np.empty(2)
    for ax in range(2):
        model, r = (st.w_m[b], ref) if ax == 0 else (0.0, 0.0)      # the model and reference of pitch only
        e = (model - r) - float(obs[oc.err[ax]])
        prev = 0.0 if fresh else st.e_x[b, ax]
        e_f = law.e_pole * st.e_y[b, ax] + law.e_gain * (e + prev)
        st.e_y[b, ax], st.e_x[b, ax] = e_f, e
        e2[ax] = _dead_zone_sq(e_f, law.e_dz)
        y[ax] = st.lp_y[b, ax]
        if law.y_dz > 0.0:
            v = y[ax] - law.y_dz
            y[ax] = v if (v >= 0.0 or np.isnan(v)) else 0.0
    if law.per_axis:
        for ax in range(2):
            st.k[b, ax] = _gain_step(law, st.k[b, ax], e2[ax], y[ax])
    else:
        st.k[b, 0] = _gain_step(law, st.k[b, 0], e2[0] + e2[1], y[0] + y[1])
    for ax in range(2):
        k = st.k[b, ax] if law.per_axis else st.k[b, 0]
        cmd = clip_k(k * st.gimbal[b, ax], -law.limit, law.limit)
        prev = cmd if fresh else st.hp_x[b, ax]
        h = law.hp_pole * st.hp_y[b, ax] + law.hp_gain * (cmd - prev)
        st.hp_y[b, ax], st.hp_x[b, ax] = h, cmd
        sq = h * h
        prev = 0.0 if fresh else st.lp_x[b, ax]
        st.lp_y[b, ax] = law.lp_pole * st.lp_y[b, ax] + law.lp_gain * (sq + prev)
        st.lp_x[b, ax] = sq
        st.gimbal[b, ax] = cmd
    st.fresh[b] = False


@nb.njit(cache=True)
def aac_act_k(tb, su, oc, base, law, st, rows, obs, value, out):
    """The actions ``out`` (k, 2) float32 of the rows ``rows`` (k,): each row's base (``tb``, ``su``,
    ``base``: :mod:`.pidkernel`'s blocks) acts on its observation ``obs[j]`` and scheduling value
    ``value[b]``, then its adaptive law (``law``, ``st``) scales the command; gimbal / limit, clipped."""
    for j in range(rows.size):
        b = rows[j]
        pid_row_k(tb, su, oc, base, b, obs[j], value[b])
        st.gimbal[b, 0], st.gimbal[b, 1] = base.gimbal[b, 0], base.gimbal[b, 1]
        _law_row(law, st, b, oc, obs[j], float(obs[j][oc.on]) >= 0.5)
        for ax in range(2):
            out[j, ax] = np.float32(clip_k(st.gimbal[b, ax] / law.limit, -1.0, 1.0))


class AACBatch:
    """``n`` rows of an :class:`.aac.AdaptiveAugmentingPolicy` on a PID-family base, stepped together (the
    batched interface of :mod:`.batch`; no ``history`` is kept). ``gimbal`` (n, 2) [rad]: each row's last
    command (the policy's ``last_gimbal``)."""

    def __init__(self, policy: Any, n: int) -> None:
        self.name, self.n = policy.name, int(n)
        self.base = PIDBatch(policy.base, self.n)
        lw, p = policy.law, policy.params
        self.law = AACLaw(p.k_min, p.k_max, p.error_gain, p.damper_gain, p.leak_rate, p.error_deadzone_radps,
                          p.damper_deadzone_rad2, lw.dt, lw.limit, lw.p_ref, bool(p.per_axis), bool(p.reset_on_engage),
                          lw.e_lp.pole, lw.e_lp.gain, lw.hp.pole, lw.hp.gain, lw.lp.pole, lw.lp.gain)
        self.oc = self.base.oc._replace(ref=int(policy._i_ref), on=int(policy._i_on))
        z2 = lambda: np.zeros((self.n, 2))             # noqa: E731
        self.st = AACState(np.ones((self.n, 2)), np.zeros(self.n), np.zeros(self.n, bool), np.ones(self.n, bool),
                           z2(), z2(), z2(), z2(), z2(), z2(), z2())

    @property
    def gimbal(self) -> np.ndarray:
        return self.st.gimbal

    def reset(self, rows: Any) -> None:
        """Rows ``rows`` start an episode: the base's reset and :meth:`.aac.AdaptiveGainLaw.reset`."""
        w = np.asarray(rows, dtype=np.int64).reshape(-1)
        self.base.reset(w)
        st = self.st
        st.k[w], st.w_m[w], st.on[w], st.fresh[w] = 1.0, 0.0, False, True
        for a in (st.e_y, st.e_x, st.hp_y, st.hp_x, st.lp_y, st.lp_x, st.gimbal):
            a[w] = 0.0

    def act(self, rows: Any, observations: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """Actions (len(rows), 2) float32 of the rows ``rows`` for their observations (len(rows), n_obs)."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        obs = np.ascontiguousarray(observations).reshape(rows.size, -1)
        base = self.base
        value = base.values(info)
        base.prepare(rows, obs, value)
        out = np.empty((rows.size, 2), np.float32)
        aac_act_k(base.tb, base.su, base.oc, base.st, self.law, self.st, rows, obs, value, out)
        return out
