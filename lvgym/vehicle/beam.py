"""Free-free bending modes of a launch-vehicle stack: Euler-Bernoulli beam finite elements.

The dynamics core takes, per bending mode k, a natural frequency ``omega_k`` [rad/s] and the
mass-normalised mode shape ``phi_k`` [1/sqrt(kg)] and slope ``dphi_k/dx`` [1/(m sqrt(kg))] at the
gimbal and at every slosh hinge (``lvgym/dynamics/layout.py``; thesis sec. 2.2, eq. 2.10-2.13).
This module computes them for a beam of piecewise-constant sections with point masses:

* Hermite cubic elements (2 DOF per node: lateral displacement ``w`` [m] and slope
  ``theta = dw/dx`` [-]), consistent mass matrix, point masses with rotary inertia placed with the
  element shape functions (they need not sit on nodes). No shear deformation and no rotary inertia
  of the sections (Euler-Bernoulli); the beam is free at both ends.
* The two rigid-body modes (translation and rotation) are removed exactly: the generalised
  symmetric problem ``K q = omega^2 M q`` is solved on the subspace M-orthogonal to them (Lanczos on
  the banded factors of ``K`` and ``M``, :mod:`.modesolve`), so every elastic mode has zero linear and
  angular momentum. ``omega_k^2`` is the Rayleigh quotient of the computed shape, which is accurate to
  about 1e-11 where the eigensolvers' eigenvalues are not (up to 2e-9).
* Modes are mass-normalised, ``q_k^T M q_k = 1 kg``: ``phi`` is in 1/sqrt(kg), the modal coordinate
  ``eta`` in sqrt(kg) m, and the physical deflection is ``sum_k eta_k phi_k(x)``.
* Reproducible: the linear algebra runs on one BLAS thread (``threadpoolctl``). Threaded BLAS sums in an
  order that depends on the thread count, which changed the mode shapes in their last bits, and a
  60 s flight then in its fourth digit, between a serial run and one in a worker process.
* Sign: every mode has ``phi > 0`` at the nose tip (the largest station), so recomputing the modes of
  a slowly changing stack does not flip them. (Should the tip be a node of a mode, |phi| below 1e-9
  of its largest value, the largest entry is made positive instead.)
* Stations are ``x_b`` positions from the nose tip (zero or negative, metres) and slopes are
  derivatives along ``+x_b`` (toward the nose).

>>> from lvgym.vehicle.beam import modes
>>> import numpy as np
>>> x = np.linspace(0.0, -10.0, 41)                   # nodes, nose first [m]
>>> m = modes(x, EI=1e6, mass_per_length=10.0, n_modes=2, query_stations=[-10.0])
>>> np.round(m.omega / np.sqrt(1e6 / (10.0 * 10.0**4)), 3)       # (beta L)^2 of a free-free beam
array([22.373, 61.673])
>>> round(float(m.phi[0, 0] * np.sqrt(100.0)), 4)     # 2 / sqrt(M) at the free end
2.0

:func:`stack_modes` builds the mesh from :class:`Section`, :class:`PointMass` and
:class:`DistributedMass` lists (a liquid column is a distributed mass). ``python -m lvgym.vehicle.beam``
prints the comparison with the thesis's hollow aluminium beams (Tables 6.4 and 6.9).
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import ThreadpoolController

from lvgym.errors import ConfigError

from .beamkernels import H_POWER, K_COEF, M_COEF, UPPER_I, UPPER_J, assemble_band_k, hermite_k
from .modesolve import BANDWIDTH, band_matmul, band_to_dense, bending_energy, dense_modes, lanczos_modes
from .sections import (MATERIALS, BeamMesh, DistributedMass, Material, PointMass, Section, frozen_array,
                       mesh_stack, per_element, point_mass_array, stations_on, tube)

__all__ = ["PointMass", "Section", "DistributedMass", "BeamModes", "BeamMesh", "modes", "assemble",
           "mesh_stack", "stack_modes", "transfer", "thesis_comparison", "thesis_comparison_markdown"]


@functools.lru_cache(maxsize=1)
def _blas() -> ThreadpoolController:
    """The loaded BLAS libraries, found once (finding them reads every loaded library: 1-3 ms a time; the
    BLAS that numpy and scipy use is loaded when this module imports scipy.linalg)."""
    return ThreadpoolController()


_one_thread_lock = threading.Lock()
_one_thread_depth = 0
_one_thread_limiter: Any = None


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """A context in which BLAS runs on one thread (reproducible sums, see the module docstring). Nested
    contexts (a timeline's solves inside its build, :func:`lvgym.simulator.build_timeline`) cost nothing:
    the outermost one limits the threads and restores them at its end (about 20 us each)."""
    global _one_thread_depth, _one_thread_limiter
    with _one_thread_lock:
        if _one_thread_depth == 0:
            _one_thread_limiter = _blas().limit(limits=1, user_api="blas")
        _one_thread_depth += 1
    try:
        yield
    finally:
        with _one_thread_lock:
            _one_thread_depth -= 1
            if _one_thread_depth == 0:
                _one_thread_limiter.restore_original_limits()
                _one_thread_limiter = None


def _hermite(xi: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Hermite cubic shape functions ``N`` and their x-derivatives ``dN`` (shape (P, 4)) at the local
    coordinates ``xi`` (P,) in [0, 1] of elements of lengths ``h`` (P,) [m]; DOF order (w1, theta1, w2,
    theta2) (:func:`.beamkernels.hermite_k`)."""
    xi = np.ascontiguousarray(xi, dtype=float)
    N, dN = np.empty((xi.size, 4)), np.empty((xi.size, 4))
    h = np.asarray(h, dtype=float)
    hermite_k(xi, np.ascontiguousarray(h if h.shape == xi.shape else np.broadcast_to(h, xi.shape)), N, dN)
    return N, dN


def _interpolate(x: np.ndarray, q: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and x-slope at stations ``s`` (q,) of DOF vectors ``q`` (2n, K) on ascending nodes ``x``."""
    e = np.minimum(np.maximum(np.searchsorted(x, s, side="right") - 1, 0), len(x) - 2)
    h = x[e + 1] - x[e]
    N, dN = _hermite((s - x[e]) / h, h)
    qe = q[2 * e[:, None] + np.arange(4)]                        # (q, 4, K)
    return np.einsum("qi,qik->qk", N, qe), np.einsum("qi,qik->qk", dN, qe)



def _check_beam(stations, EI, mass_per_length, point_masses):
    """Validated beam on ascending nodes; ``flip`` says whether the caller's nodes were descending."""
    x = np.asarray(stations, dtype=float)
    if x.ndim != 1 or x.size < 2 or not np.isfinite(x).all():
        raise ConfigError("stations", stations, "at least two finite node stations [m]")
    d = np.diff(x)
    flip = bool(d[0] < 0.0)
    if flip:
        x, d = x[::-1], -d[::-1]
    if not (d > 0.0).all():
        raise ConfigError("stations", stations, "strictly increasing or strictly decreasing")
    if x[-1] > 1e-9 * max(1.0, x[-1] - x[0]):
        raise ConfigError("stations", float(x[-1]), "stations are measured from the nose tip: <= 0 m")
    ei = per_element(EI, x.size - 1, "EI")
    mpl = per_element(mass_per_length, x.size - 1, "mass_per_length")
    if flip:
        ei, mpl = ei[::-1], mpl[::-1]
    return x, ei, mpl, point_mass_array(point_masses, float(x[0]), float(x[-1])), flip


def _assemble_band(x: np.ndarray, ei: np.ndarray, mpl: np.ndarray, pm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and consistent mass matrices of the beam on ascending nodes ``x`` [m] in LAPACK's upper
    banded storage, ``ab[BANDWIDTH + i - j, j] = A[i, j]`` (as :mod:`.modesolve` takes them), each (4, 2n):
    each entry the sum of its elements' terms, then the point masses added one after the other
    (:func:`.beamkernels.assemble_band_k`)."""
    n_dof = 2 * x.size
    h = np.diff(x)
    K = np.zeros((BANDWIDTH + 1, n_dof))
    M = np.zeros((BANDWIDTH + 1, n_dof))
    pm = np.ascontiguousarray(pm, dtype=float).reshape(-1, 3)
    element = np.minimum(np.searchsorted(x, pm[:, 0], side="right") - 1, h.size - 1)
    assemble_band_k(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(ei / h**3, dtype=float),
                    np.ascontiguousarray(mpl * h / 420.0, dtype=float), pm, element, K, M, UPPER_I, UPPER_J,
                    K_COEF, M_COEF, H_POWER)
    return K, M


def _assemble_sorted(x: np.ndarray, ei: np.ndarray, mpl: np.ndarray, pm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dense stiffness and mass matrices of the beam on ascending nodes ``x`` [m] (:func:`_assemble_band`)."""
    return tuple(band_to_dense(ab) for ab in _assemble_band(x, ei, mpl, pm))


def assemble(stations, EI, mass_per_length, point_masses: Sequence = ()) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness matrix [N/m, N, N m] and consistent mass matrix [kg, kg m, kg m^2] of the beam.

    DOFs are ``(w_0, theta_0, w_1, theta_1, ...)`` for the nodes in the order of ``stations``, with
    ``w`` the lateral displacement [m] and ``theta = dw/dx_b`` [-]. Arguments as for :func:`modes`.
    """
    x, ei, mpl, pm, flip = _check_beam(stations, EI, mass_per_length, point_masses)
    K, M = _assemble_sorted(x, ei, mpl, pm)
    if flip:
        p = (2 * np.arange(x.size)[::-1, None] + np.arange(2)).ravel()
        K, M = K[np.ix_(p, p)], M[np.ix_(p, p)]
    return K, M



@dataclass(frozen=True, eq=False)
class BeamModes:
    """Elastic free-free modes of a beam (the two rigid-body modes excluded).

    Attributes
    ----------
    omega : ndarray (K,)
        Natural frequencies [rad/s], ascending.
    node_stations : ndarray (n,)
        Node stations [m], in the order the nodes were given (nose first from :func:`stack_modes`).
    phi_nodes, dphi_nodes : ndarray (n, K)
        Mass-normalised shape [1/sqrt(kg)] and slope d(phi)/dx_b [1/(m sqrt(kg))] at the nodes.
    query_stations : ndarray (q,)
        The stations asked for [m].
    phi, dphi : ndarray (q, K)
        Shape and slope at the query stations: ``phi[j]`` is the K-vector the dynamics core takes
        for station j (``phi_gimbal``, a slosh hinge's ``phi``).
    mass, cg_station, inertia_cg : float
        Mass [kg], CG station [m] and pitch/yaw inertia about the CG [kg m^2] of the beam model
        (sections, distributed and point masses, rotary inertia of the point masses).
    """

    omega: np.ndarray
    node_stations: np.ndarray
    phi_nodes: np.ndarray
    dphi_nodes: np.ndarray
    query_stations: np.ndarray
    phi: np.ndarray
    dphi: np.ndarray
    mass: float
    cg_station: float
    inertia_cg: float
    _x: np.ndarray = field(repr=False)      # nodes, ascending [m]
    _q: np.ndarray = field(repr=False)      # DOF vectors on ascending nodes, (2n, K)
    _mb: np.ndarray = field(repr=False)     # consistent mass matrix on the DOFs of _q, upper banded (4, 2n)

    @property
    def n_modes(self) -> int:
        """Number of elastic modes K."""
        return int(self.omega.size)

    @property
    def frequency_hz(self) -> np.ndarray:
        """Natural frequencies [Hz]."""
        return self.omega / (2.0 * math.pi)

    @property
    def max_deflection(self) -> np.ndarray:
        """Largest |phi| over the nodes per mode [1/sqrt(kg)] (the thesis's "maximum deflection")."""
        return np.abs(self.phi_nodes).max(axis=0) if self.n_modes else np.zeros(0)

    def shape_at(self, stations) -> tuple[np.ndarray, np.ndarray]:
        """Shape [1/sqrt(kg)] and slope [1/(m sqrt(kg))] at any stations on the beam, each (q, K),
        interpolated with the element shape functions."""
        s = stations_on(stations, float(self._x[0]), float(self._x[-1]), "stations")
        return _interpolate(self._x, self._q, s)


def modes(stations, EI, mass_per_length, *, point_masses: Sequence = (), n_modes: int = 3,
          query_stations=()) -> BeamModes:
    """First ``n_modes`` elastic free-free bending modes of a beam (see :func:`_modes`), computed on one
    BLAS thread so that they do not depend on the machine's thread count."""
    with one_blas_thread():
        return _modes(stations, EI, mass_per_length, point_masses=point_masses, n_modes=n_modes,
                      query_stations=query_stations)


def _modes(stations, EI, mass_per_length, *, point_masses: Sequence = (), n_modes: int = 3,
           query_stations=()) -> BeamModes:
    """First ``n_modes`` elastic free-free bending modes of a beam.

    Parameters
    ----------
    stations : array (n,)
        Node stations x_b [m] from the nose tip (<= 0), strictly decreasing (nose first) or increasing.
    EI : float or array (n - 1,)
        Bending stiffness per element [N m^2], > 0.
    mass_per_length : float or array (n - 1,)
        Mass per length per element [kg/m], > 0 (structure plus anything distributed).
    point_masses : sequence of PointMass or (station, mass[, rotary_inertia])
        Lumped masses [kg] and rotary inertias [kg m^2] anywhere on the beam.
    n_modes : int
        K >= 0, at most ``2 n - 2``.
    query_stations : array (q,)
        Stations [m] at which to report shapes and slopes (gimbal, slosh hinges, sensors).

    Returns
    -------
    BeamModes
    """
    x, ei, mpl, pm, flip = _check_beam(stations, EI, mass_per_length, point_masses)
    n_dof = 2 * x.size
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or not 0 <= n_modes <= n_dof - 2:
        raise ConfigError("n_modes", n_modes, f"an integer in [0, {n_dof - 2}] (2 x nodes - 2 rigid modes)")
    query = stations_on(query_stations, float(x[0]), float(x[-1]), "query_stations")
    kb, mb = _assemble_band(x, ei, mpl, pm)
    R = np.zeros((n_dof, 2))                     # rigid modes: translation; rotation about station 0
    R[0::2, 0] = 1.0
    R[0::2, 1] = x
    R[1::2, 1] = 1.0
    MR = band_matmul(mb, R)
    mass, first, second = R[:, 0] @ MR[:, 0], R[:, 0] @ MR[:, 1], R[:, 1] @ MR[:, 1]
    cg = first / mass
    if n_modes:
        solve = lanczos_modes if n_dof - 2 >= 2 * n_modes + 20 else dense_modes
        q = solve(kb, mb, R, MR, n_modes)
        q = q - R @ np.linalg.solve(R.T @ MR, MR.T @ q)           # exactly no rigid-body motion
        q = q / np.sqrt((q * band_matmul(mb, q)).sum(axis=0))      # q^T M q = 1
        tip = q[-2]
        big = q[np.argmax(np.abs(q[0::2]), axis=0) * 2, np.arange(n_modes)]
        sign = np.where(np.abs(tip) > 1e-9 * np.abs(big), np.sign(tip), np.sign(big))
        q = q * sign
        # omega^2 from the Rayleigh quotient of the shape (q^T M q = 1), whose error is second order in
        # the shape's: the eigensolvers' own eigenvalues are off by up to 2e-9 (see :mod:`.modesolve`)
        omega = np.sqrt(bending_energy(x, ei, q))
    else:
        q, omega = np.zeros((n_dof, 0)), np.zeros(0)
    phi_q, dphi_q = _interpolate(x, q, query)
    order = slice(None, None, -1) if flip else slice(None)
    fa = frozen_array
    return BeamModes(omega=fa(omega), node_stations=fa(x[order]), phi_nodes=fa(q[0::2][order]),
                     dphi_nodes=fa(q[1::2][order]), query_stations=fa(query), phi=fa(phi_q), dphi=fa(dphi_q),
                     mass=float(mass), cg_station=float(cg), inertia_cg=float(second - mass * cg * cg),
                     _x=fa(x), _q=fa(q), _mb=fa(mb))


def stack_modes(sections: Sequence[Section], point_masses: Sequence = (),
                distributed_masses: Sequence[DistributedMass] = (), *, n_modes: int = 3, query_stations=(),
                element_length: float | None = None) -> BeamModes:
    """Mesh the stack (:func:`mesh_stack`) and return its first ``n_modes`` elastic modes with shapes
    and slopes at ``query_stations`` [m]; the nodes of the result are nose first."""
    mesh = mesh_stack(sections, point_masses, distributed_masses, query_stations=query_stations,
                      element_length=element_length)
    return modes(mesh.stations, mesh.EI, mesh.mass_per_length, point_masses=mesh.point_masses,
                 n_modes=n_modes, query_stations=query_stations)


def transfer(old: BeamModes, new: BeamModes) -> np.ndarray:
    """Matrix ``T`` (K_new, K_old) that carries modal coordinates from the basis of ``old`` to that of
    ``new`` with the deflection field kept: ``eta_new = T eta_old``, ``T = Q_new^T M_new Q_old``.

    ``Q_old`` are the old mass-normalised shapes and slopes read at the new beam's nodes (the common
    station grid; the old element shape functions interpolate between the old nodes), ``M_new`` the new
    consistent mass matrix: ``T eta_old`` is the M_new-orthogonal projection of the old field
    ``sum_k eta_k phi_k(x)`` onto the new elastic modes. Only the part of the old beam that the new one
    covers counts (after a separation, the stack still attached); what of it is rigid-body motion of
    the new beam, or lies outside its first K_new modes, is dropped (the modal truncation). For
    ``old is new`` (or equal beams) ``T`` is the identity to rounding."""
    x = np.clip(new._x, old._x[0], old._x[-1])
    with one_blas_thread():          # reproducible sums, as :func:`modes`
        w, theta = _interpolate(old._x, old._q, x)              # (n_new, K_old) each
        q_old = np.empty((2 * x.size, old.n_modes))
        q_old[0::2], q_old[1::2] = w, theta
        return new._q.T @ band_matmul(new._mb, q_old)


# ---------------------------------------------------------------------------- thesis comparison
#: the thesis's hollow aluminium beams: (where, length [m], outer diameter [m], f1 [Hz], max |phi1| [m])
THESIS_BEAMS = (
    ("Table 6.4", 8.5, 0.26, 28.43, 0.286), ("Table 6.4", 8.5, 0.30, 32.13, 0.266),
    ("Table 6.4", 7.5, 0.26, 36.40, 0.305), ("Table 6.4", 7.5, 0.30, 41.16, 0.283),
    ("Table 6.9", 8.5, 0.10, 15.00, 0.47), ("Table 6.9", 8.5, 0.20, 23.26, 0.33),
    ("Table 6.9", 8.5, 0.30, 32.00, 0.27), ("Table 6.9", 8.5, 0.40, 41.00, 0.23),
    ("Table 6.9", 8.5, 0.50, 50.71, 0.20), ("sec. 5.1, Stratos III", 8.2, 0.28, 33.0, 0.27),
)


def thesis_comparison(material: Material = MATERIALS["al_ansys"], t_wall: float = 0.002,
                      n_elements: int = 80) -> list[dict]:
    """Our first two modes of the thesis's uniform hollow beams (free-free, no end caps).

    Each row: ``where, length, d_outer, mass`` [m, m, kg], ``f1_thesis, f1`` [Hz],
    ``defl_thesis, defl`` (max |phi_1| [1/sqrt(kg)], quoted in "m" by the thesis), ``f2`` [Hz].
    """
    rows = []
    for where, length, d, f_thesis, defl_thesis in THESIS_BEAMS:
        EI, mpl = tube(material, d, t_wall)
        m = modes(np.linspace(0.0, -length, n_elements + 1), EI, mpl, n_modes=2)
        rows.append(dict(where=where, length=length, d_outer=d, mass=m.mass, f1_thesis=f_thesis,
                         f1=float(m.frequency_hz[0]), defl_thesis=defl_thesis,
                         defl=float(m.max_deflection[0]), f2=float(m.frequency_hz[1])))
    return rows


def thesis_comparison_markdown(material: Material = MATERIALS["al_ansys"], t_wall: float = 0.002,
                               n_elements: int = 80) -> str:
    """The comparison of :func:`thesis_comparison` as a Markdown table, with our versions of the
    thesis's fits Eq. (6.2) and (6.3) over D = 0.1 ... 0.4 m at L = 8.5 m (the thesis's fit points)."""
    rows = thesis_comparison(material, t_wall, n_elements)
    out = [f"Material: {material.name}, E = {material.youngs_modulus / 1e9:g} GPa, "
           f"rho = {material.density:g} kg/m3; wall {t_wall * 1e3:g} mm; {n_elements} elements.", "",
           "| source | L [m] | D [m] | mass [kg] | f1 thesis [Hz] | f1 ours [Hz] | ratio | "
           "max phi1 thesis | max phi1 ours | ratio | f2 ours [Hz] |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['where']} | {r['length']:g} | {r['d_outer']:g} | {r['mass']:.2f} | "
                   f"{r['f1_thesis']:g} | {r['f1']:.2f} | {r['f1_thesis'] / r['f1']:.3f} | "
                   f"{r['defl_thesis']:g} | {r['defl']:.3f} | {r['defl_thesis'] / r['defl']:.3f} | "
                   f"{r['f2']:.2f} |")
    t69 = [r for r in rows if r["where"] == "Table 6.9" and r["d_outer"] < 0.45]
    d = np.array([r["d_outer"] for r in t69])
    slope, offset = np.polyfit(d, [r["f1"] for r in t69], 1)
    power, log_c = np.polyfit(np.log(d), np.log([r["defl"] for r in t69]), 1)
    out += ["", f"Fits over D = 0.1, 0.2, 0.3, 0.4 m at L = 8.5 m: ours f1 = {slope:.3f} D {offset:+.3f} Hz, "
            f"max phi1 = {math.exp(log_c):.4f} D^{power:.3f}; thesis Eq. (6.2) f1 = 86.738 D + 6.131 Hz, "
            f"Eq. (6.3) max phi1 = 0.1438 D^-0.511."]
    return "\n".join(out)


def main(argv: list[str] | None = None) -> None:
    """``lvgym vehicle beam`` (``python -m lvgym.vehicle.beam``): print :func:`thesis_comparison_markdown` (no
    options)."""
    from lvgym.commandline import parse

    @dataclass
    class Args:
        """No options."""

    parse(Args, argv, "python -m lvgym.vehicle.beam", "Print the beam's bending modes against the thesis's "
          "(Tables 6.8 and 6.9, Eq. 6.2 and 6.3) as a Markdown table.")
    print(thesis_comparison_markdown())


if __name__ == "__main__":
    main()
