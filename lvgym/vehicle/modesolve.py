"""Eigen-solvers of the free-free beam of :mod:`.beam`: the first few elastic modes of ``K q = omega^2 M q``.

``K`` [N/m, N, N m] and ``M`` [kg, kg m, kg m^2] are the banded (half-bandwidth 3) stiffness and consistent
mass matrices on the DOFs ``(w_0, theta_0, w_1, ...)`` of ascending nodes; ``R`` (n_dof, 2) are the two
rigid-body modes (translation, rotation) and ``MR = M R``. Both solvers return DOF vectors of the elastic
modes, lowest first, in the subspace M-orthogonal to ``R``, neither normalised nor signed (:func:`.beam.modes`
does both and takes the frequencies from :func:`bending_energy`).

* :func:`lanczos_modes` (the default): Lanczos iteration (ARPACK) on the flexibility of the beam, applied
  with banded Cholesky factors: O(n_dof) per step, about 15 steps. A SMILE beam of 97 nodes: 1 ms
  against 5 ms for the dense solve.
* :func:`dense_modes`: the dense flexibility form ``M y = (1 / omega^2) K y`` on the elastic subspace
  (``scipy.linalg.eigh``), for beams too small for Lanczos.

Accuracy, measured on the SMILE v1 stacks against eigenpairs of the same float64 ``K``, ``M`` refined in
40-digit arithmetic: the shapes of either solver are within 1e-11 ... 3e-10 of their largest entry (the
rounding of ``K q`` on a fine mesh: the float64 floor of this discretisation); the solvers' eigenvalues are
off by up to 5e-10 relative in omega, the Rayleigh quotient of :func:`bending_energy` by less than 1e-11.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh, null_space, solve_triangular
from scipy.linalg.lapack import dpbtrf, dpbtrs

__all__ = ["BANDWIDTH", "bending_energy", "dense_modes", "lanczos_modes"]

#: half-bandwidth of K and M: the Hermite elements couple the DOFs of neighbouring nodes only
BANDWIDTH = 3


def upper_band(A: np.ndarray) -> np.ndarray:
    """LAPACK's upper banded storage (``ab[BANDWIDTH + i - j, j] = A[i, j]``) of the symmetric band matrix
    ``A``."""
    ab = np.zeros((BANDWIDTH + 1, A.shape[0]))
    for d in range(BANDWIDTH + 1):
        ab[BANDWIDTH - d, d:] = np.diagonal(A, d)
    return ab


def band_to_upper(ab: np.ndarray) -> np.ndarray:
    """The dense upper-triangular matrix of an upper banded storage ``ab``."""
    n = ab.shape[1]
    out = np.zeros((n, n))
    for d in range(ab.shape[0]):
        k = ab.shape[0] - 1 - d
        out[np.arange(n - k), np.arange(k, n)] = ab[d, k:]
    return out


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


def dense_modes(K: np.ndarray, M: np.ndarray, R: np.ndarray, MR: np.ndarray, n_modes: int) -> np.ndarray:
    """DOF vectors (n_dof, n_modes) of the lowest elastic modes by a dense solve of the flexibility form
    ``M y = (1 / omega^2) K y`` on the subspace M-orthogonal to the rigid modes, whose largest eigenvalues
    are the lowest modes (found to a relative accuracy ``eps omega_k^2 / omega_1^2`` instead of the
    stiffness form's ``eps omega_max^2 / omega_k^2``)."""
    T = null_space(MR.T)                     # (n_dof, n_dof - 2): M-orthogonal to both rigid modes
    Kr, Mr = T.T @ K @ T, T.T @ M @ T
    n_r = T.shape[1]
    _, y = eigh(0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T), subset_by_index=[n_r - n_modes, n_r - 1],
                overwrite_a=True, overwrite_b=True, check_finite=False)       # K, M checked finite
    return T @ y[:, ::-1]


def lanczos_modes(K: np.ndarray, M: np.ndarray, R: np.ndarray, MR: np.ndarray, n_modes: int) -> np.ndarray:
    """DOF vectors (n_dof, n_modes) of the lowest elastic modes by Lanczos iteration on the beam's
    flexibility, without a dense factorisation.

    The flexibility on the elastic subspace is ``F = P K_c^-1 P^T``: ``P = I - R (R^T M R)^-1 (M R)^T``
    projects M-orthogonally off the rigid modes, ``K_c`` is the stiffness with the node nearest the CG
    clamped (symmetric positive definite, banded). ``P^T`` makes a load self-equilibrated (inertia
    relief), the clamped beam deflects under it, ``P`` removes the rigid-body part of that deflection; in
    exact arithmetic the clamped node does not matter, and the one nearest the CG leaves the least
    rigid-body motion to remove (clamping the tail node lost a further digit of the slopes). In the
    symmetric form ``S = U F U^T`` (``M = U^T U``, banded Cholesky) the largest eigenvalues of ``S`` are
    ``1 / omega_k^2`` of the lowest modes and ``q = U^-1 z`` their shapes. ARPACK (``eigsh``, to machine
    precision, ``tol = 0``) from a fixed start vector: the result depends on ``K`` and ``M`` only. Should
    it not converge, :func:`dense_modes` answers instead."""
    from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh  # 20-30 ms to import

    n = K.shape[0]
    g = np.linalg.inv(R.T @ MR)                              # (2, 2): the rigid-body mass matrix, inverted
    x = R[0::2, 1]                                           # node stations [m]
    c = int(np.argmin(np.abs(x - (R[:, 0] @ MR[:, 1]) / (R[:, 0] @ MR[:, 0]))))   # the node nearest the CG
    free = np.r_[0:2 * c, 2 * c + 2:n]                       # every DOF but that node's (K_c stays banded)
    kc, info_k = dpbtrf(upper_band(K[np.ix_(free, free)]))
    mc, info_m = dpbtrf(upper_band(M))
    if info_k or info_m:
        raise np.linalg.LinAlgError(f"banded Cholesky failed (clamped K: {info_k}, M: {info_m})")
    U = band_to_upper(mc)
    UR = U @ R
    relief, clear = MR @ g, UR @ g                           # (n, 2) each
    u = np.zeros(n)

    def matvec(z: np.ndarray) -> np.ndarray:
        z = z.ravel()
        f = U.T @ z - relief @ (UR.T @ z)                    # P^T U^T z: a self-equilibrated load
        u[free] = dpbtrs(kc, f[free])[0]                     # the deflection, clamped at the CG node
        return U @ u - clear @ (MR.T @ u)                    # U P u: without rigid-body motion

    op = LinearOperator((n, n), matvec=matvec, dtype=float)
    v0 = np.random.default_rng(0).standard_normal(n)
    try:
        mu, z = eigsh(op, k=n_modes, which="LA", v0=v0, ncv=min(n - 2, 2 * n_modes + 8), tol=0.0)
    except ArpackNoConvergence:
        return dense_modes(K, M, R, MR, n_modes)
    return solve_triangular(U, z[:, np.argsort(mu)[::-1]], check_finite=False)
