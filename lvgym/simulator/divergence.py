"""Static aeroelastic divergence of a vehicle's bending modes under its strip-theory lift, from lvgym's own
modes (the timeline's beam solves) and strips (:meth:`~lvgym.environment.barrowman.BarrowmanAero.strips`,
as the simulator's aeroelastic loads use them, :mod:`.strips`).

In the pitch plane, quasi-static (no rates), with the rigid angle of attack ``alpha`` held and the K
mass-normalised free-free modes statically deflected (``eta``), the strip loads of
:mod:`lvgym.environment.aeroelastic` are, with ``s = qbar S`` [N], the strips' CN-alpha shares ``c_j``
[1/rad] at stations ``x_j`` [m] (x_b, from the nose tip, <= 0), ``d_j = x_j - x_cg`` [m] and the modes'
shapes ``phi_k(x_j)`` [1/sqrt(kg)] and slopes ``phi_k'(x_j)`` [1/(m sqrt(kg))] there:

    modal force   f_eta = -s (b alpha - A eta),   b_k = sum_j c_j phi_k(x_j),  A_kl = sum_j c_j phi_k(x_j) phi_l'(x_j)
    pitch moment  m_y   =  s (m0 alpha - e . eta), m0 = sum_j c_j d_j,         e_k = sum_j c_j d_j phi_k'(x_j)

(a slope towards +z lowers the local angle of attack). The modes' statics ``Omega^2 eta = f_eta`` give
``eta = -s (Omega^2 - s A)^-1 b alpha`` and the inertia-relieved pitch stiffness (the free-free modes are
orthogonal to the rigid ones, so the relief is built in)

    M_alpha,eff / s = m0 + s e^T (Omega^2 - s A)^-1 b,

negative (weathercock stable, ``m0 < 0``) for a stable vehicle at low pressure. It passes zero where
``det [[m0, -s e^T], [b, Omega^2 - s A]] = 0``, linear in ``s``: the smallest positive real eigenvalue of
that pencil is the loss of weathercock stiffness. With the attitude held (by the thrust vector control),
the modes alone diverge where ``Omega^2 - s A`` becomes singular (the smallest positive real eigenvalue of
the pencil ``(Omega^2, A)``): the static deflection per angle of attack grows without bound. The divergence
dynamic pressure ``q_div = s / S`` (:func:`divergence_qbar`) is the lower of the two; a weathercock-unstable
vehicle (``m0 >= 0``, e.g. finless, held by its thrust vector control) has only the second. On the slender
vehicle and the family's finned vehicles the first is 6-14 times lower than the second.

This is the aerodynamics-only divergence, the same quantity as ``divergence_qbar`` of the independent study
``experiments/aeroelastic_divergence/divergence.py`` ("aero only" in docs/aerodynamics.md). The follower
thrust and the axial compression, which lvgym's flight also feels, lower the divergence pressure further:
on the 2 mm slender vehicle the study finds 367-398 kPa with them against 474-511 kPa without (a factor of
about 0.78); a check built on this number must keep a margin for them (:mod:`lvgym.baselines.family`).

:func:`flight_divergence_qbar` gives ``q_div`` at times of a vehicle's flight (the modes of the mass state
of the moment, the strips of the stage in force at the flight's Mach number) and :func:`divergence_ratio`
a flight's ``qbar / q_div``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import linalg

from lvgym.errors import ConfigError
from lvgym.vehicle import MassModel, Vehicle, load_vehicle

from .strips import N_STRIPS, strip_models, strip_stations
from .tabulate import build_timeline
from .vehicleaero import stage_aerodynamics

__all__ = ["divergence_qbar", "divergence_ratio", "flight_divergence_qbar", "pitch_stiffness_ratio"]


def _terms(x_strip: Any, cna: Any, x_cg: float, phi: Any, dphi: Any) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    c = np.asarray(cna, float)
    d = np.asarray(x_strip, float) - float(x_cg)
    ph, dph = np.atleast_2d(np.asarray(phi, float)), np.atleast_2d(np.asarray(dphi, float))
    return float(c @ d), (c * d * dph).sum(axis=1), (c * ph).sum(axis=1), np.einsum("j,kj,lj->kl", c, ph, dph)


def pitch_stiffness_ratio(qbar: float, x_strip: Any, cna: Any, s_ref: float, x_cg: float, phi: Any, dphi: Any,
                          omega: Any) -> float:
    """``M_alpha,eff / M_alpha,rigid`` [-] at ``qbar`` [Pa] (module docstring): 1 at zero pressure, 0 at the
    divergence. Arguments as :func:`divergence_qbar`."""
    m0, e, b, A = _terms(x_strip, cna, x_cg, phi, dphi)
    s = float(qbar) * float(s_ref)
    eta = np.linalg.solve(np.diag(np.asarray(omega, float) ** 2) - s * A, b)
    return float((m0 + s * e @ eta) / m0)


def divergence_qbar(x_strip: Any, cna: Any, s_ref: float, x_cg: float, phi: Any, dphi: Any, omega: Any) -> float:
    """The dynamic pressure [Pa] where the inertia-relieved pitch stiffness of the statically deflected
    modes passes zero, or where the modes diverge at a held attitude, whichever is lower (module docstring);
    ``inf`` if neither happens (a weathercock-unstable vehicle, ``m0 >= 0``, has only the second).

    ``x_strip`` (n) strip stations [m] (<= 0, from the nose tip); ``cna`` (n) each strip's share of CN-alpha
    [1/rad] on ``s_ref`` [m^2]; ``x_cg`` the CG's station [m]; ``phi``, ``dphi`` (K, n) the mass-normalised
    mode shapes [1/sqrt(kg)] and slopes [1/(m sqrt(kg))] at the strips; ``omega`` (K) their frequencies
    [rad/s]."""
    m0, e, b, A = _terms(x_strip, cna, x_cg, phi, dphi)
    om = np.asarray(omega, float)
    if not (np.all(np.isfinite(om)) and np.all(om > 0.0)) or len(om) != len(b):
        raise ConfigError("omega", np.asarray(omega).tolist(), f"{len(b)} finite frequencies [rad/s] > 0")
    K = len(b)
    s_modes = _smallest_positive(np.diag(om ** 2), A)
    if m0 >= 0.0:
        return s_modes / float(s_ref)
    B0 = np.zeros((K + 1, K + 1))
    B1 = np.zeros((K + 1, K + 1))
    B0[0, 0], B0[1:, 0], B0[1:, 1:] = m0, b, np.diag(om ** 2)
    B1[0, 1:], B1[1:, 1:] = -e, -A
    return min(_smallest_positive(B0, -B1), s_modes) / float(s_ref)


def _smallest_positive(a: np.ndarray, b: np.ndarray) -> float:
    """The smallest positive real finite eigenvalue ``s`` of ``a v = s b v`` (``inf`` if none)."""
    with np.errstate(all="ignore"):
        s = linalg.eigvals(a, b)
    s = s[np.isfinite(s)]
    real = s[(np.abs(s.imag) <= 1e-9 * np.abs(s)) & (s.real > 0.0)].real
    return float(real.min()) if real.size else math.inf


def flight_divergence_qbar(vehicle: str | Vehicle, times: Any, mach: Any, mode_interval: float = 2.0,
                           n_strips: int = N_STRIPS, dt: float = 0.5) -> np.ndarray:
    """:func:`divergence_qbar` [Pa] at the flight times ``times`` [s] (B,) and Mach numbers ``mach`` (B,)
    of ``vehicle`` (a file, name or :class:`~lvgym.vehicle.Vehicle`): its bending modes recomputed every
    ``mode_interval`` [s] and at every separation (a timeline of ``dt`` [s] rows, all the file's modes, none
    cut off), its CG interpolated, and the strips (``n_strips`` per stage) of the stage in force, their
    CN-alpha shares at the Mach number (linear in the aerodynamic table's Mach grid, clamped, as the
    simulator's strip loads)."""
    v = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
    t = np.atleast_1d(np.asarray(times, float))
    m = np.broadcast_to(np.asarray(mach, float), t.shape)
    if t.size == 0 or not np.all(np.isfinite(t)) or np.any(t < 0.0):
        raise ConfigError("times", np.asarray(times).tolist(), "flight times [s] >= 0")
    stages = stage_aerodynamics(v)
    if stages[0] is None:
        raise ConfigError("aerodynamics", None, "a vehicle with aerodynamics (model: barrowman)")
    strips = strip_models(stages, n_strips)
    tl = build_timeline(MassModel(v), "nonrigid", float(t.max()) + 2.0 * dt, dt,
                        strip_stations=strip_stations(strips), mode_interval=mode_interval)
    if tl.dynamics.n_modes == 0:
        raise ConfigError("structure.n_modes", 0, "at least one bending mode")
    i_omega = tl.dynamics.layout.params["omega_modes"]
    omega = tl.params_at(t)[:, i_omega]
    x_cg = tl.interp("cg", t)[:, 0]
    phi, dphi, stage = tl.left("phi_strip", t), tl.left("dphi_strip", t), tl.left("stage", t).astype(int)
    out = np.empty(t.size)
    for j in range(t.size):
        sm = strips[stage[j]]
        cna = np.array([np.interp(m[j], sm.mach_grid, col) for col in sm.cna_table.T])
        out[j] = divergence_qbar(sm.x_strip, cna, sm.ref_area, x_cg[j], phi[j], dphi[j], omega[j])
    return out


def divergence_ratio(vehicle: str | Vehicle, times: Any, qbar: Any, mach: Any, **options: Any) -> np.ndarray:
    """A flight's ``qbar / q_div`` [-] at ``times`` [s] with its dynamic pressures ``qbar`` [Pa] and Mach
    numbers ``mach`` (:func:`flight_divergence_qbar`, ``options`` passed on): 0 where nothing diverges, 1 at
    the divergence."""
    q_div = flight_divergence_qbar(vehicle, times, mach, **options)
    return np.asarray(qbar, float) / q_div
