"""The simulator's compiled step: one call advances a range of batch rows by a whole control period.

Per row and per physics step of ``h = duration / ceil(duration / physics_dt)`` seconds:

1. the gimbal servo moves towards the command (:func:`.servo.servo_step_k`; or takes it at once);
2. the step is cut at every event time of the timeline inside it; on each piece the dynamics
   parameters (timeline rows interpolated, mode data held, then ``* scale + offset``), ``T_0`` and the
   nozzle exit area are taken at the middle of the piece; when the CG station moves, the state is
   shifted so that the structure stays in place (:meth:`NonRigidModel.shift_cg`);
3. one RK4 step of the dynamics core with the flight loads (:func:`lvgym.dynamics.stepper.rk4_vehicle`);
4. while on the pad or rail, the vehicle is put back on the rail line (:func:`constrain_k`) and the
   lift-off and rail-exit times are recorded at the physics step where they happen.

After the period the flight conditions are evaluated at the row's new time with the thrust at that
time. Rows whose state turns non-finite are flagged failed and no longer integrated. The functions
release the GIL, so the simulator runs row ranges on several threads.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from lvgym.dynamics.kernels import X_ETA, X_Q, X_R, X_V, X_W
from lvgym.dynamics.stepper import _alloc, rk4_vehicle, unowned
from lvgym.rotations import quat_to_dcm

from .flight import C_AE, C_DP, C_DY, C_T0, C_TIME0, flight_conditions_k, select_aero_k
from .servo import servo_step_k

# rail parameter vector (one per simulator)
R_OMEGA, R_XBASE, R_LENGTH, R_PAD, R_AXIS, R_Q0 = 0, 1, 2, 3, 6, 9
R_SIZE = 13
# per-row rail state
RS_ON, RS_LIFTED, RS_S, RS_T_LIFT, RS_T_EXIT = 0, 1, 2, 3, 4
N_RAIL_STATE = 5
_EPS = 1e-12


@nb.njit(cache=True, nogil=True, inline="always")
def locate_k(tl_t, t):
    """Row ``i`` and weight ``w`` of time ``t`` in the timeline rows ``tl_t`` (an event time takes the
    row after the event), as :meth:`.timeline.Timeline.locate`."""
    n = tl_t.size
    i = np.searchsorted(tl_t, t, side="right") - 1
    i = min(max(i, 0), n - 2)
    span = tl_t[i + 1] - tl_t[i]
    w = (t - tl_t[i]) / span if span > 0.0 else 0.0
    return i, min(max(w, 0.0), 1.0)


@nb.njit(cache=True, nogil=True, inline="always")
def params_k(tl_t, tl_p, hold, scale, offset, t, out):
    """Dynamics parameters at time ``t`` into ``out``: interpolated, held columns from the row in
    force, then ``* scale + offset``."""
    i, w = locate_k(tl_t, t)
    j = i + 1 if w >= 1.0 else i
    for k in range(out.size):
        v = tl_p[j, k] if hold[k] else (1.0 - w) * tl_p[i, k] + w * tl_p[i + 1, k]
        out[k] = v * scale[k] + offset[k]


@nb.njit(cache=True, nogil=True, inline="always")
def interp_k(tl_t, values, t):
    """Linear interpolation of a timeline column ``values`` at time ``t``."""
    i, w = locate_k(tl_t, t)
    return (1.0 - w) * values[i] + w * values[i + 1]


@nb.njit(cache=True, nogil=True, inline="always")
def held_k(tl_t, values, t):
    """The value of a piecewise-constant timeline column ``values`` in force at time ``t`` (the row
    after an event at an event time)."""
    i, w = locate_k(tl_t, t)
    return values[i + 1] if w >= 1.0 else values[i]


@nb.njit(cache=True, nogil=True, inline="always")
def shift_cg_k(x, d, C):
    """Move the reference point of ``r_zw_i``, ``v_zw_i`` by ``d`` [m] along ``x_b`` (the CG's travel
    within the structure): ``r += C_ib d``, ``v += C_ib (omega x d)``; ``C`` is 3x3 scratch."""
    quat_to_dcm(x[X_Q], x[X_Q + 1], x[X_Q + 2], x[X_Q + 3], C)
    wy, wz = x[X_W + 1], x[X_W + 2]
    # omega x (d, 0, 0) = (0, wz d, -wy d)
    for i in range(3):
        x[X_R + i] += C[i, 0] * d
        x[X_V + i] += C[i, 1] * wz * d - C[i, 2] * wy * d


@nb.njit(cache=True, nogil=True)
def constrain_k(x, t, rail, x_cg0, x_cg, rs):
    """Hold one vehicle on the rail at time ``t`` [s]: its structure on the rail line, no motion
    relative to the Earth across it (nor backwards at the rail's start), attitude fixed in the Earth
    frame. ``rail`` (layout ``R_*``); ``x_cg0`` the CG station at the start, ``x_cg`` now [m];
    ``rs[RS_S]`` receives the travel along the rail [m]."""
    w = rail[R_OMEGA]
    ang = w * t
    ca, sa = math.cos(ang), math.sin(ang)
    ae0, ae1, ae2 = rail[R_AXIS], rail[R_AXIS + 1], rail[R_AXIS + 2]
    h0 = x_cg0 - rail[R_XBASE]
    b0, b1, b2 = rail[R_PAD] + h0 * ae0, rail[R_PAD + 1] + h0 * ae1, rail[R_PAD + 2] + h0 * ae2
    a0, a1, a2 = ca * ae0 - sa * ae1, sa * ae0 + ca * ae1, ae2          # axis_i = C_ie axis_e
    o0, o1, o2 = ca * b0 - sa * b1, sa * b0 + ca * b1, b2               # origin_i = C_ie base_e
    shift = x_cg - x_cg0
    r0, r1, r2 = x[X_R], x[X_R + 1], x[X_R + 2]
    v0, v1, v2 = x[X_V], x[X_V + 1], x[X_V + 2]
    s = max((r0 - o0) * a0 + (r1 - o1) * a1 + (r2 - o2) * a2 - shift, 0.0)
    n0, n1, n2 = o0 + (s + shift) * a0, o1 + (s + shift) * a1, o2 + (s + shift) * a2
    # velocity along the rail relative to the Earth (omega_e x r = (-w y, w x, 0))
    along = (v0 + w * r1) * a0 + (v1 - w * r0) * a1 + v2 * a2
    if s <= 0.0 and along < 0.0:
        along = 0.0
    x[X_R], x[X_R + 1], x[X_R + 2] = n0, n1, n2
    x[X_V] = -w * n1 + along * a0
    x[X_V + 1] = w * n0 + along * a1
    x[X_V + 2] = along * a2
    # q_bi = q_ie(ang) * q_bi0, q_ie = (cos ang/2, 0, 0, sin ang/2)
    c, z = math.cos(0.5 * ang), math.sin(0.5 * ang)
    p0, p1, p2, p3 = rail[R_Q0], rail[R_Q0 + 1], rail[R_Q0 + 2], rail[R_Q0 + 3]
    x[X_Q] = c * p0 - z * p3
    x[X_Q + 1] = c * p1 - z * p2
    x[X_Q + 2] = c * p2 + z * p1
    x[X_Q + 3] = c * p3 + z * p0
    # omega_bi_b = C_ib0^T (0, 0, w): the third row of C_ib0 times w
    C = np.empty((3, 3))
    quat_to_dcm(p0, p1, p2, p3, C)
    for i in range(3):
        x[X_W + i] = C[2, i] * w
    rs[RS_S] = s


@nb.njit(cache=True, nogil=True)
def advance_range(lo, hi, loads_fn, x, p, c, t, scale, offset, x_cg0, failed, rail, rail_state, servo, cmd,
                  gimbal, gimbal_rate, effort, tl_t, tl_p, hold, tl_T0, tl_Ae, tl_stage, ev_t, duration, physics_dt,
                  n_slosh, n_modes, n_u, i_cg, diag):
    """Advance rows ``lo:hi`` by ``duration`` [s] (see the module docstring).

    ``x`` (B, n_x), ``p`` (B, n_p), ``c`` (B, n_c) state, parameters and context; ``t`` (B,) [s];
    ``scale``, ``offset`` (B, n_p) dispersions; ``x_cg0`` (B,) CG station at lift-off [m]; ``failed``
    (B,) bool; ``rail`` (R_SIZE,); ``rail_state`` (B, N_RAIL_STATE); ``servo`` (N_SERVO,); ``cmd``
    (B, 2) gimbal command [rad]; ``gimbal``, ``gimbal_rate`` (B, 2) servo state [rad, rad/s];
    ``effort`` (B, 2) receives the integrals of |gimbal| [rad s] and |gimbal rate| [rad] over the
    period; timeline columns ``tl_*`` (``tl_stage``: the lowest attached stage, which picks the
    aerodynamic block) and event times ``ev_t``; ``i_cg``: index of the CG station in
    ``p``; ``diag`` (B, N_DIAG) receives the flight conditions at the end."""
    n_x = x.shape[1]
    n_p = p.shape[1]
    buf, E, ws = _alloc(n_x, n_u, n_slosh, n_modes)
    pn = np.empty(n_p)
    C = np.empty((3, 3))
    n = max(1, int(math.ceil(duration / physics_dt - 1e-9)))
    h = duration / n
    for b in range(lo, hi):
        # rows of the caller's arrays, passed on without reference counting (see unowned)
        xb, pb, cb, rs = unowned(x[b]), unowned(p[b]), unowned(c[b]), rail_state[b]
        effort[b, 0] = 0.0
        effort[b, 1] = 0.0
        if failed[b]:
            t[b] += duration
            continue
        t_start = t[b]
        for k in range(n):
            servo_step_k(servo, cmd[b], gimbal[b], gimbal_rate[b], h)
            cb[C_DP], cb[C_DY] = gimbal[b, 0], gimbal[b, 1]
            effort[b, 0] += (abs(gimbal[b, 0]) + abs(gimbal[b, 1])) * h
            effort[b, 1] += (abs(gimbal_rate[b, 0]) + abs(gimbal_rate[b, 1])) * h
            ta, tb = t[b], (t_start + duration if k == n - 1 else t_start + (k + 1) * h)
            while ta < tb - _EPS:
                te = tb
                for e in ev_t:
                    if ta + _EPS < e < te - _EPS:
                        te = e
                tm = 0.5 * (ta + te)
                params_k(tl_t, tl_p, hold, scale[b], offset[b], tm, pn)
                d = pn[i_cg] - pb[i_cg]
                if d != 0.0:
                    shift_cg_k(xb, d, C)
                pb[:] = pn
                cb[C_T0] = interp_k(tl_t, tl_T0, tm)
                cb[C_AE] = interp_k(tl_t, tl_Ae, tm)
                cb[C_TIME0] = ta
                select_aero_k(cb, held_k(tl_t, tl_stage, tm))
                rk4_vehicle(loads_fn, 0.0, te - ta, xb, pb, cb, n_slosh, n_modes, True, buf, E, ws)
                ta = te
                if rs[RS_ON] != 0.0:
                    constrain_k(xb, ta, rail, x_cg0[b], pb[i_cg], rs)
                    if rs[RS_S] > 0.0 and rs[RS_LIFTED] == 0.0:
                        rs[RS_LIFTED] = 1.0
                        rs[RS_T_LIFT] = ta
                    if rs[RS_LIFTED] != 0.0 and rs[RS_S] >= rail[R_LENGTH]:
                        rs[RS_ON] = 0.0
                        rs[RS_T_EXIT] = ta
            t[b] = tb
            ok = True
            for i in range(n_x):
                if not math.isfinite(xb[i]):
                    ok = False
                    break
            if not ok:
                failed[b] = True
                t[b] = t_start + duration
                break
        cb[C_T0] = interp_k(tl_t, tl_T0, t[b])
        cb[C_AE] = interp_k(tl_t, tl_Ae, t[b])
        select_aero_k(cb, held_k(tl_t, tl_stage, t[b]))
        flight_conditions_k(t[b], xb, pb, cb, diag[b])


@nb.njit(cache=True, nogil=True)
def conditions_range(lo, hi, t, x, p, c, tl_t, tl_T0, tl_Ae, tl_stage, diag):
    """Flight conditions of rows ``lo:hi`` at their current times, thrust and aerodynamics at those
    times."""
    for b in range(lo, hi):
        c[b, C_T0] = interp_k(tl_t, tl_T0, t[b])
        c[b, C_AE] = interp_k(tl_t, tl_Ae, t[b])
        select_aero_k(c[b], held_k(tl_t, tl_stage, t[b]))
        flight_conditions_k(t[b], x[b], p[b], c[b], diag[b])


@nb.njit(cache=True, nogil=True)
def slosh_angles_k(x, n_slosh, n_modes, out):
    """Pendulum deflections from the body axis (B, N, 2) [rad]: the rod's angle in the x-y and x-z
    body planes (0 at rest, hanging aft)."""
    slosh_angles_range(0, x.shape[0], x, n_slosh, n_modes, out)


@nb.njit(cache=True, nogil=True)
def slosh_angles_range(lo, hi, x, n_slosh, n_modes, out):
    """:func:`slosh_angles_k` of rows ``lo:hi``."""
    C = np.empty((3, 3))
    S = np.empty((3, 3))
    for b in range(lo, hi):
        xb = x[b]
        quat_to_dcm(xb[X_Q], xb[X_Q + 1], xb[X_Q + 2], xb[X_Q + 3], C)
        for j in range(n_slosh):
            o = X_ETA + 4 * n_modes + 4 * j
            quat_to_dcm(xb[o], xb[o + 1], xb[o + 2], xb[o + 3], S)
            # rod direction in body axes: C_ib^T C_is e_x
            e0 = C[0, 0] * S[0, 0] + C[1, 0] * S[1, 0] + C[2, 0] * S[2, 0]
            e1 = C[0, 1] * S[0, 0] + C[1, 1] * S[1, 0] + C[2, 1] * S[2, 0]
            e2 = C[0, 2] * S[0, 0] + C[1, 2] * S[1, 0] + C[2, 2] * S[2, 0]
            out[b, j, 0] = math.atan2(e1, e0)
            out[b, j, 1] = math.atan2(e2, e0)
