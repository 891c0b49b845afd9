"""What the compiled step changes in a row at the start of a piece, besides the timeline's parameters.

:func:`.advance.advance_range` cuts every physics step at the timeline's event times and, with
``mode_basis="projected"``, at the times the bending modes are recomputed (:func:`.tabulate.build_timeline`).
At the start of each piece it

- carries the modal state across a change of basis (:func:`project_modes_k`): the modal coordinates
  ``eta`` and rates ``eta_dot`` of both planes become ``T eta`` and ``T eta_dot`` with the timeline's
  transfer matrix ``T = Phi_new^T M_new Phi_old`` of that change (:func:`lvgym.vehicle.beam.transfer`),
  so the deflection field of the attached stack is kept instead of its coordinates;
- with ``slosh_frequency="specific_force"``, sets the pendulums' damper frequency from the axial
  specific force the vehicle felt at its latest flight-condition evaluation (:func:`slosh_frequency_k`).

Each row is treated at its own time: a change applies to a row when one of its pieces starts at the
change's time, so rows of a batch stay independent.
"""

from __future__ import annotations

import math

import numba as nb

from lvgym.dynamics.layout import SLOSH_BLOCK, P, S, X
from lvgym.packing import at

from .layouts import D

#: slosh damper frequencies (``StepSetup.slosh_frequency``): 0 the timeline's, sqrt(T_0 / m / L) with the
#: vacuum thrust T_0 (v0); 1 sqrt(|a_x| / L) with the axial specific force a_x of the flight conditions
SLOSH_FREQUENCIES = ("vacuum_thrust", "specific_force")


@nb.njit(cache=True, nogil=True, inline="always")
def project_modes_k(x, T, n_slosh, n_modes, tmp):
    """``eta <- T eta`` and ``eta_dot <- T eta_dot`` in both planes of the state ``x``; ``T`` (K, K) the
    transfer matrix of one change of basis, ``tmp`` (K,) scratch."""
    K, N = n_modes, n_slosh
    for o in (at(X.eta, K, N), at(X.eta, K, N) + K, at(X.eta_dot, K, N), at(X.eta_dot, K, N) + K):
        for i in range(K):
            s = 0.0
            for k in range(K):
                s += T[i, k] * x[o + k]
            tmp[i] = s
        for i in range(K):
            x[o + i] = tmp[i]


@nb.njit(cache=True, nogil=True, inline="always")
def project_at_k(x, ta, change_t, transfer, eps, n_slosh, n_modes, tmp):
    """Apply every change of basis whose time ``change_t`` (C,) [s] is within ``eps`` [s] of the piece's
    start ``ta`` (in order; ``transfer`` (C, K, K)). The step cuts its pieces at these times, so a row
    meets each change once, at the start of the first piece after it."""
    for c in range(change_t.size):
        if abs(ta - change_t[c]) <= eps:
            project_modes_k(x, transfer[c], n_slosh, n_modes, tmp)


@nb.njit(cache=True, nogil=True, inline="always")
def axial_specific_force_k(cond, oc, p, n_slosh, n_modes):
    """Axial specific force [m/s^2] of the flight conditions ``cond[oc:]`` (layout CONDITIONS) on the
    whole vehicle of the parameters ``p``: ``(thrust_b_x + f_aero_b_x) / (m_b + sum m_j)``, thrust at
    the ambient pressure, gimbal included; negative when drag alone acts (a coast)."""
    K, N = n_modes, n_slosh
    m = p[at(P.m_b, K, N)]
    o0, blk = at(P.slosh, K, N), at(SLOSH_BLOCK, K, N)
    for j in range(N):
        m += p[o0 + j * blk + at(S.m, K, N)]
    return (cond[oc + D.thrust_b] + cond[oc + D.f_aero_b]) / m if m > 0.0 else 0.0


@nb.njit(cache=True, nogil=True, inline="always")
def slosh_frequency_k(p, scale, offset, a_x, n_slosh, n_modes):
    """Damper frequency of every pendulum in the parameters ``p`` from the axial specific force ``a_x``
    [m/s^2]: ``omega_j = sqrt(|a_x| / L_j)`` [rad/s], then the row's ``* scale + offset`` of that column
    (a dispersion of the slosh frequency). ``|a_x|``: under drag alone the liquid is pushed forward and
    the pendulum swings about the forward direction at that frequency; with ``a_x = 0`` (a drag-free
    coast) the frequency, and with it the damper, vanishes: the pendulum floats undamped. A pendulum
    without mass or length keeps 0 (before ``scale`` and ``offset``)."""
    K, N = n_modes, n_slosh
    o0, blk = at(P.slosh, K, N), at(SLOSH_BLOCK, K, N)
    for j in range(N):
        o = o0 + j * blk
        o_w = o + at(S.omega, K, N)
        m, L = p[o + at(S.m, K, N)], p[o + at(S.length, K, N)]
        w = math.sqrt(abs(a_x) / L) if (m > 0.0 and L > 0.0) else 0.0
        p[o_w] = w * scale[o_w] + offset[o_w]
