"""The allocation- and view-free kernels of the flight loads against the formulas they replace.

The simulator's loads read the environment models in place from the packed context (``*_at`` kernels
with offsets) instead of through array slices; these tests check that they give exactly (bit for bit)
what the former formulations gave.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from lvgym.dynamics import kernels
from lvgym.environment import make
from lvgym.environment.aerokernels import AeroAt, AirData, LoadsAt, TableAt, aero_loads_at, aero_loads_k, interp_k
from lvgym.environment.atmosphere import atmosphere_state, atmosphere_state_at
from lvgym.environment.gravity import (F_A, F_B, F_F0, F_FA, F_FB, F_FZ, P_COEF, P_DEGREE, P_GM, P_ORDER, P_RADIUS,
                                       gravity_at, gravity_k, harmonics_k, harmonics_work)
from lvgym.environment.search import search_right_k
from lvgym.environment.wind import wind_ned, wind_ned_at
from lvgym.vehicle import load_vehicle


@nb.njit(cache=True)
def _search_many(a, lo, hi, xs, out):
    for i in range(xs.size):
        out[i] = search_right_k(a, lo, hi, xs[i])


def test_search_right_is_numpy_searchsorted():
    rng = np.random.default_rng(1)
    a = np.concatenate([[-5.0, 7.0], np.sort(rng.choice(np.arange(12.0), 25)), [3.0]])   # duplicates
    lo, hi = 2, 27
    xs = np.concatenate([a[lo:hi], a[lo:hi] + 0.5, [-1.0, 0.0, 11.0, 12.0, 100.0, -np.inf, np.inf]])
    out = np.empty(xs.size, np.int64)
    _search_many(a, lo, hi, xs, out)
    np.testing.assert_array_equal(out - lo, np.searchsorted(a[lo:hi], xs, side="right"))


@nb.njit(cache=True)
def _harmonics_2d(x, y, z, p):
    """The former harmonics kernel (two (N+2, N+2) arrays allocated per call)."""
    gm, R = p[P_GM], p[P_RADIUS]
    N, M = int(p[P_DEGREE]), int(p[P_ORDER])
    K = (N + 1) * (N + 2) // 2
    n2 = N + 2
    F = p[P_COEF + 2 * K:P_COEF + 2 * K + 6 * n2 * n2].reshape((6, n2, n2))
    r2 = x * x + y * y + z * z
    rho = R / r2
    x0, y0, z0, rr = x * rho, y * rho, z * rho, R * rho
    V = np.zeros((n2, n2))
    W = np.zeros((n2, n2))
    V[0, 0] = R / math.sqrt(r2)
    for m in range(min(M + 1, N + 1) + 1):
        if m > 0:
            f = math.sqrt(3.0) if m == 1 else math.sqrt((2.0 * m + 1.0) / (2.0 * m))
            V[m, m] = f * (x0 * V[m - 1, m - 1] - y0 * W[m - 1, m - 1])
            W[m, m] = f * (x0 * W[m - 1, m - 1] + y0 * V[m - 1, m - 1])
        for n in range(m + 1, n2):
            a = F[F_A, n, m]
            V[n, m] = a * z0 * V[n - 1, m]
            W[n, m] = a * z0 * W[n - 1, m]
            if n > m + 1:
                b = F[F_B, n, m]
                V[n, m] -= b * rr * V[n - 2, m]
                W[n, m] -= b * rr * W[n - 2, m]
    ax = ay = az = u = 0.0
    for n in range(N + 1):
        for m in range(min(n, M) + 1):
            C, S = p[P_COEF + n * (n + 1) // 2 + m], p[P_COEF + K + n * (n + 1) // 2 + m]
            if C == 0.0 and S == 0.0:
                continue
            u += C * V[n, m] + S * W[n, m]
            az -= F[F_FZ, n, m] * (C * V[n + 1, m] + S * W[n + 1, m])
            if m == 0:
                f0 = F[F_F0, n, m]
                ax -= f0 * C * V[n + 1, 1]
                ay -= f0 * C * W[n + 1, 1]
            else:
                fa, fb = F[F_FA, n, m], F[F_FB, n, m]
                ax += 0.5 * (fa * (-C * V[n + 1, m + 1] - S * W[n + 1, m + 1])
                             + fb * (C * V[n + 1, m - 1] + S * W[n + 1, m - 1]))
                ay += 0.5 * (fa * (-C * W[n + 1, m + 1] + S * V[n + 1, m + 1])
                             + fb * (-C * W[n + 1, m - 1] + S * V[n + 1, m - 1]))
    s = gm / (R * R)
    return s * ax, s * ay, s * az, -gm / R * u


@nb.njit(cache=True)
def _gravity_in_place(r, t, c, o, ow, out):
    for j in range(r.shape[0]):
        out[j, 0], out[j, 1], out[j, 2] = gravity_at(r[j, 0], r[j, 1], r[j, 2], t, c, o, c, ow)


@pytest.mark.parametrize("spec", [{"model": "egm2008"}, {"model": "egm2008", "degree": 4, "order": 2},
                                  {"model": "wgs84_normal"}, {"model": "j2"}])
def test_gravity_in_place_equals_former_harmonics(spec):
    g = make("gravity", spec)
    rng = np.random.default_rng(2)
    r = rng.normal(0.0, 1.0, (50, 3))
    r *= (6.4e6 + rng.uniform(0.0, 2e5, 50))[:, None] / np.linalg.norm(r, axis=1)[:, None]
    if g.params[0] == 3.0:
        for x, y, z in r:
            assert harmonics_k(x, y, z, g.params) == _harmonics_2d(x, y, z, g.params)
    o = 7
    c = np.concatenate([np.full(o, np.nan), g.params, np.full(harmonics_work(g.params), np.nan)])
    out = np.empty((50, 3))
    _gravity_in_place(r, 12.5, c, o, o + g.params.size, out)       # scratch full of NaN: not read
    ref = np.array([gravity_k(x, y, z, 12.5, g.params) for x, y, z in r])
    np.testing.assert_array_equal(out, ref)


@nb.njit(cache=True)
def _atm_in_place(c, o, alt, out):
    for j in range(alt.size):
        atmosphere_state_at(c, o, alt[j], out, 4 * j)


@pytest.mark.parametrize("name", ["us76", "exponential"])
def test_atmosphere_in_place(name):
    p = make("atmosphere", name).params
    alt = np.array([-100.0, 0.0, 11000.0, 50e3, 85999.0, 86000.0, 150e3, 999e3, 2000e3])
    c = np.concatenate([np.full(5, np.nan), p])
    out = np.full(4 * alt.size, np.nan)
    _atm_in_place(c, 5, alt, out)
    ref = np.empty(4)
    for j, a in enumerate(alt):
        atmosphere_state(p, a, ref)
        np.testing.assert_array_equal(out[4 * j:4 * j + 4], ref)


@nb.njit(cache=True)
def _wind_in_place(c, o, alt, t, out):
    for j in range(alt.size):
        wind_ned_at(c, o, alt[j], t[j], out, 3 * j)


@pytest.mark.parametrize("spec", [
    {"model": "sum", "models": [{"model": "jet_stream"}, {"model": "dryden", "intensity": "moderate"},
                                {"model": "gust", "amplitude": 15.0, "length": 200.0, "direction_deg": 270.0,
                                 "onset": 3000.0}]},
    {"model": "profile", "altitude_m": [0.0, 500.0, 3000.0], "speed": [2.0, 10.0, 25.0],
     "direction_deg": [270.0, 250.0, 200.0]}])
def test_wind_in_place(spec):
    w = make("wind", spec)
    w.reset(np.random.default_rng(3))
    p = w.params
    alt = np.linspace(-100.0, 40e3, 60)
    t = np.linspace(0.0, 60.0, 60)
    c = np.concatenate([np.full(3, np.nan), p])
    out = np.full(3 * alt.size, np.nan)
    _wind_in_place(c, 3, alt, t, out)
    ref = np.empty(3)
    for j in range(alt.size):
        wind_ned(p, alt[j], t[j], ref)
        np.testing.assert_array_equal(out[3 * j:3 * j + 3], ref)


def _smile_aero(kind):
    model = make("aerodynamics", load_vehicle("smile").aerodynamics)
    if kind == "axisymmetric":
        return model
    return model.to_tables6(np.arange(-20.0, 20.1, 4.0), np.arange(-12.0, 12.1, 4.0))


@pytest.mark.parametrize("kind", ["axisymmetric", "tables6"])
def test_aero_in_place_equals_public_kernel(kind):
    model = _smile_aero(kind)
    p, grid, dims, table = model.kernel_args()
    packed = np.concatenate([[np.nan] * 3, p, grid, dims.astype(float), table.ravel()])
    op, og = 3, 3 + p.size
    od, ot = og + grid.size, og + grid.size + dims.size
    rng = np.random.default_rng(4)
    for _ in range(40):
        va = rng.normal(0.0, 300.0, 3)
        om = rng.normal(0.0, 0.3, 3)
        f, m, st = np.empty(3), np.empty(3), np.empty(7)
        aero_loads_k(va, om, 0.9, 330.0, -3.1, 1000.0, model.kernel_args(), f, m, st)
        out = np.full(13, np.nan)
        in_place = AeroAt(packed, op, TableAt(packed, og, packed, od, dims.size, packed, ot, table.shape[1]))
        aero_loads_at(AirData(tuple(va), tuple(om), 0.9, 330.0, -3.1, 1000.0), in_place, out, LoadsAt(0, 3, 6), False)
        np.testing.assert_array_equal(out[:6], np.concatenate([f, m]))
        np.testing.assert_array_equal(out[[8, 10, 11, 12]], st[[2, 4, 5, 6]])
        assert np.all(np.isnan(out[[6, 7, 9]]))                  # flow angles skipped at RK4 stages
        u, v, w = va
        vperp = math.sqrt(v * v + w * w)
        speed = math.sqrt(u * u + vperp * vperp)
        assert st[0] == math.atan2(w, u) and st[2] == math.atan2(vperp, u)
        assert st[4] == speed / 330.0 and st[6] == speed
        c = np.zeros(table.shape[1])                            # the table read through the former interpolation
        q = [speed / 330.0, st[2]] if kind == "axisymmetric" else [speed / 330.0, st[0], st[1], 1000.0]
        interp_k(grid, dims, table, np.array(q), c)
        assert f[0] == pytest.approx(-st[5] * p[1] * c[0], rel=1e-13, abs=1e-12)


@nb.njit(cache=True)
def _rank_ones_former(A, H, c, n):
    for q in range(H.shape[0]):
        for i in range(n):
            ci = c[q] * H[q, i]
            for k in range(i + 1):
                A[i, k] += ci * H[q, k]


@nb.njit(cache=True)
def _rank_ones_collected(A, H, c, n):
    G = np.empty((kernels.term_rows(H.shape[0])[0], n))
    for q in range(H.shape[0]):
        G[kernels.term_rows(q)[1], :] = H[q, :n]
        kernels._scaled_row(G, q, c[q], n)
    kernels._add_sym_outers(A, G, H.shape[0], n)


def test_collected_rank_one_updates_equal_successive_ones():
    rng = np.random.default_rng(5)
    n = 10
    A0 = rng.normal(size=(n, n))
    H = rng.normal(size=(24, n))
    c = rng.uniform(0.1, 300.0, 24)
    A1, A2 = A0.copy(), A0.copy()
    _rank_ones_former(A1, H, c, n)
    _rank_ones_collected(A2, H, c, n)
    np.testing.assert_array_equal(np.tril(A1), np.tril(A2))


def test_signals_and_slosh_angles_on_row_ranges_equal_one_range():
    from lvgym.envs import AscentFuncEnv, TaskSpec
    from lvgym.envs.ascent import SmileAscentEnv
    task = TaskSpec.build(SmileAscentEnv.PRESET, {"model": "nonrigid", "wind": "random", "randomize": True})
    outs = []
    for threads in (1, 3):
        func = AscentFuncEnv(task)
        func.sim.threads = threads
        rngs = [np.random.default_rng(10 + b) for b in range(24)]
        state = func.initial(rngs)
        a = np.random.default_rng(0).uniform(-1.0, 1.0, (30, 24, 2))
        res = []
        for k in range(30):
            state = func.transition(state, a[k], rngs, inplace=True)
            res.append((func.observation(state), func.reward(None, a[k], state),
                        func.transition_info(None, a[k], state)))
        outs.append((np.array([r[0] for r in res]), np.array([r[1] for r in res]), res[-1][2]["slosh_angles"]))
    for one, many in zip(*outs):
        np.testing.assert_array_equal(one, many)
