"""Compiled fixed-step integration of a batch of vehicles.

``rk4`` is the classical fourth-order Runge-Kutta scheme applied in the interaction frame of the
bending oscillators (the integrating-factor or Lawson RK4 of Cox & Matthews, J. Comput. Phys. 176,
2002): the free, damped modal oscillators ``eta_ddot + 2 Z Omega eta_dot + Omega^2 eta = 0`` are
propagated exactly over each stage and RK4 integrates everything else, including every coupling
into the modes. With no modes it is exactly classical RK4. It keeps fourth order, but the step is no
longer bounded by the highest bending frequency, and the modes are not artificially damped (classical
RK4 loses ``(Omega h)^6 / 72`` of a mode's energy per step: 1.5e-4 of a 15 Hz mode over 15 s at 1 ms).
``rk4-classic`` is the plain scheme, kept for comparison.

Loads come from a compiled loads function ``loads_fn(t, x, p, c, u)`` evaluated at every RK4 stage:
it writes the loads ``u`` of one vehicle from the stage time, state, parameters and the caller's
command/context vector ``c``. The default ``zoh_loads`` copies ``c`` (loads held over the step); a
simulator whose loads depend on the state (gravity with altitude, aerodynamics) compiles its own
with ``compile_loads`` and hands it to the same ``step_batch``. Loads functions are numba ``cfunc``
objects of ``LOADS_SIGNATURE``, so the stepper is compiled once and cached on disk.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.core import cgutils, types
from numba.extending import intrinsic
from numba.np.arrayobj import make_array

from .kernels import P_MODES, X_ETA, X_Q, make_workspace, vehicle_deriv

METHODS = ("rk4", "rk4-classic")


_vec = nb.types.float64[::1]
#: signature of a loads function ``loads_fn(t, x, p, c, u) -> None``
LOADS_SIGNATURE = nb.types.void(nb.types.float64, _vec, _vec, _vec, _vec)


@intrinsic
def unowned(typingctx, a):
    """A view of the array ``a`` that holds no reference to its memory (a null meminfo).

    Numba increments and decrements the reference count of every array view it makes and of every
    array argument of a compiled function it calls, with atomic instructions on the owner's counter;
    rows of one batch share that counter, so the threads that step row ranges contend for it. Passing
    unowned views of the rows to the per-stage functions (the loads, the derivative) makes those
    updates no-ops. The caller must keep ``a``'s owner alive while the view is in use."""
    if not isinstance(a, types.Array):
        return None

    def codegen(context, builder, sig, args):
        src = make_array(a)(context, builder, value=args[0])
        dst = make_array(a)(context, builder)
        dst.meminfo = cgutils.get_null_value(dst.meminfo.type)
        dst.parent = cgutils.get_null_value(dst.parent.type)
        dst.nitems = src.nitems
        dst.itemsize = src.itemsize
        dst.data = src.data
        dst.shape = src.shape
        dst.strides = src.strides
        return dst._getvalue()

    return a(a), codegen


def compile_loads(fn):
    """Compile a Python loads function ``fn(t, x, p, c, u)`` (numba-compatible code) for the
    stepper."""
    return nb.cfunc(LOADS_SIGNATURE, cache=True)(fn)


def _zoh(t, x, p, c, u):
    """Default loads function: the loads are the command vector, held over the step."""
    for i in range(u.size):
        u[i] = c[i]


zoh_loads = compile_loads(_zoh)


@nb.njit(cache=True, error_model="numpy")
def modal_propagator(p, n_modes, tau, E):
    """``E[k] = expm(L_k tau)`` for ``L_k = [[0, 1], [-Omega_k^2, -2 Z_k Omega_k]]``."""
    K = n_modes
    for k in range(K):
        om = p[P_MODES + k]
        ze = p[P_MODES + K + k]
        a = ze * om
        d2 = om * om * (1.0 - ze * ze)
        if d2 > 1e-300:
            d = math.sqrt(d2)
            c = math.cos(d * tau)
            s = math.sin(d * tau) / d
        elif d2 < -1e-300:
            d = math.sqrt(-d2)
            c = math.cosh(d * tau)
            s = math.sinh(d * tau) / d
        else:
            c = 1.0
            s = tau
        e = math.exp(-a * tau)
        E[k, 0, 0] = e * (c + s * a)
        E[k, 0, 1] = e * s
        E[k, 1, 0] = -e * s * om * om
        E[k, 1, 1] = e * (c - s * a)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _propagate(E, n_modes, v):
    """Apply the modal propagator E in place to the (eta, eta_dot) pairs of the state-sized v."""
    K = n_modes
    for k in range(2 * K):
        km = k % K
        a = v[X_ETA + k]
        b = v[X_ETA + 2 * K + k]
        v[X_ETA + k] = E[km, 0, 0] * a + E[km, 0, 1] * b
        v[X_ETA + 2 * K + k] = E[km, 1, 0] * a + E[km, 1, 1] * b


@nb.njit(cache=True, error_model="numpy", inline="always")
def _nonlinear_part(x, p, n_modes, f):
    """Subtract the free modal dynamics from the derivative f: ``f -= L x`` on the modal rows."""
    K = n_modes
    for k in range(2 * K):
        km = k % K
        om = p[P_MODES + km]
        ze = p[P_MODES + K + km]
        f[X_ETA + k] -= x[X_ETA + 2 * K + k]
        f[X_ETA + 2 * K + k] += 2.0 * ze * om * x[X_ETA + 2 * K + k] + om * om * x[X_ETA + k]


@nb.njit(cache=True, error_model="numpy", inline="always")
def normalise_quaternions(x, n_slosh, n_modes):
    """Scale the body and pendulum quaternions of one state to unit norm."""
    for o in range(-1, n_slosh):
        qo = X_Q if o < 0 else X_ETA + 4 * n_modes + 4 * o
        n = math.sqrt(x[qo] ** 2 + x[qo + 1] ** 2 + x[qo + 2] ** 2 + x[qo + 3] ** 2)
        for i in range(4):
            x[qo + i] /= n


@nb.njit(cache=True, error_model="numpy", inline="always")
def rk4_vehicle(loads_fn, t, h, x, p, c, n_slosh, n_modes, exact_modes, buf, E, ws):
    """Advance one vehicle's state x in place by one step h from time t.

    With ``P`` the exact free-mode propagator over h/2 (the identity for ``exact_modes=False`` or
    no modes) and ``N(y) = f(y) - L y`` (f less the free-mode dynamics)::

        k1 = N(x)                     k2 = N(P(x + h/2 k1))
        k3 = N(P x + h/2 k2)          k4 = N(P(P x + h k3))
        x <- P(P(x + h/6 k1) + h/3 (k2 + k3)) + h/6 k4

    which is classical RK4 when P is the identity. ``buf`` is (6, n_x) scratch, ``E`` (max(K, 1),
    2, 2) scratch, ``ws`` the kernel workspace whose last entry holds the loads vector.
    """
    N = n_slosh
    K = n_modes
    A, rhs, hh, C, S, work, u = ws
    k1, k2, k3, k4, xs, px = buf[0], buf[1], buf[2], buf[3], buf[4], buf[5]
    n = x.size
    use_if = exact_modes and K > 0
    if use_if:
        modal_propagator(p, K, 0.5 * h, E)

    loads_fn(t, x, p, c, u)
    vehicle_deriv(x, p, u, N, K, k1, A, rhs, hh, C, S, work)
    if use_if:
        _nonlinear_part(x, p, K, k1)
    for i in range(n):
        xs[i] = x[i] + 0.5 * h * k1[i]
        px[i] = x[i]
    if use_if:
        _propagate(E, K, xs)
        _propagate(E, K, px)

    loads_fn(t + 0.5 * h, xs, p, c, u)
    vehicle_deriv(xs, p, u, N, K, k2, A, rhs, hh, C, S, work)
    if use_if:
        _nonlinear_part(xs, p, K, k2)
    for i in range(n):
        xs[i] = px[i] + 0.5 * h * k2[i]

    loads_fn(t + 0.5 * h, xs, p, c, u)
    vehicle_deriv(xs, p, u, N, K, k3, A, rhs, hh, C, S, work)
    if use_if:
        _nonlinear_part(xs, p, K, k3)
    for i in range(n):
        xs[i] = px[i] + h * k3[i]
    if use_if:
        _propagate(E, K, xs)

    loads_fn(t + h, xs, p, c, u)
    vehicle_deriv(xs, p, u, N, K, k4, A, rhs, hh, C, S, work)
    if use_if:
        _nonlinear_part(xs, p, K, k4)
        for i in range(n):
            x[i] += h / 6.0 * k1[i]
        _propagate(E, K, x)
        for i in range(n):
            x[i] += h / 3.0 * (k2[i] + k3[i])
        _propagate(E, K, x)
        for i in range(n):
            x[i] += h / 6.0 * k4[i]
    else:
        for i in range(n):
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    normalise_quaternions(x, N, K)


@nb.njit(cache=True, error_model="numpy")
def _alloc(n_x, n_u, n_slosh, n_modes):
    A, rhs, hh, C, S, work = make_workspace(n_slosh, n_modes)
    ws = (A, rhs, hh, C, S, work, np.empty(n_u))
    return np.empty((6, n_x)), np.empty((max(n_modes, 1), 2, 2)), ws


@nb.njit(cache=True, error_model="numpy")
def step_batch(loads_fn, x, p, c, t0, h, n_steps, n_slosh, n_modes, exact_modes, n_u):
    """Advance every row of the batch state ``x`` (B, n_x) in place by ``n_steps`` steps of ``h``
    seconds from ``t0``, with parameters ``p`` (B, n_p) held and loads of length ``n_u`` written by
    ``loads_fn`` from the command/context rows ``c`` (B, n_c) at every stage."""
    B, n_x = x.shape
    buf, E, ws = _alloc(n_x, n_u, n_slosh, n_modes)
    for b in range(B):
        xb = x[b]
        t = t0
        for _ in range(n_steps):
            rk4_vehicle(loads_fn, t, h, xb, p[b], c[b], n_slosh, n_modes, exact_modes, buf, E, ws)
            t += h


@nb.njit(cache=True, error_model="numpy")
def deriv_batch(x, p, u, n_slosh, n_modes, out):
    """``out[b] = xdot`` of every vehicle of the batch."""
    B, n_x = x.shape
    A, rhs, hh, C, S, work = make_workspace(n_slosh, n_modes)
    for b in range(B):
        vehicle_deriv(x[b], p[b], u[b], n_slosh, n_modes, out[b], A, rhs, hh, C, S, work)


def as_batch(array: np.ndarray, n: int, what: str) -> np.ndarray:
    """View ``array`` as a C-contiguous float64 (B, n) batch, checking its last dimension."""
    a = np.ascontiguousarray(array, dtype=np.float64)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != n:
        raise ValueError(f"{what} has shape {np.shape(array)}: expected ({n},) or (batch, {n})")
    return a
