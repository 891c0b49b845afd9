"""The simulator's compiled step: one call advances a range of batch rows by a whole control period.

Per row and per physics step of ``h = duration / ceil(duration / physics_dt)`` seconds:

1. the gimbal servo moves towards the command (:func:`.servo.servo_step_k`; or takes it at once), the
   previous period's command over the row's first ``delay`` physics steps (a dispersed servo delay);
2. the step is cut at every event time of the timeline inside it (and at every change of the mode
   basis the timeline projects across); on each piece the dynamics parameters (timeline rows
   interpolated, mode data held, then ``* scale + offset``), ``T_0`` and the nozzle exit area are taken
   at the middle of the piece; when the CG station moves, the state is shifted so that the structure
   stays in place (:meth:`NonRigidModel.shift_cg`); a piece that starts at a change of the mode basis
   first projects the modal state onto the new modes, and with ``slosh_frequency`` 1 the pendulums'
   damper frequency comes from the axial specific force of the row's latest flight conditions
   (:mod:`.piece`);
3. one RK4 step of the dynamics core with the flight loads (:func:`lvgym.dynamics.stepper.rk4_vehicle`);
4. while on the pad or rail, the vehicle is put back on the rail line (:func:`constrain_k`) and the
   lift-off and rail-exit times are recorded at the physics step where they happen;
5. with an IMU (``setup.imu``, layout :data:`.layouts.IMU`), its gyro and accelerometer filters are
   advanced over the step with the step's mean inputs (:mod:`.imu`).

After the period the flight conditions are evaluated at the row's new time with the thrust at that
time. Rows whose state turns non-finite, or diverges beyond :data:`X_DIVERGED` in any entry, are flagged
failed and no longer integrated. The functions
release the GIL, so the simulator runs row ranges on several threads.

The compiled functions take a few named blocks: the rows' :class:`~.data.SimData`, the timeline's
:class:`~.timeline.Tables` and the simulator's :data:`StepSetup`; every offset comes from a layout
(:mod:`.layouts`, :mod:`lvgym.dynamics.layout`).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.borrow import unowned_all
from lvgym.dynamics.layout import STATE, X
from lvgym.dynamics.stepper import make_workspace, rk4_vehicle_call
from lvgym.packing import at
from lvgym.rotations import quat_to_dcm

from .flight import PF, XF, flight_conditions_k, select_aero_k
from .imu import imu_begin_k, imu_end_k, imu_shift_k, make_imu_work
from .layouts import AEL, CTX, IM, RL, RS, A
from .piece import axial_specific_force_k, project_at_k, slosh_frequency_k
from .strips import strip_modes_k
from .servo import servo_step_k
from .timeline import held_at_k, interp_at_k, locate_from_k, locate_k, params_at_k, row_in_force_k

#: constants of a simulator's step: ``rail`` (layout RAIL), ``servo`` (layout SERVO), ``physics_dt`` [s]
#: the largest RK4 step, ``n_slosh`` and ``n_modes`` of the dynamics model, ``n_u`` its loads' length,
#: ``slosh_frequency`` the index of the damper frequency in :data:`.piece.SLOSH_FREQUENCIES` (0: the timeline's),
#: ``imu`` the IMU's parameters (layout IMU; ``on`` 0: no IMU)
StepSetup = namedtuple("StepSetup", ["rail", "servo", "physics_dt", "n_slosh", "n_modes", "n_u", "slosh_frequency",
                                     "imu"])
#: the scratch of :func:`advance_range`: the RK4 step's :data:`~lvgym.dynamics.stepper.Workspace`, the IMU's
#: :data:`~.imu.ImuWork`, a piece's parameters (n_p,), a modal vector (K,) and a 3x3 matrix
AdvanceWork = namedtuple("AdvanceWork", ["rk4", "imu", "params", "modal", "dcm"])
XS = STATE.per_slosh
_EPS = 1e-12
#: a state entry at or beyond this (SI: a position 150 Earth radii from the centre, a speed of 1e9 m/s, a
#: rate of 1e9 rad/s) is a diverged integration: the row fails as a non-finite one does, before the flight
#: loads meet numbers they were not written for (a pendulum spun up to 800 rad/s by a gimbal switching
#: between its stops reached 4e40 in the next physics step, and the step after raised a division by zero)
X_DIVERGED = 1e9


@nb.njit(cache=True, nogil=True, inline="always")
def shift_cg_k(x, d, C):
    """Move the reference point of ``r_zw_i``, ``v_zw_i`` by ``d`` [m] along ``x_b`` (the CG's travel
    within the structure): ``r += C_ib d``, ``v += C_ib (omega x d)``; ``C`` is 3x3 scratch."""
    oq, ow, orr, ov = XF.q_bi, XF.omega_bi_b, XF.r_zw_i, XF.v_zw_i
    quat_to_dcm(x[oq], x[oq + 1], x[oq + 2], x[oq + 3], C)
    wy, wz = x[ow + 1], x[ow + 2]
    # omega x (d, 0, 0) = (0, wz d, -wy d)
    for i in range(3):
        x[orr + i] += C[i, 0] * d
        x[ov + i] += C[i, 1] * wz * d - C[i, 2] * wy * d


@nb.njit(cache=True, nogil=True)
def constrain_k(x, t, rail, x_cg0, x_cg, rs):
    """Hold one vehicle on the rail at time ``t`` [s]: its structure on the rail line, no motion
    relative to the Earth across it (nor backwards at the rail's start), attitude fixed in the Earth
    frame. ``rail`` (layout ``RAIL``); ``x_cg0`` the CG station at the start, ``x_cg`` now [m];
    ``rs[RS.s]`` (layout ``RAIL_STATE``) receives the travel along the rail [m]."""
    w = rail[RL.omega_e]
    ang = w * t
    ca, sa = math.cos(ang), math.sin(ang)
    ae0, ae1, ae2 = rail[RL.axis_e], rail[RL.axis_e + 1], rail[RL.axis_e + 2]
    h0 = x_cg0 - rail[RL.x_base]
    b0, b1, b2 = rail[RL.r_pad_e] + h0 * ae0, rail[RL.r_pad_e + 1] + h0 * ae1, rail[RL.r_pad_e + 2] + h0 * ae2
    a0, a1, a2 = ca * ae0 - sa * ae1, sa * ae0 + ca * ae1, ae2          # axis_i = C_ie axis_e
    o0, o1, o2 = ca * b0 - sa * b1, sa * b0 + ca * b1, b2               # origin_i = C_ie base_e
    shift = x_cg - x_cg0
    orr, ov, oq, ow = XF.r_zw_i, XF.v_zw_i, XF.q_bi, XF.omega_bi_b
    r0, r1, r2 = x[orr], x[orr + 1], x[orr + 2]
    v0, v1, v2 = x[ov], x[ov + 1], x[ov + 2]
    s = max((r0 - o0) * a0 + (r1 - o1) * a1 + (r2 - o2) * a2 - shift, 0.0)
    n0, n1, n2 = o0 + (s + shift) * a0, o1 + (s + shift) * a1, o2 + (s + shift) * a2
    # velocity along the rail relative to the Earth (omega_e x r = (-w y, w x, 0))
    along = (v0 + w * r1) * a0 + (v1 - w * r0) * a1 + v2 * a2
    if s <= 0.0 and along < 0.0:
        along = 0.0
    x[orr], x[orr + 1], x[orr + 2] = n0, n1, n2
    x[ov] = -w * n1 + along * a0
    x[ov + 1] = w * n0 + along * a1
    x[ov + 2] = along * a2
    # q_bi = q_ie(ang) * q_bi0, q_ie = (cos ang/2, 0, 0, sin ang/2)
    c, z = math.cos(0.5 * ang), math.sin(0.5 * ang)
    oq0 = RL.q_bi0
    p0, p1, p2, p3 = rail[oq0], rail[oq0 + 1], rail[oq0 + 2], rail[oq0 + 3]
    x[oq] = c * p0 - z * p3
    x[oq + 1] = c * p1 - z * p2
    x[oq + 2] = c * p2 + z * p1
    x[oq + 3] = c * p3 + z * p0
    # omega_bi_b = C_ib0^T (0, 0, w): the third row of C_ib0 times w
    C = np.empty((3, 3))
    quat_to_dcm(p0, p1, p2, p3, C)
    for i in range(3):
        x[ow + i] = C[2, i] * w
    rs[RS.s] = s


@nb.njit(cache=True, nogil=True, inline="always")
def _piece_thrust_k(ctx, tables, i, w):
    """Thrust ``T_0``, exit area, aerodynamic block (and the mode shapes at the aeroelastic strips) of the
    timeline at the row ``i`` and weight ``w`` of a time (:func:`~.timeline.locate_k`) into the context."""
    ctx[CTX.thrust0] = interp_at_k(tables.thrust0, i, w)
    ctx[CTX.exit_area] = interp_at_k(tables.exit_area, i, w)
    ctx[CTX.vectored_share] = interp_at_k(tables.vectored_share, i, w)
    select_aero_k(ctx, held_at_k(tables.stage, i, w))
    if ctx[CTX.aeroelastic + AEL.on] != 0.0:
        strip_modes_k(ctx, tables.phi_strip, tables.dphi_strip, row_in_force_k(i, w))


@nb.njit(cache=True, nogil=True)
def advance_range(lo, hi, loads_fn, data, tables, setup, duration):
    """Advance rows ``lo:hi`` of ``data`` (a :class:`~.data.SimData`) by ``duration`` [s] (see the
    module docstring), reading the timeline's ``tables`` and the simulator's ``setup``
    (:data:`StepSetup`). The actuator rows receive the integrals of |gimbal| [rad s] and |gimbal rate|
    [rad] over the period; the conditions rows the flight conditions at the end."""
    n_modes = setup.n_modes
    work = AdvanceWork(make_workspace(setup.n_slosh, n_modes, setup.n_u), make_imu_work(n_modes),
                       np.empty(data.p.shape[1]), np.empty(n_modes), np.empty((3, 3)))
    _advance_rows(lo, hi, loads_fn, data, tables, setup, duration, work)


@nb.njit(cache=True, nogil=True, error_model="numpy")
def _advance_rows(lo, hi, loads_fn, data, tables, setup, duration, work):
    """:func:`advance_range` with its scratch ``work`` (:data:`AdvanceWork`). Every array is used through
    a borrowed view (:mod:`lvgym.borrow`; the caller holds them all for the call): no atomic reference
    count per row, piece or RK4 stage."""
    data, tables, setup, work = unowned_all(data), unowned_all(tables), unowned_all(setup), unowned_all(work)
    x, p, t = data.x, data.p, data.t
    n_x = x.shape[1]
    n_slosh, n_modes = setup.n_slosh, setup.n_modes
    ws, iw, pn, tmp, C = work.rk4, work.imu, work.params, work.modal, work.dcm
    ch_t, ch_T = tables.mode_change_t, tables.mode_transfer
    by_force = setup.slosh_frequency != 0 and n_slosh > 0
    n = max(1, int(math.ceil(duration / setup.physics_dt - 1e-9)))
    h = duration / n
    rail, servo, ev_t = setup.rail, setup.servo, tables.event_times
    imu_on = setup.imu[IM.on] != 0.0
    for b in range(lo, hi):
        xb, pb, cb = x[b], p[b], data.ctx[b]
        rs, act = data.rail_state[b], data.actuator[b]
        scale, offset = data.scale[b], data.offset[b]
        act[A.effort] = 0.0
        act[A.effort_rate] = 0.0
        if data.failed[b]:
            t[b] += duration
            continue
        t_start = t[b]
        first = True                  # the row's latest flight conditions: data.conditions, then the scratch
        row = -1                      # the timeline row of the latest look-up (the next starts there)
        for k in range(n):
            if imu_on:
                imu_begin_k(xb, n_slosh, n_modes, iw)
            servo_step_k(servo, act, h, k)
            cb[CTX.gimbal], cb[CTX.gimbal + 1] = act[A.gimbal], act[A.gimbal + 1]
            act[A.effort] += (abs(act[A.gimbal]) + abs(act[A.gimbal + 1])) * h
            act[A.effort_rate] += (abs(act[A.gimbal_rate]) + abs(act[A.gimbal_rate + 1])) * h
            ta, tb = t[b], (t_start + duration if k == n - 1 else t_start + (k + 1) * h)
            while ta < tb - _EPS:
                te = tb
                for e in ev_t:
                    if ta + _EPS < e < te - _EPS:
                        te = e
                for e in ch_t:
                    if ta + _EPS < e < te - _EPS:
                        te = e
                tm = 0.5 * (ta + te)
                row, wm = locate_from_k(tables.t, tm, row)
                params_at_k(tables.params, tables.hold, scale, offset, row, wm, pn)
                if ch_t.size:
                    project_at_k(xb, ta, ch_t, ch_T, _EPS, n_slosh, n_modes, tmp)
                if by_force:
                    if first:
                        a_x = axial_specific_force_k(data.conditions[b], 0, pb, n_slosh, n_modes)
                    else:
                        a_x = axial_specific_force_k(cb, CTX.scratch, pb, n_slosh, n_modes)
                    slosh_frequency_k(pn, scale, offset, a_x, n_slosh, n_modes)
                first = False
                d = pn[PF.r_cg] - pb[PF.r_cg]
                if d != 0.0:
                    if imu_on:
                        imu_shift_k(xb, iw, -1.0)
                    shift_cg_k(xb, d, C)
                    if imu_on:
                        imu_shift_k(xb, iw, 1.0)
                pb[:] = pn
                _piece_thrust_k(cb, tables, row, wm)
                cb[CTX.time0] = ta
                rk4_vehicle_call(loads_fn, 0.0, te - ta, xb, pb, cb, True, ws)
                ta = te
                if rs[RS.on] != 0.0:
                    constrain_k(xb, ta, rail, data.x_cg0[b], pb[PF.r_cg], rs)
                    if rs[RS.s] > 0.0 and rs[RS.lifted] == 0.0:
                        rs[RS.lifted] = 1.0
                        rs[RS.t_lift] = ta
                    if rs[RS.lifted] != 0.0 and rs[RS.s] >= rail[RL.length]:
                        rs[RS.on] = 0.0
                        rs[RS.t_exit] = ta
            t[b] = tb
            ok = True
            for i in range(n_x):
                if not abs(xb[i]) < X_DIVERGED:          # non-finite (NaN fails the test too), or diverged
                    ok = False
                    break
            if not ok:
                data.failed[b] = True
                t[b] = t_start + duration
                break
            if imu_on:
                row, wb = locate_from_k(tables.t, tb, row)
                imu_end_k(setup.imu, data.imu[b], xb, pb, cb, tables, row_in_force_k(row, wb), h, iw, n_slosh,
                          n_modes)
        act[A.previous], act[A.previous + 1] = act[A.command], act[A.command + 1]
        row, wb = locate_from_k(tables.t, t[b], row)
        _piece_thrust_k(cb, tables, row, wb)
        flight_conditions_k(t[b], xb, pb, cb, data.conditions[b])


@nb.njit(cache=True, nogil=True)
def conditions_rows(rows, data, tables):
    """Flight conditions of the rows ``rows`` of ``data`` at their current times, thrust and
    aerodynamics at those times."""
    for b in rows:
        i, w = locate_k(tables.t, data.t[b])
        _piece_thrust_k(data.ctx[b], tables, i, w)
        flight_conditions_k(data.t[b], data.x[b], data.p[b], data.ctx[b], data.conditions[b])


@nb.njit(cache=True, nogil=True)
def slosh_angles_range(lo, hi, x, n_slosh, n_modes, out):
    """Pendulum deflections from the body axis of rows ``lo:hi`` (B, N, 2) [rad]: the rod's angle in
    the x-y and x-z body planes (0 at rest, hanging aft)."""
    C = np.empty((3, 3))
    S = np.empty((3, 3))
    oq = XF.q_bi
    for b in range(lo, hi):
        xb = x[b]
        quat_to_dcm(xb[oq], xb[oq + 1], xb[oq + 2], xb[oq + 3], C)
        for j in range(n_slosh):
            o = at(X.q_si, n_modes, n_slosh) + XS.q_si * j
            quat_to_dcm(xb[o], xb[o + 1], xb[o + 2], xb[o + 3], S)
            # rod direction in body axes: C_ib^T C_is e_x
            e0 = C[0, 0] * S[0, 0] + C[1, 0] * S[1, 0] + C[2, 0] * S[2, 0]
            e1 = C[0, 1] * S[0, 0] + C[1, 1] * S[1, 0] + C[2, 1] * S[2, 0]
            e2 = C[0, 2] * S[0, 0] + C[1, 2] * S[1, 0] + C[2, 2] * S[2, 0]
            out[b, j, 0] = math.atan2(e1, e0)
            out[b, j, 1] = math.atan2(e2, e0)
