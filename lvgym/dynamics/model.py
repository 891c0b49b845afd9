"""Python face of the dynamics core: one class for one vehicle or a batch, and a time integrator.

>>> from lvgym.dynamics import NonRigidModel
>>> model = NonRigidModel(n_slosh=1, n_modes=1)
>>> x = model.layout.zeros_state()                     # (n_x,) or (batch, n_x)
>>> p = model.params(m_b=60.0, J_b=[0.5, 300, 300], omega_modes=[90.0],
...                  slosh=[{"m": 5.0, "length": 0.3, "r_hinge": [-2.0, 0.0, 0.0]}])
>>> u = model.loads(g_i=[-9.81, 0, 0])
>>> x1 = model.step(x, p, u, dt=1e-3, n_steps=10)      # RK4, loads held over the steps
>>> round(float(x1[3]), 6)                              # free fall: v = g t
-0.0981

Arrays with a leading batch axis go through the same compiled kernel, vehicle by vehicle.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .invariants import ENERGY_TERMS, energy_batch, momentum_batch, slosh_positions_batch
from .layout import Layout
from .stepper import METHODS, as_batch, deriv_batch, step_batch, zoh_loads

ADAPTIVE_METHODS = ("RK45", "DOP853")


def _rows(a: np.ndarray, batch: int) -> np.ndarray:
    """One writable C-contiguous row per vehicle (a single row is repeated for the batch)."""
    if a.shape[0] not in (1, batch):
        raise ValueError(f"a batch of {a.shape[0]} rows for {batch} vehicles")
    return np.require(np.broadcast_to(a, (batch, a.shape[1])), np.float64, ["C", "W"])


def _rotate(q: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``C_ib a`` for unit scalar-first quaternions ``q`` (B, 4) and vectors ``a`` (B, 3)."""
    s, v = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(v, a)
    return a + s * t + np.cross(v, t)


def _shape_like(result: np.ndarray, template: np.ndarray) -> np.ndarray:
    return result[0] if np.ndim(template) == 1 else result


class NonRigidModel:
    """Equations of motion of a vehicle with ``n_slosh`` pendulums and ``n_modes`` modes per plane.

    With ``n_slosh = n_modes = 0`` it is an ordinary 6-DOF rigid body. See ``layout.py`` for the
    meaning and units of every entry of the state ``x``, parameters ``p`` and loads ``u``.
    """

    def __init__(self, n_slosh: int = 0, n_modes: int = 0) -> None:
        self.layout = Layout(n_slosh, n_modes)
        self.n_slosh = self.layout.n_slosh
        self.n_modes = self.layout.n_modes

    def __repr__(self) -> str:
        return f"NonRigidModel(n_slosh={self.n_slosh}, n_modes={self.n_modes})"

    # ----------------------------------------------------------------- building vectors by name
    def params(self, *, m_b, J_b: Sequence[float] | np.ndarray, r_cg=(0.0, 0.0, 0.0),
               r_gimbal=(0.0, 0.0, 0.0), omega_modes=(), zeta_modes=(), phi_gimbal=(),
               dphi_gimbal=(), slosh: Sequence[dict] = ()) -> np.ndarray:
        """Parameter vector from named values. ``J_b`` is a 3x3 matrix or its diagonal; ``slosh`` a
        list of N dicts with keys ``m, length, r_hinge`` and optionally ``inertia, zeta, omega, phi``.

        A batch: ``m_b`` (B,) gives parameters (B, n_p), and every other value may carry the same
        leading axis (``J_b`` (B, 3, 3) or (B, 3), ``r_cg`` (B, 3), ``omega_modes`` (B, K), a pendulum's
        ``m`` (B,), ``r_hinge`` (B, 3), ``phi`` (B, K), ...) or be shared by all rows.
        """
        lay = self.layout
        m_b = np.asarray(m_b, dtype=float)
        if m_b.ndim > 1:
            raise ValueError(f"m_b of shape {m_b.shape}: a mass [kg] or one per vehicle (B,)")
        batch = m_b.shape
        p = np.zeros(batch + (lay.n_p,))

        def put(sl: slice, value, what: str) -> None:
            v = np.asarray(value, dtype=float)
            if sl.stop - sl.start == 1 and v.shape in ((), batch):
                v = v[..., None]
            try:
                p[..., sl] = v
            except ValueError:
                raise ValueError(f"{what} has shape {v.shape}: expected {sl.stop - sl.start} entries"
                                 + (f" or {batch[0]} rows of them" if batch else "")) from None

        put(lay.params["m_b"], m_b, "m_b")
        J = np.asarray(J_b, dtype=float)
        if J.shape in ((3,), batch + (3,)) and J.shape != (3, 3):        # diagonals ((3, 3): a matrix)
            J = J[..., :, None] * np.eye(3)
        if J.shape not in ((3, 3), batch + (3, 3)):
            raise ValueError(f"J_b = {J_b!r}: a 3x3 matrix or its diagonal, in kg m^2")
        put(lay.params["J_b"], J.reshape(J.shape[:-2] + (9,)), "J_b")
        put(lay.params["r_cg"], r_cg, "r_cg")
        put(lay.params["r_gimbal"], r_gimbal, "r_gimbal")
        for key, value in (("omega_modes", omega_modes), ("zeta_modes", zeta_modes),
                           ("phi_gimbal", phi_gimbal), ("dphi_gimbal", dphi_gimbal)):
            value = np.zeros(self.n_modes) if len(value) == 0 else np.asarray(value, dtype=float)
            if value.shape[-1:] != (self.n_modes,):
                raise ValueError(f"{key} has {value.shape[-1] if value.ndim else 1} entries: expected "
                                 f"n_modes = {self.n_modes}")
            put(lay.params[key], value, key)
        if len(slosh) != self.n_slosh:
            raise ValueError(f"slosh has {len(slosh)} entries: expected n_slosh = {self.n_slosh}")
        for j, s in enumerate(slosh):
            unknown = set(s) - set(Layout.SLOSH_FIELDS)
            if unknown:
                raise KeyError(f"slosh[{j}] unknown keys {sorted(unknown)}: allowed {Layout.SLOSH_FIELDS}")
            for key in ("m", "length", "r_hinge"):
                if key not in s:
                    raise KeyError(f"slosh[{j}] misses {key!r}")
            values = {"inertia": 0.0, "zeta": 0.0, "omega": 0.0, "phi": np.zeros(self.n_modes), **s}
            for key in Layout.SLOSH_FIELDS:
                put(lay.slosh_param(j, key), values[key], f"slosh[{j}].{key}")
        self.check_params(p)
        return p

    def check_params(self, p: np.ndarray) -> None:
        """Raise ``ValueError`` naming the entry, the value and what is allowed when a parameter
        vector (one vehicle or a batch) cannot be integrated: the first vehicle that fails, at its
        first failed check."""
        lay = self.layout
        pb = as_batch(p, lay.n_p, "p")
        col = {k: pb[:, sl] for k, sl in lay.params.items()}
        J = col["J_b"].reshape(-1, 3, 3)
        # positive definite: the leading minors of the lower triangle (what an eigen-solver reads) > 0
        a, b, c, d, e, f = J[:, 0, 0], J[:, 1, 0], J[:, 1, 1], J[:, 2, 0], J[:, 2, 1], J[:, 2, 2]
        minor2 = a * c - b * b
        det = a * (c * f - e * e) - b * (b * f - e * d) + d * (b * e - c * d)
        symmetric = np.all(np.abs(J - J.transpose(0, 2, 1)) <= 1e-8 + 1e-5 * np.abs(J.transpose(0, 2, 1)),
                           axis=(1, 2))
        checks = [(~np.all(np.isfinite(pb), axis=1), "p", lambda r: pb[r][~np.isfinite(pb[r])].tolist(),
                   "every parameter must be finite"),
                  (~(col["m_b"][:, 0] > 0), "m_b", lambda r: col["m_b"][r, 0], "the rigid-body mass must be > 0 kg"),
                  (~symmetric | ~((a > 0) & (minor2 > 0) & (det > 0)), "J_b", lambda r: J[r].tolist(),
                   "must be symmetric positive definite, kg m^2")]
        for key in ("omega_modes", "zeta_modes"):
            checks.append((np.any(col[key] < 0, axis=1), key, lambda r, k=key: col[k][r].tolist(), "must be >= 0"))
        for j in range(self.n_slosh):
            get = {k: pb[:, lay.slosh_param(j, k)][:, 0] for k in ("m", "inertia", "zeta", "omega", "length")}
            for key in ("m", "inertia", "zeta", "omega"):
                checks.append((get[key] < 0, f"slosh[{j}].{key}", lambda r, k=key, g=get: g[k][r], "must be >= 0"))
            checks.append(((get["m"] > 0) & (get["length"] <= 0), f"slosh[{j}].length",
                           lambda r, g=get: g["length"][r], "an active pendulum (m > 0) needs a length > 0 m"))
        bad = np.zeros(pb.shape[0], dtype=bool)
        for mask, *_ in checks:
            bad |= mask
        if not bad.any():
            return
        r = int(np.argmax(bad))
        mask, name, value, allowed = next(c for c in checks if c[0][r])
        v = value(r)
        v = float(v) if np.ndim(v) == 0 else v
        raise ValueError(f"{'vehicle ' + str(r) + ': ' if pb.shape[0] > 1 else ''}{name} = {v!r}: {allowed}")

    def loads(self, *, f_b_i=(0.0, 0.0, 0.0), m_b_b=(0.0, 0.0, 0.0), thrust_b=(0.0, 0.0, 0.0),
              g_i=(0.0, 0.0, 0.0), f_eta=None) -> np.ndarray:
        """Loads vector from named values (see ``layout.py``)."""
        lay = self.layout
        u = lay.zeros_loads()
        for key, value in (("f_b_i", f_b_i), ("m_b_b", m_b_b), ("thrust_b", thrust_b), ("g_i", g_i)):
            u[lay.loads[key]] = value
        if f_eta is not None:
            u[lay.loads["f_eta"]] = np.asarray(f_eta, dtype=float).ravel()
        return u

    # ----------------------------------------------------------------- the equations
    def _batches(self, x, p, u=None):
        lay = self.layout
        xb = as_batch(x, lay.n_x, "x")
        pb = _rows(as_batch(p, lay.n_p, "p"), xb.shape[0])
        if u is None:
            return xb, pb
        return xb, pb, _rows(as_batch(u, lay.n_u, "u"), xb.shape[0])

    def derivative(self, x: np.ndarray, p: np.ndarray, u: np.ndarray) -> np.ndarray:
        """State derivative ``xdot``, shaped like ``x``."""
        xb, pb, ub = self._batches(x, p, u)
        out = np.zeros_like(xb)          # the unused entries of a padded layout: zero derivative
        deriv_batch(xb, pb, ub, self.n_slosh, self.n_modes, out)
        return _shape_like(out, x)

    def step(self, x: np.ndarray, p: np.ndarray, u: np.ndarray, dt: float, n_steps: int = 1,
             t0: float = 0.0, method: str = "rk4") -> np.ndarray:
        """New state after ``n_steps`` fixed steps of ``dt`` seconds with loads held (a copy)."""
        if method not in METHODS:
            raise ValueError(f"method {method!r}: allowed {METHODS}")
        if not dt > 0 or n_steps < 0:
            raise ValueError(f"dt = {dt!r} must be > 0 s and n_steps = {n_steps!r} >= 0")
        xb, pb, ub = self._batches(x, p, u)
        xb = xb.copy()
        step_batch(zoh_loads, xb, pb, ub, float(t0), float(dt), int(n_steps), self.n_slosh,
                   self.n_modes, method == "rk4", self.layout.n_u)
        return _shape_like(xb, x)

    def shift_cg(self, x: np.ndarray, delta_cg_b) -> np.ndarray:
        """State with the CG of B moved by ``delta_cg_b`` (body frame, m) within the structure.

        ``r_zw_i`` and ``v_zw_i`` refer to the CG of B. When the mass model moves the CG station
        between steps (propellant burns, a stage separates), this keeps the structure where it was:
        ``r += C_ib d`` and ``v += C_ib (omega x d)`` (the velocity of the structure point that is the
        new CG; the rate of the CG's motion through the structure is neglected, as the thesis does).
        Returns a copy shaped like ``x``; ``delta_cg_b`` is (3,) or (B, 3).
        """
        lay = self.layout
        xb = as_batch(x, lay.n_x, "x").copy()
        d = np.broadcast_to(np.asarray(delta_cg_b, dtype=float), (xb.shape[0], 3))
        q = xb[:, lay.state["q_bi"]]
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        xb[:, lay.state["r_zw_i"]] += _rotate(q, d)
        xb[:, lay.state["v_zw_i"]] += _rotate(q, np.cross(xb[:, lay.state["omega_bi_b"]], d))
        return _shape_like(xb, x)

    # ----------------------------------------------------------------- invariants
    def energy(self, x: np.ndarray, p: np.ndarray, g_i) -> dict[str, np.ndarray]:
        """Energy terms (``ENERGY_TERMS``) for uniform gravity ``g_i`` [J]; scalars for one vehicle."""
        xb, pb = self._batches(x, p)
        g = np.ascontiguousarray(np.broadcast_to(np.asarray(g_i, dtype=float), (xb.shape[0], 3)))
        out = np.empty((xb.shape[0], len(ENERGY_TERMS)))
        energy_batch(xb, pb, g, self.n_slosh, self.n_modes, out)
        out = _shape_like(out, x)
        return {name: out[..., i] for i, name in enumerate(ENERGY_TERMS)}

    def momentum(self, x: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Total linear momentum, inertial frame [kg m/s]."""
        xb, pb = self._batches(x, p)
        out = np.empty((xb.shape[0], 3))
        momentum_batch(xb, pb, self.n_slosh, self.n_modes, out)
        return _shape_like(out, x)

    def slosh_kinematics(self, x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inertial positions and velocities of the slosh masses, shape ([B,] N, 3)."""
        xb, pb = self._batches(x, p)
        r = np.zeros((xb.shape[0], self.n_slosh, 3))
        v = np.zeros_like(r)
        slosh_positions_batch(xb, pb, self.n_slosh, self.n_modes, r, v)
        return _shape_like(r, x), _shape_like(v, x)


# --------------------------------------------------------------------------- integration over time
@dataclass(frozen=True)
class Trajectory:
    """Recorded states: ``t`` (n,), ``x`` (n, [B,] n_x)."""

    t: np.ndarray
    x: np.ndarray


def _cuts(t0: float, t1: float, t_events: Sequence[float]) -> list[float]:
    """Start, end and the event times between them, sorted."""
    return sorted({t0, t1, *(float(e) for e in t_events if t0 < e < t1)})


def _grid(t0: float, t1: float, dt: float, t_events: Sequence[float]) -> np.ndarray:
    """Step boundaries from t0 to t1 with steps of at most dt that land on every event time."""
    cuts = _cuts(t0, t1, t_events)
    pieces = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        n = max(1, int(np.ceil((b - a) / dt - 1e-9)))
        pieces.append(np.linspace(a, b, n + 1)[:-1])
    pieces.append(np.array([t1]))
    return np.concatenate(pieces)


def integrate(model: NonRigidModel, x0: np.ndarray, p: np.ndarray | Callable[[float], np.ndarray],
              loads: np.ndarray | Callable[[float], np.ndarray], t_span: tuple[float, float],
              dt: float = 1e-2, method: str = "rk4", t_events: Sequence[float] = (),
              rtol: float = 1e-10, atol: float = 1e-12, record_dt: float | None = None) -> Trajectory:
    """Integrate from ``t_span[0]`` to ``t_span[1]``.

    ``p`` and ``loads`` are arrays or functions of time. With ``rk4`` / ``rk4-classic`` they are
    evaluated at the start of every step and held over it, and the steps (at most ``dt``) land on
    every time in ``t_events`` (where a load switches). ``RK45`` / ``DOP853`` (scipy) evaluate them at
    every stage and restart at every event time; ``rtol``/``atol`` are their tolerances.
    States are recorded every ``record_dt`` (default: every step for RK4, ``dt`` for scipy) and at
    the end.
    """
    t0, t1 = map(float, t_span)
    if not t1 > t0:
        raise ValueError(f"t_span = {t_span!r}: the end must be after the start")
    p_of = p if callable(p) else (lambda t, _p=p: _p)
    u_of = loads if callable(loads) else (lambda t, _u=loads: _u)
    record_dt = dt if record_dt is None else record_dt
    if method in METHODS:
        grid = _grid(t0, t1, dt, t_events)
        x = np.array(x0, dtype=float)
        ts, xs = [t0], [x.copy()]
        next_record = t0 + record_dt
        for a, b in zip(grid[:-1], grid[1:]):
            x = model.step(x, p_of(a), u_of(a), b - a, 1, a, method)
            if not np.all(np.isfinite(x)):
                raise FloatingPointError(f"the state is not finite at t = {b:.6g} s after a step of "
                                         f"{b - a:.3g} s: reduce dt or check the parameters")
            if b >= next_record - 1e-9 * record_dt or b == t1:
                ts.append(b)
                xs.append(x.copy())
                next_record = b + record_dt
        return Trajectory(np.array(ts), np.array(xs))
    if method not in ADAPTIVE_METHODS:
        raise ValueError(f"method {method!r}: allowed {METHODS + ADAPTIVE_METHODS}")
    shape = np.shape(x0)
    cuts = _cuts(t0, t1, t_events)
    n_rec = max(1, int(round((t1 - t0) / record_dt)))
    t_rec = np.linspace(t0, t1, n_rec + 1)
    y = np.array(x0, dtype=float).ravel()
    ts, xs = [t0], [y.reshape(shape).copy()]

    def rhs(t, yy):
        return model.derivative(yy.reshape(shape), p_of(t), u_of(t)).ravel()

    from scipy.integrate import solve_ivp      # here, not at the top: importing it costs 0.2-0.4 s of every start

    for a, b in zip(cuts[:-1], cuts[1:]):
        inside = t_rec[(t_rec > a + 1e-12) & (t_rec <= b + 1e-12)]
        t_eval = np.unique(np.clip(np.append(inside, b), a, b))
        sol = solve_ivp(rhs, (a, b), y, method=method, rtol=rtol, atol=atol, t_eval=t_eval)
        if not sol.success:
            raise RuntimeError(f"{method} failed on [{a}, {b}]: {sol.message}")
        for t, col in zip(sol.t, sol.y.T):
            ts.append(t)
            xs.append(col.reshape(shape).copy())
        y = sol.y[:, -1]
    return Trajectory(np.array(ts), np.array(xs))
