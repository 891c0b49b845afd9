"""Strip-theory aeroelastic loads in the simulator's compiled loads (thesis eq. 2.14-2.19).

With the simulator's ``aeroelastic`` option on (default: the vehicle file's ``structure.aeroelastic``)
and a model with bending modes, every RK4 stage adds to the table aerodynamics the loads of
:func:`lvgym.environment.aeroelastic.strip_loads_k` over ``N_STRIPS`` equal strips of each stage's
aerodynamic model (:meth:`~lvgym.environment.barrowman.BarrowmanAero.strips`, their CN-alpha shares
tabulated at every Mach number of the model's own table):

- the generalised modal forces ``f_eta`` of the whole strip distribution (rigid crossflow, body rate,
  deflection rate and slope: the rigid angle of attack bends the vehicle too), the core's ``f_eta`` load;
- the elastic part only of the body force and moment (the slope and deflection-rate terms,
  ``include_rigid=False``), added to the table's force and moment.

Why the table keeps the rigid loads: the table is the vehicle's full aerodynamic model (axial force,
the normal force nonlinear in the angle of attack up to 180 deg, pitch damping Cmq, its own centre of
pressure against Mach), and the v0 envs fly it; strip theory is linear in small angles and has no axial
force. Replacing the table's rigid loads by the strips' would change the rigid flight and the meaning of
``aerodynamics`` for every vehicle; adding the elastic increment keeps the rigid flight the table's and
lets the bending alone change it. The two rigid models agree where both hold (the strips sum to the
table's CN-alpha and CP, tests/test_aeroelastic.py), so ``f_eta`` is consistent with the table's loads.

Per row of a batch, the context holds (layout :data:`.layouts.AEROELASTIC`, offsets packed by
:func:`pack_strips`): each stage's strip stations, Mach grid and CN-alpha table (a table of contents of
:data:`.layouts.STRIPS` rows; the stage in force is copied into the header with the aerodynamic block),
the mode shapes and slopes at the strips of the current piece (copied from the timeline's
``phi_strip``/``dphi_strip`` row in force, which changes as the modes are recomputed) and the scratch of
the loads. The state's ``eta`` and ``eta_dot`` are read by the dynamics layout's offsets.

The row's ``normal_scale`` dispersion (layout :data:`.layouts.DISPERSION`, the ``aerodynamics`` draw of v1)
multiplies the strips' force, moment and modal forces as it multiplies the table's normal force: both come
from the same CN-alpha distribution. ``cp_shift`` moves only the table's rigid normal force: the elastic
increment acts where the bending puts it.
"""

from __future__ import annotations

from collections import namedtuple
from typing import Any

import numba as nb
import numpy as np

from lvgym.dynamics.layout import U, X
from lvgym.environment.aeroelastic import StripAeroelastic, StripLoads, StripModes, StripTable, strip_loads_k
from lvgym.errors import ConfigError
from lvgym.packing import at

from .layouts import AEROELASTIC, AEL, CTX, DS, STR, STRIPS, D

__all__ = ["N_STRIPS", "StripSetup", "pack_strips", "strip_models", "strip_stations"]

#: strips per stage (17 cm each on the 8.5 m slender vehicle: the fins' mean chord spans two)
N_STRIPS = 50
#: what :func:`pack_strips` packs: ``stages`` one :class:`StripAeroelastic` per stage, the dynamics
#: layout's ``n_modes`` (K) and ``n_slosh`` (N)
StripSetup = namedtuple("StripSetup", ["stages", "n_modes", "n_slosh"])
STRIPS_SIZE = STRIPS.size


def strip_models(stage_aerodynamics: list[Any], n: int = N_STRIPS) -> list[StripAeroelastic]:
    """One :class:`StripAeroelastic` (elastic increment, ``include_rigid=False``) per stage from the
    stage's aerodynamic model (the same object for the stages that share a model)."""
    made: dict[int, StripAeroelastic] = {}
    out = []
    for model in stage_aerodynamics:
        if id(model) not in made:
            if not hasattr(model, "strips"):
                raise ConfigError("aeroelastic", True, "an aerodynamic model with a strip distribution of its "
                                  f"normal force (model: barrowman), not {type(model).__name__}")
            mach = np.asarray(model.axes[0], dtype=float)
            x, width, _ = model.strips(float(mach[0]), n)
            per_m = np.array([model.strips(float(m), n)[2] / width for m in mach])
            made[id(model)] = StripAeroelastic(x, width, per_m, model.s_ref, mach=mach, include_rigid=False)
        out.append(made[id(model)])
    return out


def strip_stations(models: list[StripAeroelastic]) -> np.ndarray:
    """The strip stations of each stage (n_stages, n) [m]: what the timeline tabulates the modes at."""
    return np.array([m.x_strip for m in models])


def pack_strips(header: np.ndarray, offset: int, setup: StripSetup) -> list[np.ndarray]:
    """Fill the context's aeroelastic block ``header`` (layout AEROELASTIC, a view into the context
    header) for blocks that start at ``offset`` and return those blocks: each distinct stage model's
    stations, Mach grid and table, the table of contents (one STRIPS row per stage), the piece's mode
    shapes and slopes (zero until the first piece) and the scratch."""
    K, n = int(setup.n_modes), setup.stages[0].x_strip.size
    if any(m.x_strip.size != n for m in setup.stages):
        raise ValueError("every stage needs the same number of strips")
    blocks: list[np.ndarray] = []
    rows: dict[int, np.ndarray] = {}
    toc = []
    for m in setup.stages:
        if id(m) not in rows:
            row = STRIPS.zeros()
            for name, part in (("x_strip", m.x_strip), ("mach", m.mach_grid), ("cna", m.cna_table.ravel())):
                row[STRIPS.index(name)] = offset
                blocks.append(np.asarray(part, float))
                offset += part.size
            row[STRIPS.index("n_mach")] = m.mach_grid.size
            row[STRIPS.index("s_ref")] = m.ref_area
            rows[id(m)] = row
        toc.append(rows[id(m)])
    values = {"on": 1.0, "n_modes": K, "n_slosh": setup.n_slosh, "n_strip": n, "toc": offset}
    blocks.append(np.concatenate(toc))
    offset += blocks[-1].size
    for name, size in (("phi", K * n), ("dphi", K * n), ("f_eta", 2 * K), ("df", 2 * n)):
        values[name] = offset
        blocks.append(np.zeros(size))
        offset += size
    values["end"] = offset
    for name, value in values.items():
        header[AEROELASTIC.index(name)] = value
    header[AEROELASTIC.slice("strip")] = toc[0]
    return blocks


@nb.njit(cache=True, nogil=True, inline="always")
def strip_stage_k(ctx, s):
    """Put the strip block of stage ``s`` (a row of the table of contents) in force."""
    o = int(ctx[CTX.aeroelastic + AEL.toc]) + STRIPS_SIZE * s
    for i in range(STRIPS_SIZE):
        ctx[CTX.aeroelastic + AEL.strip + i] = ctx[o + i]


@nb.njit(cache=True, nogil=True, inline="always")
def strip_modes_k(ctx, phi_rows, dphi_rows, j):
    """Copy the mode shapes and slopes at the strips of timeline row ``j`` (``phi_rows``, ``dphi_rows``
    (n_rows, K, n)) into the context."""
    a = CTX.aeroelastic
    op, od = int(ctx[a + AEL.phi]), int(ctx[a + AEL.dphi])
    K, n = phi_rows.shape[1], phi_rows.shape[2]
    for k in range(K):
        for i in range(n):
            ctx[op + k * n + i] = phi_rows[j, k, i]
            ctx[od + k * n + i] = dphi_rows[j, k, i]


@nb.njit(cache=True, nogil=True, inline="always")
def strip_loads_at(x, p_cg, ctx, cond, oc):
    """Add the strips' elastic force and moment to the flight conditions ``cond[oc:]`` (``f_aero_b``,
    ``m_aero_b``, whose air data they read) of the state ``x`` with the CG of B at station ``p_cg``
    [m], and leave the modal forces in the context's scratch (:func:`strip_modal_forces_k`)."""
    a = CTX.aeroelastic
    K, N, n = int(ctx[a + AEL.n_modes]), int(ctx[a + AEL.n_slosh]), int(ctx[a + AEL.n_strip])
    ox, om = int(ctx[a + AEL.x_strip]), int(ctx[a + AEL.mach])
    n_m, oa = int(ctx[a + AEL.n_mach]), int(ctx[a + AEL.cna])
    op, od = int(ctx[a + AEL.phi]), int(ctx[a + AEL.dphi])
    oe, odf, end = int(ctx[a + AEL.f_eta]), int(ctx[a + AEL.df]), int(ctx[a + AEL.end])
    of, omb = a + AEL.f_b, a + AEL.m_b
    n_eta = odf - oe                                      # 2K modal coordinates (y plane, then z)
    o_eta, o_etad = at(X.eta, K, N), at(X.eta_dot, K, N)
    ow, va = at(X.omega_bi_b, K, N), oc + D.v_air_b
    strips = StripTable(ctx[ox:ox + n], ctx[om:om + n_m], ctx[oa:oa + n_m * n].reshape((n_m, n)), ctx[a + AEL.s_ref],
                        False)
    modes = StripModes(ctx[op:op + K * n].reshape((K, n)), ctx[od:od + K * n].reshape((K, n)),
                       x[o_eta:o_eta + n_eta], x[o_etad:o_etad + n_eta])
    loads = StripLoads(ctx[of:of + 3], ctx[omb:omb + 3], ctx[oe:odf], ctx[odf:end].reshape((n, 2)))
    strip_loads_k(cond[va:va + 3], x[ow:ow + 3], cond[oc + D.density], cond[oc + D.speed_of_sound], p_cg, strips,
                  modes, loads)
    kn = ctx[CTX.dispersion + DS.normal_scale]          # the normal-force dispersion scales every strip's CN-alpha
    if kn != 1.0:
        for i in range(3):
            ctx[of + i] *= kn
            ctx[omb + i] *= kn
        for k in range(n_eta):
            ctx[oe + k] *= kn
    for i in range(3):
        cond[oc + D.f_aero_b + i] += ctx[of + i]
        cond[oc + D.m_aero_b + i] += ctx[omb + i]


@nb.njit(cache=True, nogil=True, inline="always")
def strip_modal_forces_k(ctx, u):
    """The modal forces of the latest :func:`strip_loads_at` into the loads ``u`` (``f_eta``)."""
    a = CTX.aeroelastic
    K, N = int(ctx[a + AEL.n_modes]), int(ctx[a + AEL.n_slosh])
    o, oe, odf = at(U.f_eta, K, N), int(ctx[a + AEL.f_eta]), int(ctx[a + AEL.df])
    for k in range(odf - oe):
        u[o + k] = ctx[oe + k]

