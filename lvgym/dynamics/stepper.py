"""Compiled fixed-step integration of a batch of vehicles.

``rk4`` is the classical fourth-order Runge-Kutta scheme applied in the interaction frame of the
bending oscillators (the integrating-factor or Lawson RK4 of Cox & Matthews, J. Comput. Phys. 176,
2002): the free, damped modal oscillators ``eta_ddot + 2 Z Omega eta_dot + Omega^2 eta = 0`` are
propagated exactly over each stage and RK4 integrates everything else, including every coupling
into the modes. With no modes it is exactly classical RK4. It keeps fourth order, but the step is no
longer bounded by the highest bending frequency, and the modes are not artificially damped (classical
RK4 loses ``(Omega h)^6 / 72`` of a mode's energy per step: 1.5e-4 of a 15 Hz mode over 15 s at 1 ms).
``rk4-classic`` is the plain scheme, kept for comparison.

Loads come from a compiled loads function ``loads_fn(t, x, p, ctx, u)`` evaluated at every RK4 stage:
it writes the loads ``u`` of one vehicle from the stage time, state, parameters and the caller's
command/context vector ``ctx``. The default ``zoh_loads`` copies ``ctx`` (loads held over the step); a
simulator whose loads depend on the state (gravity with altitude, aerodynamics) compiles its own
with ``compile_loads`` and hands it to the same ``step_batch``. Loads functions are numba ``cfunc``
objects of ``LOADS_SIGNATURE``, so the stepper is compiled once and cached on disk.

A caller that steps vehicles itself (the simulator) makes one :data:`Workspace` with
``make_workspace(n_slosh, n_modes, n_u)`` and calls ``rk4_vehicle(loads_fn, t, h, x, p, ctx,
exact_modes, ws)`` per step; the offsets of every array come from :mod:`.layout` and from
:data:`.layout.RK4_ROWS`.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from lvgym.packing import at

from .kernels import DerivWork, make_deriv_work, unowned, vehicle_deriv  # noqa: F401 (DerivWork, unowned: re-exported)
from .layout import RK4_ROWS, SIZES, X_PER_SLOSH, P, X

METHODS = ("rk4", "rk4-classic")

RK, _RK4_SIZE = RK4_ROWS.at, RK4_ROWS.size

#: scratch of the dynamics kernels, made by :func:`make_workspace`: the sizes, the derivative's
#: :data:`~.kernels.DerivWork` and the arrays of the RK4 step :func:`rk4_vehicle`
Workspace = namedtuple("Workspace", [
    "n_slosh", "n_modes",               # N pendulums, K modes per plane
    "deriv",                            # DerivWork of vehicle_deriv
    "u",                                # loads of the current stage (n_u,)
    "buf",                              # RK4_ROWS rows of n_x: the RK4 stages and states
    "E",                                # free-mode propagators (max(K, 1), 2, 2)
])


@nb.njit(cache=True, error_model="numpy")
def make_workspace(n_slosh, n_modes, n_u):
    """A :data:`Workspace` for ``n_slosh`` pendulums, ``n_modes`` modes per plane and loads of length
    ``n_u``. The RK4 buffer and the loads are zero, so the unused entries of a padded layout keep a zero
    derivative.

    :func:`~.kernels.vehicle_deriv` takes only the part ``deriv``: numba passes a tuple by value, entry
    by entry, and the derivative is called four times per step."""
    nx = at(SIZES.state, n_modes, n_slosh)
    return Workspace(n_slosh, n_modes, make_deriv_work(n_slosh, n_modes), np.zeros(n_u), np.zeros((_RK4_SIZE, nx)),
                     np.empty((max(n_modes, 1), 2, 2)))


_vec = nb.types.float64[::1]
#: signature of a loads function ``loads_fn(t, x, p, ctx, u) -> None``
LOADS_SIGNATURE = nb.types.void(nb.types.float64, _vec, _vec, _vec, _vec)


def compile_loads(fn):
    """Compile a Python loads function ``fn(t, x, p, ctx, u)`` (numba-compatible code) for the
    stepper. A division by zero gives inf or NaN (numpy's error model, as the dynamics kernels), which the
    simulator's check of the state fails the row on, instead of raising out of the whole batch."""
    return nb.cfunc(LOADS_SIGNATURE, cache=True, error_model="numpy")(fn)


def _zoh(t, x, p, ctx, u):
    """Default loads function: the loads are the command vector, held over the step."""
    for i in range(u.size):
        u[i] = ctx[i]


zoh_loads = compile_loads(_zoh)


@nb.njit(cache=True, error_model="numpy")
def modal_propagator(p, n_slosh, n_modes, tau, E):
    """``E[k] = expm(L_k tau)`` for ``L_k = [[0, 1], [-Omega_k^2, -2 Z_k Omega_k]]``."""
    K = n_modes
    N = n_slosh
    o_om = at(P.omega_modes, K, N)
    o_ze = at(P.zeta_modes, K, N)
    for k in range(K):
        om = p[o_om + k]
        ze = p[o_ze + k]
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
def _propagate(E, n_slosh, n_modes, v):
    """Apply the modal propagator E in place to the (eta, eta_dot) pairs of the state-sized v."""
    K = n_modes
    N = n_slosh
    o_eta = at(X.eta, K, N)
    o_etad = at(X.eta_dot, K, N)
    for k in range(2 * K):
        km = k % K
        a = v[o_eta + k]
        b = v[o_etad + k]
        v[o_eta + k] = E[km, 0, 0] * a + E[km, 0, 1] * b
        v[o_etad + k] = E[km, 1, 0] * a + E[km, 1, 1] * b


@nb.njit(cache=True, error_model="numpy", inline="always")
def _nonlinear_part(x, p, n_slosh, n_modes, f):
    """Subtract the free modal dynamics from the derivative f: ``f -= L x`` on the modal rows."""
    K = n_modes
    N = n_slosh
    o_om = at(P.omega_modes, K, N)
    o_ze = at(P.zeta_modes, K, N)
    o_eta = at(X.eta, K, N)
    o_etad = at(X.eta_dot, K, N)
    for k in range(2 * K):
        km = k % K
        om = p[o_om + km]
        ze = p[o_ze + km]
        f[o_eta + k] -= x[o_etad + k]
        f[o_etad + k] += 2.0 * ze * om * x[o_etad + k] + om * om * x[o_eta + k]


@nb.njit(cache=True, error_model="numpy", inline="always")
def normalise_quaternions(x, n_slosh, n_modes):
    """Scale the body and pendulum quaternions of one state to unit norm (only these fields are read)."""
    K = n_modes
    N = n_slosh
    for j in range(-1, N):
        qo = at(X.q_bi, K, N) if j < 0 else at(X.q_si, K, N) + j * X_PER_SLOSH.q_si
        n = math.sqrt(x[qo] ** 2 + x[qo + 1] ** 2 + x[qo + 2] ** 2 + x[qo + 3] ** 2)
        for i in range(4):
            x[qo + i] /= n


@nb.njit(cache=True, error_model="numpy")
def rk4_vehicle_call(loads_fn, t, h, x, p, ctx, exact_modes, ws):
    """:func:`rk4_vehicle` as a function of its own (not inlined into the caller)."""
    rk4_vehicle(loads_fn, t, h, x, p, ctx, exact_modes, ws)


@nb.njit(cache=True, error_model="numpy", inline="always")
def rk4_vehicle(loads_fn, t, h, x, p, ctx, exact_modes, ws):
    """Advance one vehicle's state x in place by one step h from time t, with the parameters ``p``
    held and the loads written by ``loads_fn(t, x, p, ctx, ws.u)`` at every stage from the caller's
    command/context vector ``ctx``; ``ws`` is a :data:`Workspace` of :func:`make_workspace` (its sizes
    say how many pendulums and modes ``x`` has). Unused entries of a padded state keep their values.

    With ``P`` the exact free-mode propagator over h/2 (the identity for ``exact_modes=False`` or
    no modes) and ``N(y) = f(y) - L y`` (f less the free-mode dynamics)::

        k1 = N(x)                     k2 = N(P(x + h/2 k1))
        k3 = N(P x + h/2 k2)          k4 = N(P(P x + h k3))
        x <- P(P(x + h/6 k1) + h/3 (k2 + k3)) + h/6 k4

    which is classical RK4 when P is the identity.
    """
    N = ws.n_slosh
    K = ws.n_modes
    u, E = ws.u, ws.E
    buf = ws.buf
    dw = ws.deriv
    k1, k2, k3, k4, xs, px = buf[RK.k1], buf[RK.k2], buf[RK.k3], buf[RK.k4], buf[RK.x_stage], buf[RK.x_prop]
    n = x.size
    use_if = exact_modes and K > 0
    if use_if:
        modal_propagator(p, N, K, 0.5 * h, E)

    loads_fn(t, x, p, ctx, u)
    vehicle_deriv(x, p, u, k1, dw)
    if use_if:
        _nonlinear_part(x, p, N, K, k1)
    for i in range(n):
        xs[i] = x[i] + 0.5 * h * k1[i]
        px[i] = x[i]
    if use_if:
        _propagate(E, N, K, xs)
        _propagate(E, N, K, px)

    loads_fn(t + 0.5 * h, xs, p, ctx, u)
    vehicle_deriv(xs, p, u, k2, dw)
    if use_if:
        _nonlinear_part(xs, p, N, K, k2)
    for i in range(n):
        xs[i] = px[i] + 0.5 * h * k2[i]

    loads_fn(t + 0.5 * h, xs, p, ctx, u)
    vehicle_deriv(xs, p, u, k3, dw)
    if use_if:
        _nonlinear_part(xs, p, N, K, k3)
    for i in range(n):
        xs[i] = px[i] + h * k3[i]
    if use_if:
        _propagate(E, N, K, xs)

    loads_fn(t + h, xs, p, ctx, u)
    vehicle_deriv(xs, p, u, k4, dw)
    if use_if:
        _nonlinear_part(xs, p, N, K, k4)
        for i in range(n):
            x[i] += h / 6.0 * k1[i]
        _propagate(E, N, K, x)
        for i in range(n):
            x[i] += h / 3.0 * (k2[i] + k3[i])
        _propagate(E, N, K, x)
        for i in range(n):
            x[i] += h / 6.0 * k4[i]
    else:
        for i in range(n):
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    normalise_quaternions(x, N, K)


@nb.njit(cache=True, error_model="numpy")
def step_batch(loads_fn, x, p, ctx, t0, h, n_steps, n_slosh, n_modes, exact_modes, n_u):
    """Advance every row of the batch state ``x`` (B, n_x) in place by ``n_steps`` steps of ``h``
    seconds from ``t0``, with parameters ``p`` (B, n_p) held and loads of length ``n_u`` written by
    ``loads_fn`` from the command/context rows ``ctx`` (B, n_ctx) at every stage."""
    B = x.shape[0]
    ws = make_workspace(n_slosh, n_modes, n_u)
    for b in range(B):
        xb = x[b]
        t = t0
        for _ in range(n_steps):
            rk4_vehicle(loads_fn, t, h, xb, p[b], ctx[b], exact_modes, ws)
            t += h


@nb.njit(cache=True, error_model="numpy")
def deriv_batch(x, p, u, n_slosh, n_modes, out):
    """``out[b] = xdot`` of every vehicle of the batch (only the state's fields of ``out`` are
    written: the unused entries of a padded layout keep what they hold)."""
    B = x.shape[0]
    dw = make_deriv_work(n_slosh, n_modes)
    for b in range(B):
        vehicle_deriv(x[b], p[b], u[b], out[b], dw)


def as_batch(array: np.ndarray, n: int, what: str) -> np.ndarray:
    """View ``array`` as a C-contiguous float64 (B, n) batch, checking its last dimension."""
    a = np.ascontiguousarray(array, dtype=np.float64)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != n:
        raise ValueError(f"{what} has shape {np.shape(array)}: expected ({n},) or (batch, {n})")
    return a
