"""Compiled pieces of the beam's assembly (:mod:`.beam`): the element loop and the point masses.

They do what the former array formulation did, term by term and in the same order (each entry's sum of
element terms, then the point masses one after the other), so the matrices are the same to the bit
(``tests/test_beam.py`` checks them against that formulation); one compiled call instead of some twenty
array operations, which for a beam of 80-100 nodes cost more than their arithmetic.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

__all__ = ["assemble_band_k", "band_matmul_k", "hermite_k", "subdivide_k"]

#: the entries (i, j), i <= j, of a Hermite element's 4 x 4 matrices in the order (0,0) (0,1) (0,2) (0,3)
#: (1,1) (1,2) (1,3) (2,2) (2,3) (3,3); an entry goes to LAPACK's upper banded storage at row
#: 3 + i - j, column (first DOF of the element) + j
UPPER_I = np.array([0, 0, 0, 0, 1, 1, 1, 2, 2, 3])
UPPER_J = np.array([0, 1, 2, 3, 1, 2, 3, 2, 3, 3])
#: the stiffness (times h^3 / EI) and consistent mass (times 420 / (m' h)) coefficients ``c`` of those
#: entries and the power ``p`` of the element length h in them: ``c`` (p = 0), ``c h`` (1), ``(c h) h`` (2)
K_COEF = np.array([12.0, 6.0, -12.0, 6.0, 4.0, -6.0, 2.0, 12.0, -6.0, 4.0])
M_COEF = np.array([156.0, 22.0, 54.0, -13.0, 4.0, 13.0, -3.0, 156.0, -22.0, 4.0])
H_POWER = np.array([0, 1, 0, 1, 2, 1, 2, 0, 1, 2])


@nb.njit(cache=True, nogil=True)
def hermite_k(xi, h, N, dN):
    """Hermite cubic shape functions ``N`` (P, 4) and their x-derivatives ``dN`` (P, 4) at the local
    coordinates ``xi`` (P,) in [0, 1] of elements of lengths ``h`` (P,) [m] (DOF order w1, theta1, w2,
    theta2), written into ``N`` and ``dN``."""
    for p in range(xi.size):
        x, hp = xi[p], h[p]
        xi2 = x * x
        xi3 = x * x * x
        N[p, 0] = 1.0 - 3.0 * xi2 + 2.0 * xi3
        N[p, 1] = hp * (x - 2.0 * xi2 + xi3)
        N[p, 2] = 3.0 * xi2 - 2.0 * xi3
        N[p, 3] = hp * (xi3 - xi2)
        dN[p, 0] = (6.0 * xi2 - 6.0 * x) / hp
        dN[p, 1] = 1.0 - 4.0 * x + 3.0 * xi2
        dN[p, 2] = (6.0 * x - 6.0 * xi2) / hp
        dN[p, 3] = 3.0 * xi2 - 2.0 * x


@nb.njit(cache=True, nogil=True)
def assemble_band_k(x, k_scale, m_scale, pm, pm_element, K, M, upper_i, upper_j, k_coef, m_coef, h_power):
    """Add the elements between the ascending nodes ``x`` (n,) [m] into the banded stiffness ``K`` and
    mass ``M`` (4, 2 n), zeros on entry, with ``k_scale = EI / h^3`` [N/m] and ``m_scale =
    m' h / 420`` [kg] (n - 1,): the even elements, then the odd ones; then the point masses ``pm`` (P, 3)
    (station [m], mass [kg], rotary inertia [kg m^2]), each on its element ``pm_element`` (P,) through the
    element's shape functions, one after the other. The tables are :data:`UPPER_I`, :data:`UPPER_J`,
    :data:`K_COEF`, :data:`M_COEF`, :data:`H_POWER`."""
    n_el = x.size - 1
    for first in range(2):
        for e in range(first, n_el, 2):
            he, ks, ms = x[e + 1] - x[e], k_scale[e], m_scale[e]
            for j in range(10):
                p = h_power[j]
                kc, mc = k_coef[j], m_coef[j]
                if p == 1:
                    kc, mc = kc * he, mc * he
                elif p == 2:
                    kc, mc = kc * he * he, mc * he * he
                row, col = 3 + upper_i[j] - upper_j[j], 2 * e + upper_j[j]
                K[row, col] += kc * ks
                M[row, col] += mc * ms
    P = pm.shape[0]
    if P:
        N, dN = np.empty((P, 4)), np.empty((P, 4))
        xi, hp = np.empty(P), np.empty(P)
        for p in range(P):
            e = pm_element[p]
            hp[p] = x[e + 1] - x[e]
            xi[p] = (pm[p, 0] - x[e]) / hp[p]
        hermite_k(xi, hp, N, dN)
        for p in range(P):
            e = pm_element[p]
            for j in range(10):
                a, b = upper_i[j], upper_j[j]
                M[3 + a - b, 2 * e + b] += pm[p, 1] * (N[p, a] * N[p, b]) + pm[p, 2] * (dN[p, a] * dN[p, b])


@nb.njit(cache=True, nogil=True)
def band_matmul_k(ab, X, out):
    """``out = A @ X`` (n, K) for the symmetric band matrix ``A`` of half-bandwidth 3 in upper banded
    storage ``ab`` (4, n): the diagonal term, then for each distance d = 1, 2, 3 the terms above and
    then below it, each added in that order (as :func:`.modesolve.band_matmul` formulates it)."""
    n, K = X.shape
    for i in range(n):
        for k in range(K):
            out[i, k] = ab[3, i] * X[i, k]
    for d in range(1, 4):
        for i in range(n - d):
            for k in range(K):
                out[i, k] += ab[3 - d, i + d] * X[i + d, k]
        for i in range(d, n):
            for k in range(K):
                out[i, k] += ab[3 - d, i] * X[i - d, k]


@nb.njit(cache=True, nogil=True)
def subdivide_k(kept, h):
    """Nodes [m] from the descending breakpoints ``kept`` (k,): each span cut into the fewest equal elements
    no longer than ``h`` [m], node i of a span of n at ``i ((b - a) / n) + a`` and its last node exactly
    ``b`` (as :func:`.sections._subdivide` formulated it with arrays)."""
    k = kept.size
    counts = np.empty(k - 1, dtype=np.int64)
    total = 1
    for s in range(k - 1):
        counts[s] = math.ceil((kept[s] - kept[s + 1]) / h - 1e-9)
        total += max(counts[s], 0)
    x = np.empty(total)
    x[0] = kept[0]
    j = 1
    for s in range(k - 1):
        a, b, n = kept[s], kept[s + 1], counts[s]
        if n <= 0:
            continue
        step = (b - a) / n
        for i in range(1, n):
            x[j] = i * step + a
            j += 1
        x[j] = b
        j += 1
    return x
