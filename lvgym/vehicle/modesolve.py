"""Eigen-solvers of the free-free beam of :mod:`.beam`: the first few elastic modes of ``K q = omega^2 M q``.

``K`` [N/m, N, N m] and ``M`` [kg, kg m, kg m^2] are the stiffness and consistent mass matrices on the DOFs
``(w_0, theta_0, w_1, ...)`` of ascending nodes, symmetric with half-bandwidth 3 and passed in LAPACK's upper
banded storage ``ab[BANDWIDTH + i - j, j] = A[i, j]`` (4, n_dof); ``R`` (n_dof, 2) are the two rigid-body
modes (translation, rotation) and ``MR = M R``. Both solvers return DOF vectors of the elastic
modes, lowest first, in the subspace M-orthogonal to ``R``, neither normalised nor signed (:func:`.beam.modes`
does both and takes the frequencies from :func:`bending_energy`).

* :func:`lanczos_modes` (the default): Lanczos iteration (ARPACK) on the flexibility of the beam, applied
  with banded Cholesky factors: O(n_dof) per step, 13 steps for two modes. A 97-node SMILE beam: 0.5 ms
  (all of :func:`.beam.modes` 1 ms, against 5-6 ms with the dense solve).
* :func:`dense_modes`: the dense flexibility form ``M y = (1 / omega^2) K y`` on the elastic subspace
  (``scipy.linalg.eigh``), for beams too small for Lanczos.

Accuracy, measured on the SMILE v1 and slender v1 stacks against eigenpairs of the same float64 ``K``, ``M``
refined in 40-digit arithmetic: the shapes of either solver are within 1e-11 ... 5e-10 of their largest entry
(the rounding of ``K q`` on a fine mesh: the float64 floor of this discretisation); the dense solver's
eigenvalues are off by up to 2e-9 relative in omega (5e-10 on SMILE v1), the Rayleigh quotient of
:func:`bending_energy` by less than 2e-11.
"""

from __future__ import annotations

import functools
import inspect
from typing import Any

import numpy as np
from scipy.linalg import eigh, null_space
from scipy.linalg.blas import dtbmv
from scipy.linalg.lapack import dpbtrf, dpbtrs, dtbtrs

from .beamkernels import band_matmul_k

__all__ = ["BANDWIDTH", "band_matmul", "band_to_dense", "bending_energy", "dense_modes", "lanczos_modes"]

#: half-bandwidth of K and M: the Hermite elements couple the DOFs of neighbouring nodes only
BANDWIDTH = 3


def band_to_dense(ab: np.ndarray) -> np.ndarray:
    """The dense symmetric matrix of an upper banded storage ``ab``."""
    n = ab.shape[1]
    out = np.zeros((n, n))
    for d in range(BANDWIDTH + 1):
        i = np.arange(n - d)
        out[i, i + d] = out[i + d, i] = ab[BANDWIDTH - d, d:]
    return out


def band_matmul(ab: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``A @ X`` for the symmetric band matrix ``A`` of upper banded storage ``ab`` and ``X`` (n,) or (n, K):
    ``A[i, i] X[i]``, then for d = 1 .. 3 the terms ``A[i, i + d] X[i + d]`` and then ``A[i, i - d] X[i - d]``
    added in turn (:func:`.beamkernels.band_matmul_k`)."""
    X = np.asarray(X, dtype=float)
    X2 = np.ascontiguousarray(X.reshape(X.shape[0], -1))
    out = np.empty_like(X2)
    band_matmul_k(np.ascontiguousarray(ab, dtype=float), X2, out)
    return out.reshape(X.shape)


def clamped_band(kb: np.ndarray, node: int) -> np.ndarray:
    """The banded stiffness ``kb`` with the DOFs of ``node`` clamped: their rows and columns zero, their
    diagonal 1, so that ``K_c u = f`` with ``f = 0`` at those DOFs gives ``u = 0`` there and the clamped
    beam's deflection elsewhere (the Cholesky factor of the other DOFs is that of ``K`` without the rows
    and columns, to the bit: the eliminations only subtract zeros)."""
    ab = kb.copy()
    n = ab.shape[1]
    for dof in (2 * node, 2 * node + 1):
        for d in range(BANDWIDTH + 1):
            if dof + d < n:
                ab[BANDWIDTH - d, dof + d] = 0.0             # row dof, column dof + d
            if dof - d >= 0:
                ab[BANDWIDTH - d, dof] = 0.0                 # row dof - d, column dof
        ab[BANDWIDTH, dof] = 1.0
    return ab


def bending_energy(x: np.ndarray, ei: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``q^T K q`` per column of ``q`` (2n, K) on ascending nodes ``x`` [m] with element stiffnesses ``ei``
    [N m^2]: twice the strain energy [J/kg for mass-normalised shapes, i.e. omega^2 in rad^2/s^2], summed
    element by element as ``integral(EI w''^2) = EI / h ((theta_2 - theta_1)^2
    + 3 (theta_1 + theta_2 - 2 (w_2 - w_1) / h)^2)`` (a Hermite element's curvature is linear: its mean and
    its end-to-end difference). A sum of squares, so without the cancellation of ``q^T (K q)``, whose
    entries of ``K q`` are differences of terms ``omega_max^2 / omega_k^2`` times larger (rounding noise
    of about 1e-10 in ``omega_1^2``)."""
    h = np.diff(x)[:, None]
    w, theta = q[0::2], q[1::2]
    mean = theta[1:] - theta[:-1]
    skew = theta[:-1] + theta[1:] - 2.0 * (w[1:] - w[:-1]) / h
    return ((ei[:, None] / h) * (mean * mean + 3.0 * skew * skew)).sum(axis=0)


def dense_modes(kb: np.ndarray, mb: np.ndarray, R: np.ndarray, MR: np.ndarray, n_modes: int) -> np.ndarray:
    """DOF vectors (n_dof, n_modes) of the lowest elastic modes by a dense solve of the flexibility form
    ``M y = (1 / omega^2) K y`` on the subspace M-orthogonal to the rigid modes, whose largest eigenvalues
    are the lowest modes (found to a relative accuracy ``eps omega_k^2 / omega_1^2`` instead of the
    stiffness form's ``eps omega_max^2 / omega_k^2``)."""
    K, M = band_to_dense(kb), band_to_dense(mb)
    T = null_space(MR.T)                     # (n_dof, n_dof - 2): M-orthogonal to both rigid modes
    Kr, Mr = T.T @ K @ T, T.T @ M @ T
    n_r = T.shape[1]
    _, y = eigh(0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T), subset_by_index=[n_r - n_modes, n_r - 1],
                overwrite_a=True, overwrite_b=True, check_finite=False)       # K, M checked finite
    return T @ y[:, ::-1]


@functools.lru_cache(maxsize=1)
def _flexibility_operator() -> type:
    """A ``LinearOperator`` whose ``matvec`` is the given function itself, without the checks and
    reshapes of the generic one (ARPACK passes a 1-D vector of the right size 13 times a solve), defined
    at first use (``scipy.sparse.linalg`` takes 20-30 ms to import)."""
    from scipy.sparse.linalg import LinearOperator

    class Flexibility(LinearOperator):
        def __init__(self, shape: tuple[int, int], matvec: Any, dtype: Any) -> None:
            super().__init__(dtype=np.dtype(dtype), shape=shape)
            self._apply = matvec

        def _matvec(self, x: np.ndarray) -> np.ndarray:
            return self._apply(x)

        def matvec(self, x: np.ndarray) -> np.ndarray:
            return self._apply(x)

    return Flexibility


@functools.lru_cache(maxsize=1)
def _eigsh_takes_rng() -> bool:
    """Whether ``scipy.sparse.linalg.eigsh`` has an ``rng`` argument (SciPy >= 1.15), looked up once."""
    from scipy.sparse.linalg import eigsh
    return "rng" in inspect.signature(eigsh).parameters


def lanczos_modes(kb: np.ndarray, mb: np.ndarray, R: np.ndarray, MR: np.ndarray, n_modes: int) -> np.ndarray:
    """DOF vectors (n_dof, n_modes) of the lowest elastic modes by Lanczos iteration on the beam's
    flexibility, without a dense factorisation.

    The flexibility on the elastic subspace is ``F = P K_c^-1 P^T``: ``P = I - R (R^T M R)^-1 (M R)^T``
    projects M-orthogonally off the rigid modes, ``K_c`` is the stiffness with the node nearest the CG
    clamped (symmetric positive definite, banded). ``P^T`` makes a load self-equilibrated (inertia
    relief), the clamped beam deflects under it, ``P`` removes the rigid-body part of that deflection; in
    exact arithmetic the clamped node does not matter, and the one nearest the CG leaves the least
    rigid-body motion to remove (clamping the tail node made the slopes' errors up to 4 times larger). In the
    symmetric form ``S = U F U^T`` (``M = U^T U``, banded Cholesky) the largest eigenvalues of ``S`` are
    ``1 / omega_k^2`` of the lowest modes and ``q = U^-1 z`` their shapes. ARPACK (``eigsh``, to machine
    precision, ``tol = 0``) from a fixed start vector: the result depends on ``K`` and ``M`` only. Should
    it not converge, :func:`dense_modes` answers instead."""
    from scipy.sparse.linalg import ArpackNoConvergence, eigsh  # 20-30 ms to import

    n = kb.shape[1]
    g = np.linalg.inv(R.T @ MR)                              # (2, 2): the rigid-body mass matrix, inverted
    x = R[0::2, 1]                                           # node stations [m]
    c = int(np.argmin(np.abs(x - (R[:, 0] @ MR[:, 1]) / (R[:, 0] @ MR[:, 0]))))   # the node nearest the CG
    clamped = slice(2 * c, 2 * c + 2)
    kc, info_k = dpbtrf(clamped_band(kb, c))
    mc, info_m = dpbtrf(mb)                                  # M = U^T U, U upper banded
    if info_k or info_m:
        raise np.linalg.LinAlgError(f"banded Cholesky failed (clamped K: {info_k}, M: {info_m})")
    UR = np.column_stack([dtbmv(BANDWIDTH, mc, r) for r in R.T])
    relief = MR @ g                                          # (n, 2)

    def matvec(z: np.ndarray) -> np.ndarray:
        z = z.ravel()
        f = dtbmv(BANDWIDTH, mc, z, trans=1) - relief @ (UR.T @ z)   # P^T U^T z: a self-equilibrated load
        f[clamped] = 0.0
        u = dpbtrs(kc, f)[0]                                 # the deflection, clamped at the CG node
        return dtbmv(BANDWIDTH, mc, u - R @ (g @ (MR.T @ u)))         # U P u: without rigid-body motion

    op = _flexibility_operator()((n, n), matvec, float)
    rng = np.random.default_rng(0)
    # SciPy >= 1.15 takes the generator too (else it draws its own from OS entropy, 0.2 ms a call, unused
    # as v0 is given); older ones have no rng argument. The start vector is v0 either way.
    seeded = {"rng": rng} if _eigsh_takes_rng() else {}
    try:
        mu, z = eigsh(op, k=n_modes, which="LA", v0=rng.standard_normal(n), ncv=min(n - 2, 2 * n_modes + 8),
                      tol=0.0, **seeded)
    except ArpackNoConvergence:
        return dense_modes(kb, mb, R, MR, n_modes)
    q, info = dtbtrs(mc, z[:, np.argsort(mu)[::-1]])        # q = U^-1 z
    if info:
        raise np.linalg.LinAlgError(f"banded triangular solve failed ({info})")
    return q
