"""The condensed quadratic program of one row of the MPC (:mod:`.mpc`): the LQ cost of ``lqg``'s regulator
over a short horizon under the gimbal's angle and rate limits, solved by OSQP with warm start.

The row's augmented plant ``z_{k+1} = Aa z_k + Ba u_k`` (the delayed plant and the rate error's leaky
integral, :func:`.design.lqg_row.regulator_problem`) is condensed over ``N`` steps: with
``U = (u_0 .. u_{N-1})`` [rad], ``z_k = Phi_k z_0 + Gamma_k U`` and::

    J(U) = sum_{k=0}^{N-1} (z_k' Q z_k + u_k' R u_k) + z_N' P z_N = U' H U + 2 U' F z_0 + const

    subject to  |u_k| <= limit  and the rate limit, either on the command (``rate_state`` None):
                |u_k - u_{k-1}| <= rate_step  (u_{-1}: the command sent last period),
                or on the servo's rate in the model (``rate_state`` its index in z):
                |z_k[rate_state]| <= rate_step / dt  for k = 1 .. N

``P`` is the terminal weight: the infinite-horizon Riccati solution of the same ``Q``, ``R`` (then the
unconstrained minimiser's first move is the row's LQR gain, ``-K z_0``: with the limits inactive the MPC
is ``lqg``'s regulator; Scokaert and Rawlings, "Constrained linear quadratic regulation", IEEE TAC 43(8),
1998). ``rate_step`` [rad] is the servo's rate limit times the control period ``dt``: a command that moves
by less per period never drives the servo into its rate limit for long, but the servo (15 rad/s) follows a
single larger step with a much lower peak rate; the servo-rate form holds the predicted rate itself,
sampled at the control periods (docs/mpc.md).

Solution per period (:meth:`CondensedQP.solve`): the unconstrained minimiser ``U* = -H^-1 F z_0`` (one
matrix-vector product); if it meets every limit it is the QP's solution and OSQP is not called; else OSQP
(Stellato et al., "OSQP: an operator splitting solver for quadratic programs", Math. Prog. Comp. 12, 2020)
solves the QP in the scaled variable ``s = U / limit`` with only ``q`` and the first rate bound updated
and warm-started from the last solution shifted by one period. If OSQP does not report a solution, the
first move falls back to ``U*_0`` clipped to the limits (counted in ``fallbacks``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from lvgym.errors import ConfigError, check_choice, check_number

__all__ = ["CondensedQP", "QPOptions", "condense", "terminal_weight"]


@dataclass(frozen=True)
class QPOptions:
    """The MPC's horizon and OSQP's settings: ``horizon`` [control periods], ``rate`` where the rate limit
    acts (``servo``: the model's servo rate; ``command``: the command's change per period), ``eps`` OSQP's
    absolute and relative tolerance on the scaled command (fractions of the gimbal limit) [-], ``max_iter``."""

    horizon: int = 15
    rate: str = "servo"
    eps: float = 1e-6
    max_iter: int = 4000

    def __post_init__(self) -> None:
        check_choice("mpc.rate", self.rate, ("servo", "command"))
        object.__setattr__(self, "horizon", check_number("mpc.horizon", self.horizon, 1, 200, integer=True))
        object.__setattr__(self, "eps", check_number("mpc.eps", self.eps, 1e-12, 1e-2))
        object.__setattr__(self, "max_iter", check_number("mpc.max_iter", self.max_iter, 10, 10**6, integer=True))


def terminal_weight(Aa: np.ndarray, Ba: np.ndarray, Q: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The infinite-horizon Riccati solution ``P`` of ``(Aa, Ba, Q, R)`` and its gain ``K`` (``u = -K z``)."""
    P = sla.solve_discrete_are(Aa, Ba, Q, R)
    K = np.linalg.solve(R + Ba.T @ P @ Ba, Ba.T @ P @ Aa)
    return P, K


def condense(Aa: np.ndarray, Ba: np.ndarray, Q: np.ndarray, R: np.ndarray, P: np.ndarray,
             N: int, rate_state: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``H`` (N, N) and ``F`` (N, nz) of the cost ``U' H U + 2 U' F z_0`` (module docstring), and the
    prediction of the state ``rate_state`` over periods 1 .. N, ``Phi_r z_0 + Gamma_r U`` (``Gamma_r`` (N, N),
    ``Phi_r`` (N, nz); zeros without ``rate_state``)."""
    nz = Aa.shape[0]
    Phi = np.empty((N + 1, nz, nz))
    Phi[0] = np.eye(nz)
    for k in range(N):
        Phi[k + 1] = Aa @ Phi[k]
    H = np.kron(np.eye(N), R)
    F = np.zeros((N, nz))
    Gr, Pr = np.zeros((N, N)), np.zeros((N, nz))
    G = np.zeros((nz, N))                      # Gamma_k: column j is Aa^(k-1-j) Ba for j < k
    for k in range(1, N + 1):
        G = Aa @ G
        G[:, k - 1] = Ba[:, 0]
        W = P if k == N else Q
        WG = W @ G
        H += G.T @ WG
        F += WG.T @ Phi[k]
        if rate_state is not None:
            Gr[k - 1], Pr[k - 1] = G[rate_state], Phi[k][rate_state]
    return 0.5 * (H + H.T), F, Gr, Pr


@dataclass
class CondensedQP:
    """One row's QP (module docstring) for the gimbal ``limit`` [rad] and ``rate_step`` [rad per period].
    ``H``, ``F`` and, for the servo-rate form, ``Gr``, ``Pr`` from :func:`condense` with the period
    ``dt`` [s] (None: the rate limit on the command); ``solve(z0, u_prev) -> U`` [rad]. ``solves`` counts
    the periods OSQP was called, ``fallbacks`` those it gave no solution, ``iterations`` its iterations."""

    H: np.ndarray
    F: np.ndarray
    limit: float
    rate_step: float
    options: QPOptions = QPOptions()
    Gr: np.ndarray | None = None
    Pr: np.ndarray | None = None
    dt: float | None = None
    solves: int = 0
    fallbacks: int = 0
    iterations: int = 0
    _solver: Any = field(default=None, repr=False)
    _last: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        N = self.H.shape[0]
        if self.H.shape != (N, N) or self.F.shape[0] != N:
            raise ConfigError("mpc H, F", (self.H.shape, self.F.shape), "H (N, N) and F (N, nz)")
        if not (self.limit > 0.0 and self.rate_step > 0.0):
            raise ConfigError("mpc limits", (self.limit, self.rate_step), "a gimbal limit and rate step > 0 rad")
        self.gain = -np.linalg.solve(self.H, self.F)           # U* = gain @ z0
        self.servo = self.Gr is not None
        if self.servo and not (self.dt and self.dt > 0 and self.Pr is not None):
            raise ConfigError("mpc dt", self.dt, "the control period > 0 s with Gr and Pr (the servo-rate form)")
        if self.servo:                                          # rows: |s_k| <= 1, |rate_k| <= rate limit
            self.rate = self.rate_step / self.dt               # rad/s
            self.A = sp.vstack([sp.eye(N, format="csc"), sp.csc_matrix(self.limit * self.Gr)], format="csc")
            self.lo = np.concatenate([-np.ones(N), np.full(N, -self.rate)])
            self.hi = np.concatenate([np.ones(N), np.full(N, self.rate)])
        else:                                                   # rows: |s_k| <= 1, |s_k - s_{k-1}| <= r
            self.r = self.rate_step / self.limit
            D = sp.eye(N, format="csc") - sp.eye(N, k=-1, format="csc")
            self.A = sp.vstack([sp.eye(N, format="csc"), D], format="csc")
            self.lo = np.concatenate([-np.ones(N), np.full(N, -self.r)])
            self.hi = np.concatenate([np.ones(N), np.full(N, self.r)])

    def feasible(self, U: np.ndarray, u_prev: float, z0: np.ndarray | None = None) -> bool:
        """Whether the commands ``U`` [rad] meet the limits after the command ``u_prev`` [rad] (from the state
        ``z0`` in the servo-rate form)."""
        tol = 1e-12 * self.limit
        if not np.all(np.abs(U) <= self.limit + tol):
            return False
        if self.servo:
            return bool(np.all(np.abs(self.Pr @ z0 + self.Gr @ U) <= self.rate * (1 + 1e-12)))
        return bool(np.all(np.abs(np.diff(U, prepend=u_prev)) <= self.rate_step + tol))

    def _setup(self, q: np.ndarray) -> None:
        import osqp

        P = sp.triu(sp.csc_matrix(2.0 * self.limit ** 2 * self.H), format="csc")
        o = self.options
        self._ok = (osqp.SolverStatus.OSQP_SOLVED, osqp.SolverStatus.OSQP_SOLVED_INACCURATE)
        self._solver = osqp.OSQP()
        self._solver.setup(P, q, self.A, self.lo, self.hi, eps_abs=o.eps, eps_rel=o.eps, max_iter=o.max_iter,
                           polishing=True, warm_starting=True, verbose=False)

    def solve(self, z0: np.ndarray, u_prev: float) -> np.ndarray:
        """The commands ``U`` (N,) [rad] that minimise the cost from the state ``z0`` (nz,) after the command
        ``u_prev`` [rad] under the limits (module docstring): the unconstrained plan where it meets them, else
        :meth:`qp`, warm-started from the last plan."""
        U = self.gain @ z0
        if self.feasible(U, u_prev, z0):
            self._last = U / self.limit
            return U
        U, self._last = self.qp(z0, u_prev, self._last)
        return U

    def qp(self, z0: np.ndarray, u_prev: float, warm: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
        """OSQP's commands ``U`` (N,) [rad] from the state ``z0`` after the command ``u_prev`` [rad], warm-started
        from the last plan ``warm`` (N,) [gimbal limits] (None: none), and the plan to warm-start the next
        period from (None after a fallback: the unconstrained first move held to the limits)."""
        U = self.gain @ z0
        s_prev = u_prev / self.limit
        q = 2.0 * self.limit * (self.F @ z0)
        lo, hi = self.lo.copy(), self.hi.copy()
        N = self.H.shape[0]
        if self.servo:
            free = self.Pr @ z0                                 # the servo's rates without commands
            lo[N:] -= free
            hi[N:] -= free
        else:
            lo[N], hi[N] = s_prev - self.r, s_prev + self.r
        if self._solver is None:
            self._setup(q)
            self._solver.update(l=lo, u=hi)
        else:
            self._solver.update(q=q, l=lo, u=hi)
        if warm is not None:
            self._solver.warm_start(x=np.append(warm[1:], warm[-1]))
        res = self._solver.solve(raise_error=False)
        self.solves += 1
        self.iterations += int(res.info.iter)
        if res.info.status_val not in self._ok or res.x is None or not np.all(np.isfinite(res.x)):
            self.fallbacks += 1
            step = np.inf if self.servo else self.rate_step
            u0 = min(max(U[0], -self.limit, u_prev - step), self.limit, u_prev + step)
            return np.full(N, u0), None
        s = np.clip(res.x, -1.0, 1.0)
        if not self.servo:                                      # OSQP's tolerance: the first move exactly
            s[0] = min(max(s[0], s_prev - self.r), s_prev + self.r)
        return s * self.limit, s

    def reset(self) -> None:
        """Forget the warm start (a new episode or engagement)."""
        self._last = None
