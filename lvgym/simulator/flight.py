"""Compiled flight loads: gravity, thrust and aerodynamics of one vehicle at every RK4 stage.

The dynamics core integrates with a compiled loads function ``loads_fn(t, x, p, c, u)`` (see
:mod:`lvgym.dynamics.stepper`). This module builds the simulator's: :func:`flight_conditions_k` evaluates
the environment models (through their own compiled kernels) for one state and writes a vector of
flight conditions (layout :data:`.layouts.CONDITIONS`); :data:`flight_loads` turns that vector into the loads
vector of the core. The same function fills the recorded and observed conditions, so what a policy sees is what
the vehicle felt.

``ctx`` is the per-vehicle *context* vector (header :data:`.layouts.CONTEXT`): the commands (gimbal
angles, a body moment such as reaction-control thrusters give) and thrust held over a step and the
piece's start time ``time0`` (the stepper's time is relative to it, so the rows of a batch may be at
different times), the aerodynamic block in force (``aero``, chosen per stage from a table of contents by
:func:`select_aero_k`), a scratch block the compiled functions write into (so that an evaluation
allocates nothing; each row is only ever evaluated by one thread at a time), followed by the parameter
arrays of the launch site, gravity, atmosphere, wind and aerodynamic models, packed end to end with their
start offsets in the header (rows of a batch may have different wind blocks; shorter rows are padded),
and, with the aeroelastic strip loads on, their blocks (:mod:`.strips`). :func:`pack_context` builds it.

Aeroelastic loads (:mod:`.strips`, off unless the context's ``aeroelastic.on`` is set): the strips'
elastic force and moment are added to the table's (so the conditions hold them too) and their modal
forces are the core's ``f_eta``; without them ``f_eta`` is zero.

Thrust: ``T = max(T_0 - A_e p_amb, 0)`` with ``T_0`` and the total nozzle exit area ``A_e`` [m^2] from the
mass model's timeline and ``p_amb`` the ambient pressure at the stage's altitude. Its direction in the
undeformed engine frame (body axes) is set by the gimbal angles ``delta_p``, ``delta_y`` [rad] plus a
fixed misalignment: ``e = (cos dp cos dy, -sin dy, sin dp cos dy)`` with ``dp = delta_p + mis_p`` and
``dy = delta_y + mis_y``, so that a positive ``delta_p`` pitches the nose up about ``+y_b`` and a positive
``delta_y`` yaws it about ``+z_b`` for an engine aft of the centre of gravity.

Dispersions (the context's ``dispersion`` block, layout :data:`.layouts.DISPERSION`, neutral by default):
the thrust times ``thrust_scale``; the aerodynamic axial force times ``axial_scale``; the normal force and
the moment about the CG times ``normal_scale``, and the normal force moved ``cp_shift`` [m] towards the
nose, which adds ``cp_shift e_x x f_normal`` to the moment.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numba as nb
import numpy as np

from lvgym.dynamics.layout import LOADS, PARAMS, STATE
from lvgym.borrow import unowned, unowned_matrix
from lvgym.dynamics.stepper import compile_loads
from lvgym.environment.aerokernels import AeroAt, AirData, LoadsAt, TableAt, aero_loads_at
from lvgym.environment.atmosphere import atmosphere_state_at
from lvgym.environment.earth import SITE_SIZE, site_dcm_ni_latlon_at, site_geodetic_at, site_velocity_wrt_earth_at
from lvgym.environment.gravity import gravity_at, harmonics_work
from lvgym.environment.wind import wind_ned_at
from lvgym.rotations import quat_to_dcm

from .coldstart import announce_compile
from .layouts import AE, AEL, AERO, CONDITIONS, CONTEXT, CTX, DISPERSION, DS, TG, TRIG, D
from .strips import pack_strips, strip_loads_at, strip_modal_forces_k, strip_stage_k

XF, PF, UF = STATE.fixed, PARAMS.fixed, LOADS.fixed      # dynamics offsets independent of K and N
N_COND = CONDITIONS.size
AERO_SIZE = AERO.size


@nb.njit(cache=True, error_model="numpy", inline="always")
def flight_conditions_at(t, x, p, ctx, cond, oc, full):
    """Flight conditions (layout ``CONDITIONS``) of the state ``x`` at time ``t`` [s] into
    ``cond[oc:oc + N_COND]`` (``cond`` may be ``ctx``: its scratch). The models are read in place from the
    packed context: no array view, no allocation. ``full=False`` (the loads at an RK4 stage) skips the
    flow angles alpha, beta and phi_aero, which no load depends on (they are left as they were)."""
    rx, ry, rz = x[XF.r_zw_i], x[XF.r_zw_i + 1], x[XF.r_zw_i + 2]
    o_site, o_grav, o_atm = int(ctx[CTX.site]), int(ctx[CTX.gravity]), int(ctx[CTX.atmosphere])
    o_wind = int(ctx[CTX.wind])
    o_ap, o_ag, o_ad = int(ctx[CTX.aero + AE.params]), int(ctx[CTX.aero + AE.grid]), int(ctx[CTX.aero + AE.dims])
    o_at, n_col = int(ctx[CTX.aero + AE.table]), int(ctx[CTX.aero + AE.n_col])
    lat, lon, alt = site_geodetic_at(rx, ry, rz, t, ctx, o_site)
    cond[oc + D.altitude] = alt
    gx, gy, gz = gravity_at(rx, ry, rz, t, ctx, o_grav, ctx, int(ctx[CTX.gravity_work]))
    cond[oc + D.g_i], cond[oc + D.g_i + 1], cond[oc + D.g_i + 2] = gx, gy, gz
    atmosphere_state_at(ctx, o_atm, alt, cond, oc + D.air)
    rho, pres, sound = cond[oc + D.density], cond[oc + D.pressure], cond[oc + D.speed_of_sound]
    w = oc + D.wind_n
    wind_ned_at(ctx, o_wind, alt, t, cond, w)
    wn0, wn1, wn2 = cond[w], cond[w + 1], cond[w + 2]
    C = unowned_matrix(ctx, CTX.scratch_dcm, 3, 3)
    site_dcm_ni_latlon_at(lat, lon, t, ctx, o_site, C)
    ov = XF.v_zw_i
    vx, vy, vz = site_velocity_wrt_earth_at(rx, ry, rz, x[ov], x[ov + 1], x[ov + 2], ctx, o_site)
    vr0 = vx - (C[0, 0] * wn0 + C[1, 0] * wn1 + C[2, 0] * wn2)
    vr1 = vy - (C[0, 1] * wn0 + C[1, 1] * wn1 + C[2, 1] * wn2)
    vr2 = vz - (C[0, 2] * wn0 + C[1, 2] * wn1 + C[2, 2] * wn2)
    oq = XF.q_bi
    quat_to_dcm(x[oq], x[oq + 1], x[oq + 2], x[oq + 3], C)           # C = C_ib
    va = oc + D.v_air_b
    for i in range(3):
        cond[va + i] = C[0, i] * vr0 + C[1, i] * vr1 + C[2, i] * vr2    # v_air_b = C_ib^T v_rel_i
    u, v, w = cond[va], cond[va + 1], cond[va + 2]
    fa, ma, st = oc + D.f_aero_b, oc + D.m_aero_b, oc + D.flow
    ow = XF.omega_bi_b
    if ctx[CTX.aero_on] != 0.0:
        air = AirData((u, v, w), (x[ow], x[ow + 1], x[ow + 2]), rho, sound, p[PF.r_cg], alt)
        model = AeroAt(ctx, o_ap, TableAt(ctx, o_ag, ctx, o_ad, o_at - o_ad, ctx, o_at, n_col))
        aero_loads_at(air, model, cond, LoadsAt(fa, ma, st), full)
    else:                                                         # flow angles only
        vperp = math.sqrt(v * v + w * w)
        speed = math.sqrt(u * u + vperp * vperp)
        cond[oc + D.alpha] = math.atan2(w, u)
        cond[oc + D.beta] = math.atan2(v, math.sqrt(u * u + w * w))
        cond[oc + D.alpha_total] = math.atan2(vperp, u)
        cond[oc + D.phi_aero] = math.atan2(v, w) if vperp > 0.0 else 0.0
        cond[oc + D.mach] = speed / sound if sound > 0.0 else 0.0
        cond[oc + D.qbar] = 0.5 * rho * speed * speed
        cond[oc + D.airspeed] = speed
        for i in range(3):
            cond[fa + i] = 0.0
            cond[ma + i] = 0.0
    ds = CTX.dispersion
    kn, dx = ctx[ds + DS.normal_scale], ctx[ds + DS.cp_shift]
    if kn != 1.0 or dx != 0.0 or ctx[ds + DS.axial_scale] != 1.0:
        fy, fz = kn * cond[fa + 1], kn * cond[fa + 2]
        cond[fa] *= ctx[ds + DS.axial_scale]
        cond[fa + 1], cond[fa + 2] = fy, fz
        cond[ma + 1] = kn * cond[ma + 1] - dx * fz           # (dx e_x) x f_normal
        cond[ma + 2] = kn * cond[ma + 2] + dx * fy
    if ctx[CTX.aeroelastic + AEL.on] != 0.0:
        strip_loads_at(x, p[PF.r_cg], ctx, cond, oc)
    for i in range(3):
        cond[oc + D.f_aero_i + i] = C[i, 0] * cond[fa] + C[i, 1] * cond[fa + 1] + C[i, 2] * cond[fa + 2]
    thrust = 0.0
    if ctx[CTX.thrust0] > 0.0:
        thrust = max(ctx[CTX.thrust0] - ctx[CTX.exit_area] * pres, 0.0) * ctx[ds + DS.thrust_scale]
    cond[oc + D.thrust] = thrust
    dp = ctx[CTX.gimbal] + ctx[CTX.misalignment]
    dy = ctx[CTX.gimbal + 1] + ctx[CTX.misalignment + 1]
    tg = CTX.trig
    if dp != ctx[tg + TG.pitch] or dy != ctx[tg + TG.yaw]:        # the gimbal is held over an RK4 step
        ctx[tg + TG.pitch], ctx[tg + TG.yaw] = dp, dy
        ctx[tg + TG.cos_pitch], ctx[tg + TG.sin_pitch] = math.cos(dp), math.sin(dp)
        ctx[tg + TG.cos_yaw], ctx[tg + TG.sin_yaw] = math.cos(dy), math.sin(dy)
    share = ctx[CTX.vectored_share]
    if share == 1.0:                                              # every engine gimballed (the shipped vehicles)
        cond[oc + D.thrust_b] = thrust * ctx[tg + TG.cos_pitch] * ctx[tg + TG.cos_yaw]
        cond[oc + D.thrust_b + 1] = -thrust * ctx[tg + TG.sin_yaw]
        cond[oc + D.thrust_b + 2] = thrust * ctx[tg + TG.sin_pitch] * ctx[tg + TG.cos_yaw]
    else:                                                         # the gimbal turns a share, the rest acts on x_b
        turned = share * thrust
        cond[oc + D.thrust_b] = turned * ctx[tg + TG.cos_pitch] * ctx[tg + TG.cos_yaw] + (thrust - turned)
        cond[oc + D.thrust_b + 1] = -turned * ctx[tg + TG.sin_yaw]
        cond[oc + D.thrust_b + 2] = turned * ctx[tg + TG.sin_pitch] * ctx[tg + TG.cos_yaw]


@nb.njit(cache=True, error_model="numpy")
def flight_conditions_k(t, x, p, ctx, cond):
    """Flight conditions (layout ``CONDITIONS``) of the state ``x`` at time ``t`` [s] into ``cond``."""
    flight_conditions_at(t, x, p, ctx, cond, 0, True)


def _flight_loads(t, x, p, ctx, u):
    """Loads of the dynamics core from the flight conditions: aerodynamic force (inertial) plus the
    commanded body force ``force_b`` turned to inertial axes, aerodynamic plus commanded moment about the
    CG, thrust in the engine frame, gravity; generalised modal forces from the aeroelastic strips when
    they are on, else none. The arrays are used through :func:`~lvgym.dynamics.kernels.unowned` views (the
    caller holds them), so the views made from them (the scratch matrix, the models' blocks) count no
    references: no atomic instruction per view."""
    x, p, ctx, u = unowned(x), unowned(p), unowned(ctx), unowned(u)
    flight_conditions_at(ctx[CTX.time0] + t, x, p, ctx, ctx, CTX.scratch, False)
    sc = CTX.scratch
    for i in range(3):
        u[UF.f_b_i + i] = ctx[sc + D.f_aero_i + i]
        u[UF.m_b_b + i] = ctx[sc + D.m_aero_b + i] + ctx[CTX.moment_b + i]
        u[UF.thrust_b + i] = ctx[sc + D.thrust_b + i]
        u[UF.g_i + i] = ctx[sc + D.g_i + i]
    fb = CTX.force_b
    if ctx[fb] != 0.0 or ctx[fb + 1] != 0.0 or ctx[fb + 2] != 0.0:     # C_ib is in the scratch matrix
        C = unowned_matrix(ctx, CTX.scratch_dcm, 3, 3)
        for i in range(3):
            u[UF.f_b_i + i] += C[i, 0] * ctx[fb] + C[i, 1] * ctx[fb + 1] + C[i, 2] * ctx[fb + 2]
    for i in range(UF.f_eta, u.size):
        u[i] = 0.0
    if ctx[CTX.aeroelastic + AEL.on] != 0.0:
        strip_modal_forces_k(ctx, u)


announce_compile(_flight_loads)                      # one line on stderr before a compile from a cold cache
flight_loads = compile_loads(_flight_loads)


@nb.njit(cache=True)
def flight_conditions_batch(t, x, p, ctx, cond):
    """:func:`flight_conditions_k` for every row: ``t`` (B,), ``x`` (B, n_x), ``p`` (B, n_p), ``ctx``
    (B, n_ctx) into ``cond`` (B, N_COND)."""
    for b in range(x.shape[0]):
        flight_conditions_k(t[b], x[b], p[b], ctx[b], cond[b])


@nb.njit(cache=True, nogil=True, inline="always")
def select_aero_k(ctx, stage):
    """Put the aerodynamic block of ``stage`` (the lowest attached stage) in force in the context ``ctx``
    (stages beyond the table of contents take its last row)."""
    s = min(max(int(stage), 0), int(ctx[CTX.n_stages]) - 1)
    if int(ctx[CTX.stage]) == s:
        return
    o = int(ctx[CTX.toc]) + AERO_SIZE * s
    for i in range(AERO_SIZE):
        ctx[CTX.aero + i] = ctx[o + i]
    if ctx[CTX.aeroelastic + AEL.on] != 0.0:
        strip_stage_k(ctx, s)
    ctx[CTX.stage] = s


def pack_context(site: np.ndarray, gravity: np.ndarray, atmosphere: np.ndarray, wind: np.ndarray,
                 aero: Any, strips: Any = None) -> np.ndarray:
    """Context vector of one vehicle from the models' parameter arrays; commands are zero.

    ``aero``: None (no aerodynamic loads), one model's ``kernel_args()``, or a list of them, one per
    stage: entry ``s`` is in force while stage ``s`` is the lowest attached one (the same tuple object
    given for several stages is packed once). Stage 0's block is in force at first. ``strips``: None
    (no aeroelastic loads) or a :data:`.strips.StripSetup` (one strip model per stage)."""
    per_stage = [None] if aero is None else (list(aero) if isinstance(aero, list) else [aero])
    blocks = [np.asarray(site, float), np.asarray(gravity, float), np.asarray(atmosphere, float),
              np.asarray(wind, float)]
    if blocks[0].size != SITE_SIZE:
        raise ValueError(f"site parameters have {blocks[0].size} entries: expected {SITE_SIZE}")
    header = CONTEXT.zeros()
    view = functools.partial(CONTEXT.view, header)
    trig = view("trig")                                        # the thrust angles' cache is empty
    trig[TRIG.index("pitch")] = trig[TRIG.index("yaw")] = np.nan
    view("aero_on")[:] = 0.0 if aero is None else 1.0
    view("dispersion")[:] = DISPERSION.pack({"thrust_scale": 1.0, "normal_scale": 1.0, "axial_scale": 1.0})
    offset = CONTEXT.size
    for key, block in zip(("site", "gravity", "atmosphere", "wind"), blocks):
        view(key)[:] = offset
        offset += block.size
    view("wind_end")[:] = offset
    packed: dict[int, list[float]] = {}
    toc = []
    for args in per_stage:
        if id(args) not in packed:
            ap, grid, dims, table = ((np.zeros(4), np.zeros(1), np.ones(1), np.zeros((1, 1))) if args is None
                                     else args)
            parts = [np.asarray(ap, float), np.asarray(grid, float), np.asarray(dims, float),
                     np.ascontiguousarray(table, float).ravel()]
            row = AERO.zeros()
            for name, part in zip(("params", "grid", "dims", "table"), parts):
                row[AERO.index(name)] = offset
                blocks.append(part)
                offset += part.size
            row[AERO.index("n_col")] = float(np.shape(table)[1])
            row[AERO.index("end")] = offset
            packed[id(args)] = row
        toc.append(packed[id(args)])
    view("n_stages")[:] = len(toc)
    view("toc")[:] = offset
    blocks.append(np.concatenate(toc))
    offset += blocks[-1].size
    view("gravity_work")[:] = offset
    blocks.append(np.zeros(harmonics_work(blocks[1])))
    if strips is not None:
        blocks += pack_strips(view("aeroelastic"), offset + blocks[-1].size, strips)
    view("aero")[:] = toc[0]
    view("stage")[:] = 0.0
    return np.concatenate([header, *blocks])


def stack_contexts(rows: list[np.ndarray]) -> np.ndarray:
    """Rows of possibly different lengths as one (B, n_c) array, zero-padded at the end."""
    n = max(r.size for r in rows)
    out = np.zeros((len(rows), n))
    for b, r in enumerate(rows):
        out[b, :r.size] = r
    return out
