"""Compiled kernels of the aerodynamic tables (:mod:`.aerodynamics` documents the models and re-exports
these): multilinear table interpolation and the aerodynamic force and moment of either table kind.

:func:`aero_loads_k` takes the model's ``kernel_args()``, an :data:`AeroArrays`; :func:`aero_loads_at`
is the same kernel reading those arrays in place from packed arrays at given offsets (an :data:`AeroAt`:
the simulator's context), without array views or allocation, which is what the flight loads call at
every RK4 stage. The kernels take a few named blocks: the air data (:data:`AirData`), the model's arrays
and where the loads go (:data:`LoadsAt`).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.packing import Field, Packed

from .search import search_right_k

#: the flow state the aerodynamic kernels write, in this order (an interface: ``AeroState``)
FLOW = Packed("flow state", [
    Field("alpha", 1, "rad", "angle of attack atan2(w, u)"),
    Field("beta", 1, "rad", "sideslip atan2(v, sqrt(u^2 + w^2))"),
    Field("alpha_total", 1, "rad", "total angle of attack atan2(sqrt(v^2 + w^2), u)"),
    Field("phi_aero", 1, "rad", "aerodynamic roll angle atan2(v, w)"),
    Field("mach", 1, "-", "Mach number"),
    Field("qbar", 1, "Pa", "dynamic pressure"),
    Field("airspeed", 1, "m/s", "speed relative to the air"),
], interface=True)
_FL = FLOW.at

KIND_AXISYMMETRIC, KIND_TABLES6 = 0.0, 1.0
P_KIND, P_SREF, P_LREF, P_XREF = 0, 1, 2, 3

#: a table model's arrays (``kernel_args()``): ``params`` ``[kind, S [m^2], L [m], x_ref [m]]``, ``grid`` the
#: axes end to end, ``dims`` their lengths, ``table`` (rows of the grid points, row major; a column per
#: coefficient)
AeroArrays = namedtuple("AeroArrays", ["params", "grid", "dims", "table"])
#: a table read in place from packed arrays: the axes at ``grid[o_grid:]``, their ``n_dims`` lengths at
#: ``dims[o_dims:]`` (integers or whole floats), the table row major with ``n_col`` columns at ``table[o_table:]``
TableAt = namedtuple("TableAt", ["grid", "o_grid", "dims", "o_dims", "n_dims", "table", "o_table", "n_col"])
#: a table model read in place: its ``params`` (as :data:`AeroArrays`) at ``params[o_params:]`` and its
#: :data:`TableAt` ``table``
AeroAt = namedtuple("AeroAt", ["params", "o_params", "table"])
#: the air data of one evaluation (numbers): ``v_air_b`` (u, v, w) [m/s] the velocity relative to the air,
#: body axes; ``omega_bi_b`` (3) [rad/s]; ``rho`` [kg/m^3]; ``sound`` speed of sound [m/s]; ``x_cg`` CG
#: station [m]; ``alt`` altitude [m] (only for ``tables6`` with an altitude axis; anything otherwise)
AirData = namedtuple("AirData", ["v_air_b", "omega_bi_b", "rho", "sound", "x_cg", "alt"])
#: where :func:`aero_loads_at` writes into its output array: the offsets of the force ``f_b`` (3), the
#: moment ``m_b`` (3) and the flow state ``flow`` (layout :data:`FLOW`)
LoadsAt = namedtuple("LoadsAt", ["f_b", "m_b", "flow"])


@nb.njit(cache=True)
def interp_at(tab, q, out):
    """:func:`interp_k` on the table ``tab`` (a :data:`TableAt`) read in place from packed arrays."""
    grid, og, dims, od, nd = tab.grid, tab.o_grid, tab.dims, tab.o_dims, tab.n_dims
    table, ot, ncol = tab.table, tab.o_table, tab.n_col
    idx = np.zeros(nd, np.int64)
    wgt = np.zeros(nd)
    stride = np.ones(nd, np.int64)
    off = og
    for d in range(nd):
        n = int(dims[od + d])
        if n > 1:
            x = q[d]
            if x >= grid[off + n - 1]:
                idx[d], wgt[d] = n - 2, 1.0
            elif x > grid[off]:
                i = search_right_k(grid, off, off + n, x) - off - 1
                idx[d] = i
                wgt[d] = (x - grid[off + i]) / (grid[off + i + 1] - grid[off + i])
        off += n
    for d in range(nd - 2, -1, -1):
        stride[d] = stride[d + 1] * int(dims[od + d + 1])
    for c in range(ncol):
        out[c] = 0.0
    for corner in range(1 << nd):
        weight = 1.0
        row = 0
        for d in range(nd):
            bit = (corner >> d) & 1
            if bit == 1:
                if dims[od + d] == 1:
                    weight = 0.0
                    break
                weight *= wgt[d]
            else:
                weight *= 1.0 - wgt[d]
            row += (idx[d] + bit) * stride[d]
        if weight != 0.0:
            for c in range(ncol):
                out[c] += weight * table[ot + row * ncol + c]


@nb.njit(cache=True)
def interp_k(grid, dims, table, q, out):
    """Multilinear interpolation of every column of ``table`` at the point ``q`` (one value per
    axis), clamped to the grid; axes of length 1 are constant. Writes ``out[:table.shape[1]]``."""
    # dims may be integers or whole floats (a packed context)
    interp_at(TableAt(grid, 0, dims, 0, dims.shape[0], table.ravel(), 0, table.shape[1]), q, out)


@nb.njit(cache=True, inline="always")
def _axis_k(grid, off, n, x):
    """Index ``i``, next index and weight of ``x`` on the axis ``grid[off:off+n]`` (clamped)."""
    if n <= 1 or x <= grid[off]:
        return 0, min(1, n - 1), 0.0
    if x >= grid[off + n - 1]:
        return n - 2, n - 1, 1.0
    i = search_right_k(grid, off, off + n, x) - off - 1
    return i, i + 1, (x - grid[off + i]) / (grid[off + i + 1] - grid[off + i])


@nb.njit(cache=True, inline="always")
def _axisymmetric_k(tab, mach, alpha_t, x_ref, x_cg, l_ref):
    """``CA, CN, Cm, Cmq, Clp`` of an axisymmetric table (a :data:`TableAt`, read in place) at (Mach,
    total angle of attack), with Cmq moved from ``x_ref`` to the CG (see the module docstring);
    bilinear, without allocation (the same values as :func:`interp_k`)."""
    grid, og, dims, od, table, ot, nc = tab.grid, tab.o_grid, tab.dims, tab.o_dims, tab.table, tab.o_table, tab.n_col
    nm, na = int(dims[od]), int(dims[od + 1])
    i0, i1, wm = _axis_k(grid, og, nm, mach)
    j0, j1, wa = _axis_k(grid, og + nm, na, alpha_t)
    w00, w01, w10, w11 = (1.0 - wm) * (1.0 - wa), (1.0 - wm) * wa, wm * (1.0 - wa), wm * wa
    r00, r01 = ot + (i0 * na + j0) * nc, ot + (i0 * na + j1) * nc
    r10, r11 = ot + (i1 * na + j0) * nc, ot + (i1 * na + j1) * nc
    ca = w00 * table[r00] + w01 * table[r01] + w10 * table[r10] + w11 * table[r11]
    cn = w00 * table[r00 + 1] + w01 * table[r01 + 1] + w10 * table[r10 + 1] + w11 * table[r11 + 1]
    cm = w00 * table[r00 + 2] + w01 * table[r01 + 2] + w10 * table[r10 + 2] + w11 * table[r11 + 2]
    cmq = w00 * table[r00 + 3] + w01 * table[r01 + 3] + w10 * table[r10 + 3] + w11 * table[r11 + 3]
    clp = w00 * table[r00 + 4] + w01 * table[r01 + 4] + w10 * table[r10 + 4] + w11 * table[r11 + 4]
    if cmq != 0.0 and na > 1:
        # static slopes about x_ref from the table's first nonzero angle, at this Mach
        a1 = grid[og + nm + 1]
        q0, q1 = ot + (i0 * na + 1) * nc, ot + (i1 * na + 1) * nc
        cn1 = (1.0 - wm) * table[q0 + 1] + wm * table[q1 + 1]
        cm1 = (1.0 - wm) * table[q0 + 2] + wm * table[q1 + 2]
        dl = (x_ref - x_cg) / l_ref
        cmq = cmq - 4.0 * dl * cm1 / a1 - 2.0 * dl * dl * cn1 / a1
    return ca, cn, cm, cmq, clp


@nb.njit(cache=True, inline="always")
def aero_loads_at(air, model, out, dest, full):
    """:func:`aero_loads_k` on arrays read in place: the air data ``air`` (an :data:`AirData`), the model
    ``model`` (an :data:`AeroAt`); writes ``f_b``, ``m_b``, ``state`` into ``out`` at the offsets ``dest``
    (a :data:`LoadsAt`: ``out[f_b:f_b + 3]``, ``out[m_b:m_b + 3]``, ``out[flow:flow + 7]``; with ``full``
    false, alpha, beta and phi_a are not written: no load depends on them). The axisymmetric kind
    allocates nothing."""
    u, v, w = air.v_air_b
    p0, p1, p2 = air.omega_bi_b
    rho, sound, x_cg = air.rho, air.sound, air.x_cg
    p, op, tab = model.params, model.o_params, model.table
    of, om, os = dest.f_b, dest.m_b, dest.flow
    vperp = math.sqrt(v * v + w * w)
    speed = math.sqrt(u * u + vperp * vperp)
    alpha_t = math.atan2(vperp, u)
    mach = speed / sound if sound > 0.0 else 0.0
    qbar = 0.5 * rho * speed * speed
    s_ref, l_ref = p[op + P_SREF], p[op + P_LREF]
    qs = qbar * s_ref
    kd = 0.25 * rho * speed * s_ref * l_ref * l_ref          # damping: qbar S L * L / (2 V)
    if p[op + P_KIND] == KIND_AXISYMMETRIC:
        ca, cn, cm, cmq, clp = _axisymmetric_k(tab, mach, alpha_t, p[op + P_XREF], x_cg, l_ref)
        sp, cp = (v / vperp, w / vperp) if vperp > 0.0 else (0.0, 1.0)
        out[of] = -qs * ca
        out[of + 1] = -qs * cn * sp
        out[of + 2] = -qs * cn * cp
        out[om] = kd * clp * p0
        out[om + 1] = qs * l_ref * cm * cp + kd * cmq * p1
        out[om + 2] = -qs * l_ref * cm * sp + kd * cmq * p2
    else:
        c = np.zeros(tab.n_col)
        q = np.array([mach, math.atan2(w, u), math.atan2(v, math.sqrt(u * u + w * w)), air.alt])
        interp_at(tab, q, c)
        out[of] = -qs * c[0]
        out[of + 1] = qs * c[1]
        out[of + 2] = -qs * c[2]
        out[om] = qs * l_ref * c[3] + kd * c[6] * p0
        out[om + 1] = qs * l_ref * c[4] + kd * c[7] * p1
        out[om + 2] = qs * l_ref * c[5] + kd * c[8] * p2
    d = p[op + P_XREF] - x_cg                                # m_cg = m_ref + d e_x x f
    out[om + 1] -= d * out[of + 2]
    out[om + 2] += d * out[of + 1]
    if full:
        out[os + _FL.alpha] = math.atan2(w, u)
        out[os + _FL.beta] = math.atan2(v, math.sqrt(u * u + w * w))
        out[os + _FL.phi_aero] = math.atan2(v, w) if vperp > 0.0 else 0.0
    out[os + _FL.alpha_total] = alpha_t
    out[os + _FL.mach] = mach
    out[os + _FL.qbar] = qbar
    out[os + _FL.airspeed] = speed


@nb.njit(cache=True)
def aero_loads_k(v_air_b, omega_bi_b, rho, sound, x_cg, alt, model, f_b, m_b, state):
    """Aerodynamic force ``f_b`` [N] and moment about the CG ``m_b`` [N m] (body frame) of either
    table kind, written into the 3-vectors ``f_b``, ``m_b``; ``state`` (7) receives alpha, beta,
    alpha_t, phi_a [rad], Mach [-], qbar [Pa], airspeed [m/s].

    ``v_air_b`` (3) [m/s] vehicle velocity relative to the air, body axes; ``omega_bi_b`` (3)
    [rad/s]; ``rho`` [kg/m^3]; ``sound`` speed of sound [m/s]; ``x_cg`` CG station [m]; ``alt``
    altitude [m] (only for ``tables6`` with an altitude axis; anything otherwise); ``model`` the
    model's :data:`AeroArrays` (``kernel_args()``).
    """
    out = np.empty(13)
    p, grid, dims, table = model
    air = AirData((v_air_b[0], v_air_b[1], v_air_b[2]), (omega_bi_b[0], omega_bi_b[1], omega_bi_b[2]), rho, sound,
                  x_cg, alt)
    tab = TableAt(grid, 0, dims, 0, dims.shape[0], table.ravel(), 0, table.shape[1])
    aero_loads_at(air, AeroAt(p, 0, tab), out, LoadsAt(0, 3, 6), True)
    for i in range(3):
        f_b[i] = out[i]
        m_b[i] = out[3 + i]
    for i in range(7):
        state[i] = out[6 + i]


@nb.njit(cache=True)
def aero_loads_batch(v_air_b, omega_bi_b, rho, sound, x_cg, alt, model, f_b, m_b, state):
    """:func:`aero_loads_k` over a leading batch axis of every per-vehicle argument (``model`` shared)."""
    for j in range(v_air_b.shape[0]):
        aero_loads_k(v_air_b[j], omega_bi_b[j], rho[j], sound[j], x_cg[j], alt[j], model, f_b[j], m_b[j], state[j])
