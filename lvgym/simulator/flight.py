"""Compiled flight loads: gravity, thrust and aerodynamics of one vehicle at every RK4 stage.

The dynamics core integrates with a compiled loads function ``loads_fn(t, x, p, c, u)`` (see
:mod:`lvgym.dynamics.stepper`). This module builds the simulator's: :func:`flight_conditions_k` evaluates
the environment models (through their own compiled kernels) for one state and writes a vector of
flight conditions (layout ``D_*`` below); :data:`flight_loads` turns that vector into the loads vector of
the core. The same function fills the recorded and observed conditions, so what a policy sees is what
the vehicle felt.

``c`` is the per-vehicle *context* vector (layout ``C_*``): the commands (gimbal angles, a body moment
such as reaction-control thrusters give) and thrust held over a step
and the row's start time ``c[C_TIME0]`` (the stepper's time is relative to it, so the rows of a batch
may be at different times), the aerodynamic block in force (``C_AP`` .. ``C_END``, chosen per stage from a
table of contents by :func:`select_aero_k`), a scratch block the compiled functions write into (so that an evaluation
allocates nothing; each row is only ever evaluated by one thread at a time), followed by the parameter arrays of the launch site, gravity, atmosphere, wind and aerodynamic models,
packed end to end with their start offsets in the header (rows of a batch may have different wind
blocks; shorter rows are padded). :func:`pack_context` builds it.

Thrust: ``T = max(T_0 - A_e p_amb, 0)`` with ``T_0`` and the total nozzle exit area ``A_e`` [m^2] from the
mass model's timeline and ``p_amb`` the ambient pressure at the stage's altitude. Its direction in the
undeformed engine frame (body axes) is set by the gimbal angles ``delta_p``, ``delta_y`` [rad] plus a
fixed misalignment: ``e = (cos dp cos dy, -sin dy, sin dp cos dy)`` with ``dp = delta_p + mis_p`` and
``dy = delta_y + mis_y``, so that a positive ``delta_p`` pitches the nose up about ``+y_b`` and a positive
``delta_y`` yaws it about ``+z_b`` for an engine aft of the centre of gravity.
"""

from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np

from lvgym.dynamics.stepper import compile_loads
from lvgym.environment.aerodynamics import STATE_FIELDS
from lvgym.environment.aerokernels import aero_loads_at
from lvgym.environment.atmosphere import atmosphere_state_at
from lvgym.environment.earth import SITE_SIZE, site_dcm_ni_latlon_at, site_geodetic_at, site_velocity_wrt_earth_at
from lvgym.environment.gravity import gravity_at, harmonics_work
from lvgym.environment.wind import wind_ned_at
from lvgym.rotations import quat_to_dcm

# ---------------------------------------------------------------------------- context layout
C_T0, C_AE, C_DP, C_DY, C_MIS_P, C_MIS_Y, C_AERO = 0, 1, 2, 3, 4, 5, 6
C_SITE, C_GRAV, C_ATM, C_WIND, C_AP, C_AG, C_AD, C_AT, C_NCOL, C_END = 7, 8, 9, 10, 11, 12, 13, 14, 15, 16
C_TIME0 = 17                      # start time of the row's step [s]: the stepper's t is relative to it
C_MOMENT = 18                     # commanded body moment (3) [N m], e.g. reaction-control thrusters
C_WEND = 21                       # end of the wind block
C_STAGE = 22                      # the stage whose aerodynamic block is in force (C_AP .. C_END)
C_NBLOCK = 23                     # rows of the aerodynamic table of contents (one per stage)
C_TOC = 24                        # offset of that table: per stage (o_ap, o_ag, o_ad, o_at, n_col, o_end)
C_GWORK = 25                      # offset of the gravity kernel's scratch block (spherical harmonics)
C_SCRATCH = 26                    # scratch of the compiled functions (flight conditions, a 3x3 matrix)
_TOC_KEYS = (C_AP, C_AG, C_AD, C_AT, C_NCOL, C_END)

# ---------------------------------------------------------------------------- flight conditions layout
DIAG_FIELDS = (
    ("altitude", 1), ("density", 1), ("pressure", 1), ("temperature", 1), ("speed_of_sound", 1),
    ("wind_n", 3), ("v_air_b", 3), ("alpha", 1), ("beta", 1), ("alpha_total", 1), ("phi_aero", 1),
    ("mach", 1), ("qbar", 1), ("airspeed", 1), ("f_aero_b", 3), ("m_aero_b", 3), ("f_aero_i", 3),
    ("g_i", 3), ("thrust", 1), ("thrust_e", 3),
)
DIAG: dict[str, slice] = {}
_o = 0
for _name, _size in DIAG_FIELDS:
    DIAG[_name] = slice(_o, _o + _size)
    _o += _size
N_DIAG = _o
C_SCRATCH_M = C_SCRATCH + N_DIAG
C_TRIG = C_SCRATCH_M + 9          # cache: the angles dp, dy and cos dp, sin dp, cos dy, sin dy of the thrust
C_HEADER = C_TRIG + 6
(D_ALT, D_RHO, D_PRES, D_TEMP, D_SOUND) = (DIAG[k].start for k in
                                            ("altitude", "density", "pressure", "temperature", "speed_of_sound"))
D_WIND, D_VAIR, D_ALPHA = DIAG["wind_n"].start, DIAG["v_air_b"].start, DIAG["alpha"].start
D_FAERO, D_MAERO, D_FAERO_I, D_G = (DIAG[k].start for k in ("f_aero_b", "m_aero_b", "f_aero_i", "g_i"))
D_THRUST, D_THRUST_E = DIAG["thrust"].start, DIAG["thrust_e"].start
_P_CG = 1                        # station of the CG of B in the dynamics parameter vector
_U_F, _U_M, _U_T, _U_G = 0, 3, 6, 9     # loads layout of the dynamics core (f_b_i, m_b_b, thrust_e, g_i)
assert len(STATE_FIELDS) == 7


@nb.njit(cache=True, error_model="numpy", inline="always")
def flight_conditions_at(t, x, p, c, d, od, full):
    """Flight conditions (layout ``DIAG``) of the state ``x`` at time ``t`` [s] into ``d[od:od +
    N_DIAG]`` (``d`` may be ``c``: its scratch). The models are read in place from the packed context:
    no array view, no allocation. ``full=False`` (the loads at an RK4 stage) skips the flow angles
    alpha, beta and phi_aero, which no load depends on (they are left as they were)."""
    rx, ry, rz = x[0], x[1], x[2]
    o_site, o_grav, o_atm = int(c[C_SITE]), int(c[C_GRAV]), int(c[C_ATM])
    o_wind, o_ap, o_ag, o_ad = int(c[C_WIND]), int(c[C_AP]), int(c[C_AG]), int(c[C_AD])
    o_at, n_col = int(c[C_AT]), int(c[C_NCOL])
    lat, lon, alt = site_geodetic_at(rx, ry, rz, t, c, o_site)
    d[od + D_ALT] = alt
    gx, gy, gz = gravity_at(rx, ry, rz, t, c, o_grav, c, int(c[C_GWORK]))
    d[od + D_G], d[od + D_G + 1], d[od + D_G + 2] = gx, gy, gz
    atmosphere_state_at(c, o_atm, alt, d, od + D_RHO)
    rho, pres, sound = d[od + D_RHO], d[od + D_PRES], d[od + D_SOUND]
    w = od + D_WIND
    wind_ned_at(c, o_wind, alt, t, d, w)
    wn0, wn1, wn2 = d[w], d[w + 1], d[w + 2]
    C = c[C_SCRATCH_M:C_SCRATCH_M + 9].reshape((3, 3))
    site_dcm_ni_latlon_at(lat, lon, t, c, o_site, C)
    vx, vy, vz = site_velocity_wrt_earth_at(rx, ry, rz, x[3], x[4], x[5], c, o_site)
    vr0 = vx - (C[0, 0] * wn0 + C[1, 0] * wn1 + C[2, 0] * wn2)
    vr1 = vy - (C[0, 1] * wn0 + C[1, 1] * wn1 + C[2, 1] * wn2)
    vr2 = vz - (C[0, 2] * wn0 + C[1, 2] * wn1 + C[2, 2] * wn2)
    quat_to_dcm(x[6], x[7], x[8], x[9], C)                       # C = C_ib
    va = od + D_VAIR
    for i in range(3):
        d[va + i] = C[0, i] * vr0 + C[1, i] * vr1 + C[2, i] * vr2    # v_air_b = C_ib^T v_rel_i
    u, v, w = d[va], d[va + 1], d[va + 2]
    fa, ma, st = od + D_FAERO, od + D_MAERO, od + D_ALPHA
    if c[C_AERO] != 0.0:
        aero_loads_at(u, v, w, x[10], x[11], x[12], rho, sound, p[_P_CG], alt, c, o_ap, c, o_ag, c, o_ad,
                      o_at - o_ad, c, o_at, n_col, d, fa, ma, st, full)
    else:                                                         # flow angles only
        vperp = math.sqrt(v * v + w * w)
        speed = math.sqrt(u * u + vperp * vperp)
        d[st] = math.atan2(w, u)
        d[st + 1] = math.atan2(v, math.sqrt(u * u + w * w))
        d[st + 2] = math.atan2(vperp, u)
        d[st + 3] = math.atan2(v, w) if vperp > 0.0 else 0.0
        d[st + 4] = speed / sound if sound > 0.0 else 0.0
        d[st + 5] = 0.5 * rho * speed * speed
        d[st + 6] = speed
        for i in range(3):
            d[fa + i] = 0.0
            d[ma + i] = 0.0
    for i in range(3):
        d[od + D_FAERO_I + i] = C[i, 0] * d[fa] + C[i, 1] * d[fa + 1] + C[i, 2] * d[fa + 2]
    thrust = 0.0
    if c[C_T0] > 0.0:
        thrust = max(c[C_T0] - c[C_AE] * pres, 0.0)
    d[od + D_THRUST] = thrust
    dp = c[C_DP] + c[C_MIS_P]
    dy = c[C_DY] + c[C_MIS_Y]
    if dp != c[C_TRIG] or dy != c[C_TRIG + 1]:              # the gimbal is held over an RK4 step
        c[C_TRIG], c[C_TRIG + 1] = dp, dy
        c[C_TRIG + 2], c[C_TRIG + 3] = math.cos(dp), math.sin(dp)
        c[C_TRIG + 4], c[C_TRIG + 5] = math.cos(dy), math.sin(dy)
    d[od + D_THRUST_E] = thrust * c[C_TRIG + 2] * c[C_TRIG + 4]
    d[od + D_THRUST_E + 1] = -thrust * c[C_TRIG + 5]
    d[od + D_THRUST_E + 2] = thrust * c[C_TRIG + 3] * c[C_TRIG + 4]


@nb.njit(cache=True, error_model="numpy")
def flight_conditions_k(t, x, p, c, d):
    """Flight conditions (layout ``DIAG``) of the state ``x`` at time ``t`` [s] into ``d`` (N_DIAG)."""
    flight_conditions_at(t, x, p, c, d, 0, True)


def _flight_loads(t, x, p, c, u):
    """Loads of the dynamics core from the flight conditions: aerodynamic force (inertial) and moment
    about the CG, thrust in the engine frame, gravity; no generalised modal forces."""
    flight_conditions_at(c[C_TIME0] + t, x, p, c, c, C_SCRATCH, False)
    for i in range(3):
        u[_U_F + i] = c[C_SCRATCH + D_FAERO_I + i]
        u[_U_M + i] = c[C_SCRATCH + D_MAERO + i] + c[C_MOMENT + i]
        u[_U_T + i] = c[C_SCRATCH + D_THRUST_E + i]
        u[_U_G + i] = c[C_SCRATCH + D_G + i]
    for i in range(12, u.size):
        u[i] = 0.0


flight_loads = compile_loads(_flight_loads)


@nb.njit(cache=True)
def flight_conditions_batch(t, x, p, c, d):
    """:func:`flight_conditions_k` for every row: ``t`` (B,), ``x`` (B, n_x), ``p`` (B, n_p), ``c``
    (B, n_c) into ``d`` (B, N_DIAG)."""
    for b in range(x.shape[0]):
        flight_conditions_k(t[b], x[b], p[b], c[b], d[b])


@nb.njit(cache=True, nogil=True, inline="always")
def select_aero_k(c, stage):
    """Put the aerodynamic block of ``stage`` (the lowest attached stage) in force in the context ``c``
    (stages beyond the table of contents take its last row)."""
    s = min(max(int(stage), 0), int(c[C_NBLOCK]) - 1)
    if int(c[C_STAGE]) == s:
        return
    o = int(c[C_TOC]) + 6 * s
    c[C_AP], c[C_AG], c[C_AD], c[C_AT], c[C_NCOL], c[C_END] = c[o], c[o + 1], c[o + 2], c[o + 3], c[o + 4], c[o + 5]
    c[C_STAGE] = s


def pack_context(site: np.ndarray, gravity: np.ndarray, atmosphere: np.ndarray, wind: np.ndarray,
                 aero: Any) -> np.ndarray:
    """Context vector of one vehicle from the models' parameter arrays; commands are zero.

    ``aero``: None (no aerodynamic loads), one model's ``kernel_args()``, or a list of them, one per
    stage: entry ``s`` is in force while stage ``s`` is the lowest attached one (the same tuple object
    given for several stages is packed once). Stage 0's block is in force at first."""
    per_stage = [None] if aero is None else (list(aero) if isinstance(aero, list) else [aero])
    blocks = [np.asarray(site, float), np.asarray(gravity, float), np.asarray(atmosphere, float),
              np.asarray(wind, float)]
    if blocks[0].size != SITE_SIZE:
        raise ValueError(f"site parameters have {blocks[0].size} entries: expected {SITE_SIZE}")
    header = np.zeros(C_HEADER)
    header[C_TRIG:C_TRIG + 2] = np.nan                         # the thrust angles' cache is empty
    header[C_AERO] = 0.0 if aero is None else 1.0
    offset = C_HEADER
    for key, block in zip((C_SITE, C_GRAV, C_ATM, C_WIND), blocks):
        header[key] = offset
        offset += block.size
    header[C_WEND] = offset
    packed: dict[int, list[float]] = {}
    toc = []
    for args in per_stage:
        if id(args) not in packed:
            ap, grid, dims, table = ((np.zeros(4), np.zeros(1), np.ones(1), np.zeros((1, 1))) if args is None
                                     else args)
            parts = [np.asarray(ap, float), np.asarray(grid, float), np.asarray(dims, float),
                     np.ascontiguousarray(table, float).ravel()]
            starts = []
            for part in parts:
                starts.append(offset)
                blocks.append(part)
                offset += part.size
            packed[id(args)] = [*starts, float(np.shape(table)[1]), offset]
        toc.append(packed[id(args)])
    header[C_NBLOCK] = len(toc)
    header[C_TOC] = offset
    blocks.append(np.asarray(toc, float).ravel())
    offset += blocks[-1].size
    header[C_GWORK] = offset
    blocks.append(np.zeros(harmonics_work(blocks[1])))
    for key, value in zip(_TOC_KEYS, toc[0]):
        header[key] = value
    header[C_STAGE] = 0.0
    return np.concatenate([header, *blocks])


def stack_contexts(rows: list[np.ndarray]) -> np.ndarray:
    """Rows of possibly different lengths as one (B, n_c) array, zero-padded at the end."""
    n = max(r.size for r in rows)
    out = np.zeros((len(rows), n))
    for b, r in enumerate(rows):
        out[b, :r.size] = r
    return out
