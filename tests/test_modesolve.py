"""The beam's eigen-solvers (lvgym.vehicle.modesolve): Lanczos against the dense solve and against eigenpairs
refined in 40-digit arithmetic; the Rayleigh quotient of the bending energy."""

import mpmath
import numpy as np
import pytest

from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.beam import PointMass, Section, DistributedMass, mesh_stack, modes
from lvgym.vehicle.beam import _assemble_band, _check_beam
from lvgym.vehicle.modesolve import (BANDWIDTH, band_matmul, band_to_dense, bending_energy, dense_modes,
                                     lanczos_modes)
from lvgym.vehicle.structure import ModeSchedule

SECTIONS = [Section(0.0, -2.0, 4.0e5, 8.0), Section(-2.0, -8.0, 2.0e6, 12.0), Section(-8.0, -10.0, 1.0e6, 10.0)]
POINTS = [PointMass(-9.6, 150.0, 3.0), PointMass(-0.7, 20.0, 0.4)]
LIQUID = [DistributedMass(-2.4, -7.8, 600.0)]


def stack_matrices():
    """x, ei, banded K and M, R, MR of the test stack on ascending nodes."""
    mesh = mesh_stack(SECTIONS, POINTS, LIQUID)
    x, ei, mpl, pm, _ = _check_beam(mesh.stations, mesh.EI, mesh.mass_per_length, mesh.point_masses)
    kb, mb = _assemble_band(x, ei, mpl, pm)
    R = np.zeros((2 * x.size, 2))
    R[0::2, 0], R[0::2, 1], R[1::2, 1] = 1.0, x, 1.0
    return x, ei, kb, mb, R, band_matmul(mb, R)


def normalised(q, M):
    q = q / np.sqrt((q * (M @ q)).sum(axis=0))
    return q * np.sign(q[-2])


def refined(K, M, q, lam, iterations=3, digits=40):
    """Eigenpair of the float64 matrices ``K``, ``M`` near ``(lam, q)``: shifted inverse iteration in
    ``digits``-digit arithmetic (banded elimination), mass-normalised, tip positive; ``(omega, q)``."""
    n, b = K.shape[0], BANDWIDTH
    with mpmath.workdps(digits):
        band = lambda A: [{j: mpmath.mpf(float(A[i, j])) for j in range(max(0, i - b), min(n, i + b + 1))}
                          for i in range(n)]
        Km, Mm = band(K), band(M)
        mul = lambda A, v: [sum(a * v[j] for j, a in row.items()) for row in A]
        shift = mpmath.mpf(float(lam)) * (1 + mpmath.mpf(1e-7))
        v = [mpmath.mpf(float(a)) for a in q]
        for _ in range(iterations):
            A = [{j: Km[i][j] - shift * Mm[i][j] for j in Km[i]} for i in range(n)]
            rhs = mul(Mm, v)
            for k in range(n):                       # elimination without pivoting, within the band
                for i in range(k + 1, min(n, k + b + 1)):
                    f = A[i][k] / A[k][k]
                    for j in range(k, min(n, k + b + 1)):
                        A[i][j] = A[i].get(j, 0) - f * A[k][j]
                    rhs[i] -= f * rhs[k]
            v = [mpmath.mpf(0)] * n
            for i in range(n - 1, -1, -1):
                v[i] = (rhs[i] - sum(A[i][j] * v[j] for j in range(i + 1, min(n, i + b + 1)))) / A[i][i]
            norm = mpmath.sqrt(sum(a * c for a, c in zip(v, mul(Mm, v))))
            v = [a / norm for a in v]
        sign = 1 if v[-2] > 0 else -1
        omega = mpmath.sqrt(sum(a * c for a, c in zip(v, mul(Km, v))))
        return float(omega), np.array([float(sign * a) for a in v])


def test_lanczos_and_dense_shapes_agree():
    x, ei, kb, mb, R, MR = stack_matrices()
    M = band_to_dense(mb)
    a, b = (normalised(f(kb, mb, R, MR, 4), M) for f in (lanczos_modes, dense_modes))
    assert np.abs(a - b).max() <= 1e-9 * np.abs(b).max()
    assert np.abs(R.T @ M @ a).max() <= 1e-10 * np.abs(MR).max() * np.abs(a).max()


def test_modes_against_a_40_digit_refinement():
    """Frequencies to 2e-11 and shapes to 1e-9 of their largest entry (measured: 1.4e-12 and 1.9e-11 here; on
    the SMILE v1 stacks 1.4e-11 and 3.4e-10, where the old dense eigenvalues were off by up to 5.5e-10)."""
    x, ei, kb, mb, R, MR = stack_matrices()
    K, M = band_to_dense(kb), band_to_dense(mb)
    mesh = mesh_stack(SECTIONS, POINTS, LIQUID)
    m = modes(mesh.stations, mesh.EI, mesh.mass_per_length, point_masses=mesh.point_masses, n_modes=3)
    for k in range(3):
        omega, q = refined(K, M, m._q[:, k], m.omega[k] ** 2)
        assert m.omega[k] == pytest.approx(omega, rel=2e-11)
        assert np.abs(m._q[:, k] - q).max() <= 1e-9 * np.abs(q).max()


def test_banded_storage_and_product():
    x, ei, kb, mb, R, MR = stack_matrices()
    M = band_to_dense(mb)
    X = np.random.default_rng(2).standard_normal((M.shape[0], 3))
    np.testing.assert_allclose(band_matmul(mb, X), M @ X, rtol=0, atol=1e-13 * np.abs(M).max() * np.abs(X).max())
    np.testing.assert_array_equal(M, M.T)
    assert np.abs(np.triu(M, BANDWIDTH + 1)).max() == 0.0


def test_bending_energy_is_q_K_q():
    x, ei, kb, mb, R, MR = stack_matrices()
    K = band_to_dense(kb)
    q = np.random.default_rng(1).standard_normal((K.shape[0], 3))
    np.testing.assert_allclose(bending_energy(x, ei, q), np.einsum("ik,ij,jk->k", q, K, q), rtol=1e-12)


def test_small_beams_take_the_dense_solve():
    """Below 2 n_modes + 20 elastic DOFs the dense solve answers (its shapes, bit for bit); Lanczos on the
    same small beam agrees with it."""
    x = np.linspace(-10.0, 0.0, 11)                                               # 20 elastic DOFs
    m = modes(x, 1e6, 10.0, n_modes=2)
    kb, mb = _assemble_band(x, np.full(10, 1e6), np.full(10, 10.0), np.zeros((0, 3)))
    R = np.zeros((22, 2))
    R[0::2, 0], R[0::2, 1], R[1::2, 1] = 1.0, x, 1.0
    MR = band_matmul(mb, R)
    dense = dense_modes(kb, mb, R, MR, 2)
    dense = dense - R @ np.linalg.solve(R.T @ MR, MR.T @ dense)
    dense = dense / np.sqrt((dense * band_matmul(mb, dense)).sum(axis=0))
    dense = dense * np.sign(dense[-2])
    np.testing.assert_array_equal(m._q, dense)
    M = band_to_dense(mb)
    np.testing.assert_allclose(normalised(lanczos_modes(kb, mb, R, MR, 2), M), dense, rtol=0, atol=1e-10)


def test_smile_v1_modes_the_schedule_reproduces():
    """A fresh solve of the same stack gives the same bits (fixed Lanczos start vector)."""
    mm = MassModel(load_vehicle("smile_v1"))
    state = mm.initial_state()
    a, b = (ModeSchedule(mm).modes(state, mm.properties(state)) for _ in range(2))
    for u, v in ((a.omega, b.omega), (a.phi_gimbal, b.phi_gimbal), (a.phi_hinge, b.phi_hinge)):
        np.testing.assert_array_equal(u, v)


def test_fine_meshes_keep_their_accuracy():
    """Uniform free-free beam (L = 10 m, EI = 1e6 N m^2, m' = 10 kg/m) against the exact roots of
    cos(bL) cosh(bL) = 1. At 400 elements the error is the discretisation's (order 4: 1.4e-11, 1.0e-10,
    4.0e-10 for modes 1-3), at 1600 the solve's floor (measured 1e-11, 2e-12, 2e-12; 4e-11 in omega_1 on
    another machine's LAPACK, 2026-12-07). The dense eigh of the projected pencil was off by 7e-8 (400) and
    1.4e-4 (1600) in omega_1."""
    from scipy.optimize import brentq
    roots = [brentq(lambda b: np.cos(b) * np.cosh(b) - 1.0, lo, lo + 1.5) for lo in (4.0, 7.0, 10.5)]
    exact = np.array(roots) ** 2 * np.sqrt(1e6 / (10.0 * 10.0 ** 4))
    for n_el, rtol in ((400, 5e-10), (1600, 1e-10)):
        m = modes(np.linspace(0.0, -10.0, n_el + 1), 1e6, 10.0, n_modes=3)
        np.testing.assert_allclose(m.omega, exact, rtol=rtol)
