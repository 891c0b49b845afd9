"""Compiled task signals of the ascent envs: reference, errors, reward terms, termination, observation.

One call per control step evaluates, for every row of a batch, what :class:`~.core.AscentBatch` needs
after the simulator has advanced: the reference rates (zero, or the gravity-turn pitch program), the
reference axis turned by them, the rate errors and their integral, the reward terms, the q-alpha and
attitude checks, and the noise-free observation. Sensor noise is added afterwards from each row's own
generator. The formulas are those documented on :class:`~.core.AscentBatch`; this module only runs
them without Python overhead (a single env pays one call instead of a hundred numpy calls).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from lvgym.dynamics.kernels import X_ETA, X_Q, X_V, X_W
from lvgym.rotations import quat_to_dcm
from lvgym.simulator.advance import locate_k
from lvgym.simulator.flight import DIAG

# task parameter vector
(T_ON_AFTER, T_DT, T_MISSION, T_W_ROLL, T_W_PITCH, T_W_YAW, T_EFFORT, T_EFFORT_RATE, T_PENALTY, T_QALPHA, T_ATT,
 T_GIMBAL, T_GTURN, T_KICK0, T_KICK1, T_KICK_ANGLE, T_SENSORS, T_N_STEPS) = range(18)
N_TASK = 18
#: termination codes (the order is the precedence: a later one overrides an earlier one)
REASONS = ("", "attitude error beyond the limit", "q-alpha beyond the structural limit", "non-finite state")
G0 = 9.80665

_ALPHA, _BETA, _AT = DIAG["alpha"].start, DIAG["beta"].start, DIAG["alpha_total"].start
_MACH, _QBAR, _G = DIAG["mach"].start, DIAG["qbar"].start, DIAG["g_i"].start
_FA, _TE = DIAG["f_aero_b"].start, DIAG["thrust_e"].start


@nb.njit(cache=True, nogil=True)
def controller_on_k(tp, tl_t, tl_burning, t):
    """Whether the controller acts at time ``t``: after ``T_ON_AFTER`` and while an engine burns."""
    i, w = locate_k(tl_t, t)
    return t >= tp[T_ON_AFTER] - 1e-9 and tl_burning[i + 1 if w >= 1.0 else i] != 0.0


@nb.njit(cache=True, nogil=True)
def reference_pitch_rate_k(tp, t, x, d):
    """Reference pitch rate [rad/s]: zero, or the gravity-turn programme (a kick of ``T_KICK_ANGLE``
    between ``T_KICK0`` and ``T_KICK1``, then ``-g sin(theta) / V`` with theta the velocity's angle
    from the local vertical; negative turns the nose downrange)."""
    if tp[T_GTURN] == 0.0:
        return 0.0
    if tp[T_KICK0] <= t < tp[T_KICK1]:
        return -tp[T_KICK_ANGLE] / (tp[T_KICK1] - tp[T_KICK0])
    if t < tp[T_KICK1]:
        return 0.0
    gx, gy, gz = d[_G], d[_G + 1], d[_G + 2]
    gn = math.sqrt(gx * gx + gy * gy + gz * gz)
    vx, vy, vz = x[X_V], x[X_V + 1], x[X_V + 2]
    speed = max(math.sqrt(vx * vx + vy * vy + vz * vz), 1.0)
    cos_th = min(max(-(vx * gx + vy * gy + vz * gz) / (gn * speed), -1.0), 1.0)
    return -gn * math.sqrt(1.0 - cos_th * cos_th) / speed


@nb.njit(cache=True, nogil=True)
def attitude_error_k(C, a, out):
    """Pitch and yaw attitude error [rad] of the body axis ``C[:, 0]`` (``C = C_ib``) against the
    reference axis ``a`` (inertial): ``-(C^T (x_b x a))[1:3]``."""
    x0, x1, x2 = C[0, 0], C[1, 0], C[2, 0]
    e0, e1, e2 = x1 * a[2] - x2 * a[1], x2 * a[0] - x0 * a[2], x0 * a[1] - x1 * a[0]
    out[0] = -(C[0, 1] * e0 + C[1, 1] * e1 + C[2, 1] * e2)
    out[1] = -(C[0, 2] * e0 + C[1, 2] * e1 + C[2, 2] * e2)


@nb.njit(cache=True, nogil=True)
def observe_k(tp, t, x, d, C, a, gimbal, on, ref_pitch, bias, dphi, mass, n_modes, obs, att):
    """Noise-free observation (14) of one row into ``obs`` and its attitude error into ``att``.
    ``dphi`` (K,): mode slopes at the IMU (sensors only); ``mass`` [kg] of the whole stack."""
    attitude_error_k(C, a, att)
    w0, w1, w2 = x[X_W], x[X_W + 1], x[X_W + 2]
    if tp[T_SENSORS] != 0.0:
        K = n_modes
        for k in range(K):                   # the gyro sees the slope rate of the deflected section
            w1 -= dphi[k] * x[X_ETA + 2 * K + K + k]
            w2 += dphi[k] * x[X_ETA + 2 * K + k]
        w0 += bias[0]
        w1 += bias[1]
        w2 += bias[2]
        obs[5] = (d[_FA + 2] + d[_TE + 2]) / mass / G0
        obs[6] = (d[_FA + 1] + d[_TE + 1]) / mass / G0
    else:
        obs[5] = d[_ALPHA]
        obs[6] = d[_BETA]
    obs[0] = w0
    obs[1] = w1 - ref_pitch
    obs[2] = w2
    obs[3] = att[0]
    obs[4] = att[1]
    obs[7] = d[_MACH] / 10.0
    obs[8] = d[_QBAR] / 1e5
    obs[9] = gimbal[0] / tp[T_GIMBAL]
    obs[10] = gimbal[1] / tp[T_GIMBAL]
    obs[11] = t / tp[T_MISSION]
    obs[12] = 1.0 if on else 0.0
    obs[13] = ref_pitch


@nb.njit(cache=True, nogil=True)
def reset_signals(rows, tp, t, x, diag, gimbal, axis_ref, bias, tl_t, tl_burning, tl_mass, tl_dphi, n_modes, on,
                  obs, att):
    """Reference axis (the launch axis), controller flag and observation of freshly reset ``rows``."""
    C = np.empty((3, 3))
    for b in rows:
        xb = x[b]
        quat_to_dcm(xb[X_Q], xb[X_Q + 1], xb[X_Q + 2], xb[X_Q + 3], C)
        for i in range(3):
            axis_ref[b, i] = C[i, 0]
        on[b] = controller_on_k(tp, tl_t, tl_burning, t[b])
        i, w = locate_k(tl_t, t[b])
        j = i + 1 if w >= 1.0 else i
        observe_k(tp, t[b], xb, diag[b], C, axis_ref[b], gimbal[b], on[b],
                  reference_pitch_rate_k(tp, t[b], xb, diag[b]), bias[b], tl_dphi[j, 0],
                  (1.0 - w) * tl_mass[i] + w * tl_mass[i + 1], n_modes, obs[b], att[b])


@nb.njit(cache=True, nogil=True)
def step_signals_range(lo, hi, tp, t, x, diag, failed, effort, gimbal, steps, axis_ref, cum_error, bias, tl_t,
                       tl_burning, tl_mass, tl_dphi, n_modes, on, obs, att, terms, reward, reason, truncated, qalpha):
    """Signals of rows ``lo:hi`` after a control step (``steps`` already counts it).

    Updates ``axis_ref`` (B, 3) (turned by the reference pitch rate about the body pitch axis),
    ``cum_error`` (B, 3) [rad] and ``on`` (B,) (the controller flag for the next step); writes the
    observation ``obs`` (B, 14) without noise, attitude error ``att`` (B, 2) [rad], reward ``terms``
    (B, 6) in the order of :data:`~.core.REWARD_TERMS` and their sum ``reward``, the termination code
    ``reason`` (index into :data:`REASONS`), ``truncated`` and q-alpha [Pa deg]."""
    dt = tp[T_DT]
    C = np.empty((3, 3))
    for b in range(lo, hi):
        xb, db, a = x[b], diag[b], axis_ref[b]
        quat_to_dcm(xb[X_Q], xb[X_Q + 1], xb[X_Q + 2], xb[X_Q + 3], C)
        ref_pitch = reference_pitch_rate_k(tp, t[b], xb, db)
        if ref_pitch != 0.0:                  # Rodrigues: turn a about the body pitch axis k
            ang = ref_pitch * dt
            k0, k1, k2 = C[0, 1], C[1, 1], C[2, 1]
            ca, sa = math.cos(ang), math.sin(ang)
            kv = k0 * a[0] + k1 * a[1] + k2 * a[2]
            c0, c1, c2 = k1 * a[2] - k2 * a[1], k2 * a[0] - k0 * a[2], k0 * a[1] - k1 * a[0]
            a[0] = a[0] * ca + c0 * sa + k0 * kv * (1.0 - ca)
            a[1] = a[1] * ca + c1 * sa + k1 * kv * (1.0 - ca)
            a[2] = a[2] * ca + c2 * sa + k2 * kv * (1.0 - ca)
        e0, e1, e2 = 0.0, 0.0, 0.0
        if not failed[b]:
            e0, e1, e2 = abs(xb[X_W]), abs(xb[X_W + 1] - ref_pitch), abs(xb[X_W + 2])
        cum_error[b, 0] += e0 * dt
        cum_error[b, 1] += e1 * dt
        cum_error[b, 2] += e2 * dt
        terms[b, 0] = -tp[T_W_ROLL] * e0 * dt
        terms[b, 1] = -tp[T_W_PITCH] * e1 * dt
        terms[b, 2] = -tp[T_W_YAW] * e2 * dt
        terms[b, 3] = -tp[T_EFFORT] * effort[b, 0]
        terms[b, 4] = -tp[T_EFFORT_RATE] * effort[b, 1]
        on[b] = controller_on_k(tp, tl_t, tl_burning, t[b])
        i, w = locate_k(tl_t, t[b])
        j = i + 1 if w >= 1.0 else i
        observe_k(tp, t[b], xb, db, C, a, gimbal[b], on[b], ref_pitch, bias[b], tl_dphi[j, 0],
                  (1.0 - w) * tl_mass[i] + w * tl_mass[i + 1], n_modes, obs[b], att[b])
        qalpha[b] = db[_QBAR] * math.degrees(db[_AT])
        code = 0
        if math.degrees(math.sqrt(att[b, 0] ** 2 + att[b, 1] ** 2)) > tp[T_ATT]:
            code = 1
        if qalpha[b] > tp[T_QALPHA]:
            code = 2
        if failed[b]:
            code = 3
        reason[b] = code
        truncated[b] = code == 0 and steps[b] >= tp[T_N_STEPS]
        terms[b, 5] = -tp[T_PENALTY] * max(tp[T_MISSION] - t[b], 0.0) if code != 0 else 0.0
        reward[b] = terms[b, 0] + terms[b, 1] + terms[b, 2] + terms[b, 3] + terms[b, 4] + terms[b, 5]
        if failed[b]:
            for i in range(obs.shape[1]):
                obs[b, i] = 0.0


@nb.njit(cache=True, nogil=True)
def step_signals(tp, t, x, diag, failed, effort, gimbal, steps, axis_ref, cum_error, bias, tl_t, tl_burning,
                 tl_mass, tl_dphi, n_modes, on, obs, att, terms, reward, reason, truncated, qalpha):
    """:func:`step_signals_range` over every row (the batch wrapper runs row ranges on the simulator's
    threads)."""
    step_signals_range(0, x.shape[0], tp, t, x, diag, failed, effort, gimbal, steps, axis_ref, cum_error, bias, tl_t,
                       tl_burning, tl_mass, tl_dphi, n_modes, on, obs, att, terms, reward, reason, truncated, qalpha)
