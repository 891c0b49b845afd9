"""An independent check of the slender vehicle's aeroelastic static instability (docs/aerodynamics.md,
"Independent check of the divergence").

Nothing here uses lvgym's beam solver, mass model or strip code. The model, in the pitch plane, with
``xi`` the distance behind the nose tip [m] and the lateral deflection ``y`` positive up:

- **structure**: a free-free Euler-Bernoulli beam of Hermite cubic elements (``n_el`` equal elements)
  with the tube's bending stiffness ``EI = E pi (D^4 - (D - 2 t)^4) / 64`` over the whole length, the
  wall's line mass, the liquid column (the tank's cross-section times the density over the filled part
  at the tank's bottom, drained at the mass flow: it stays rigidly attached, no slosh pendulum), and
  point masses for the two equipment masses and the engine, all read from the vehicle's parameters
  (:func:`lvgym.vehicle.slender.slender_mapping`), not from lvgym's mass model. Its first two elastic
  modes, mass-normalised (``phi^T M phi = 1``, units 1/sqrt(kg)), orthogonal to the rigid modes (mean
  axes: the rigid-body acceleration does not load them, i.e. inertia relief is built in);
- **aerodynamics**: slender-body theory over the tangent ogive nose computed here,
  ``dCN_alpha / dxi = (2 / S) dA / dxi`` (integrates to 2), and the fins' normal-force slope as one
  concentrated load at their centre of pressure, with the numbers of lvgym's Barrowman table at the
  flight's Mach number (:meth:`lvgym.environment.barrowman.BarrowmanAero.components`; the v1 env freezes
  its tables at Mach 2); the body carries no lift;
- **local incidence** (derived here from the geometry): the local forward axis is inclined by
  ``theta - dy_e/dxi`` and the local flow by the plunge and the deflection rate, so
  ``alpha(xi) = theta - v / V + (xi - xi_cg) q / V - sum_k phi_k'(xi) eta_k - sum_k phi_k(xi) eta_dot_k / V``;
- **thrust** (optional): a follower force along the local tangent at the gimbal, with its generalised
  forces from virtual work; **axial load** (optional): the geometric stiffness of the compression that
  accelerates the mass ahead of each section (drag applied at the nose tip).

:func:`static_stiffness` gives the quasi-static elastic pitching moment (the modes' static deflection
under a unit angle of attack) and :func:`divergence_qbar` the dynamic pressure where the inertia-relieved
pitch stiffness ``M_alpha,eff = M_alpha - qS e^T (Omega^2 + qS A)^-1 b qS`` passes zero;
:func:`dynamic_matrix` the linear pitch-plane dynamics (plunge velocity, pitch, rate, the modes), whose
real positive eigenvalue is compared with lvgym's linearised v1 plant (:func:`lvgym_poles`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import linalg, optimize

from lvgym.vehicle.sections import MATERIALS
from lvgym.vehicle.slender import slender_mapping

__all__ = ["Beam", "Lift", "FlightCondition", "vehicle_beam", "vehicle_lift", "uniform_beam_check",
           "static_stiffness", "elastic_moment_ratio", "divergence_qbar", "dynamic_matrix", "growth_rate",
           "pinned_operating_point", "lvgym_poles", "pitch_stiffness", "divergence_qbar_flight", "stabilisability", "lqg_sensitivity_sweep"]


@dataclass
class Beam:
    """A free-free beam: nodes ``xi`` [m] behind the nose, mass and stiffness matrices (DOFs ``(y, y')``
    per node), rigid properties and the first elastic modes (``omega`` [rad/s], mass-normalised shape
    vectors ``modes`` (n_dof, K))."""

    xi: np.ndarray
    M: np.ndarray
    K: np.ndarray
    mass: float
    cg: float
    inertia: float
    omega: np.ndarray
    modes: np.ndarray
    length: float
    gimbal: float

    def shape(self, x: Any, k: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Mode shapes and slopes (K, len(x)) at stations ``x`` [m] (Hermite interpolation)."""
        x = np.atleast_1d(np.asarray(x, float))
        le = self.xi[1] - self.xi[0]
        e = np.clip(((x - self.xi[0]) / le).astype(int), 0, len(self.xi) - 2)
        s = (x - self.xi[e]) / le
        h = np.array([1 - 3 * s**2 + 2 * s**3, le * (s - 2 * s**2 + s**3), 3 * s**2 - 2 * s**3, le * (-s**2 + s**3)])
        dh = np.array([(-6 * s + 6 * s**2) / le, 1 - 4 * s + 3 * s**2, (6 * s - 6 * s**2) / le, -2 * s + 3 * s**2])
        modes = self.modes if k is None else self.modes[:, [k]]
        idx = np.stack([2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3])            # (4, n)
        vals = modes[idx]                                                   # (4, n, K)
        phi = np.einsum("in,ink->kn", h, vals)
        dphi = np.einsum("in,ink->kn", dh, vals)
        return phi, dphi

    def compression(self, x: Any, accel: float, drag: float) -> np.ndarray:
        """Axial compression [N] at stations ``x``: the force that accelerates the mass ahead of each
        section at ``accel`` [m/s^2] (the sensed axial acceleration) plus the drag at the nose tip."""
        x = np.atleast_1d(np.asarray(x, float))
        ahead = np.array([self._mass_ahead(v) for v in x])
        return ahead * accel + drag

    def _mass_ahead(self, x: float) -> float:
        """Mass [kg] ahead of station ``x`` (from the lumped translational diagonal of M's rows)."""
        n = len(self.xi)
        w = np.zeros(2 * n)
        w[0::2] = 1.0
        per_node = (self.M @ w)[0::2]
        return float(per_node[self.xi < x].sum() + 0.5 * per_node[np.isclose(self.xi, x)].sum())


def _element(EI: float, mu: float, le: float) -> tuple[np.ndarray, np.ndarray]:
    k = EI / le**3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                               [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le**2, -6 * le, 4 * le**2]])
    m = mu * le / 420 * np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                                  [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le**2, -22 * le, 4 * le**2]])
    return k, m


def free_free_beam(length: float, EI: float, line_mass: Any, points: list[tuple[float, float]],
                   n_el: int = 170, n_modes: int = 2, gimbal: float | None = None) -> Beam:
    """A free-free beam of ``n_el`` elements: ``line_mass(xi)`` [kg/m] (a callable, averaged over each
    element at 8 points), ``points`` ``(xi, mass)`` lumped at the nearest node."""
    xi = np.linspace(0.0, length, n_el + 1)
    le = length / n_el
    n = 2 * (n_el + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_el):
        mu = float(np.mean(line_mass(xi[e] + le * (np.arange(8) + 0.5) / 8)))
        k, m = _element(EI, mu, le)
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
    for x, m in points:
        i = int(round(x / le))
        M[2 * i, 2 * i] += m
    t_vec = np.zeros(n)
    t_vec[0::2] = 1.0
    mass = float(t_vec @ M @ t_vec)
    r = np.zeros(n)                                  # rigid rotation about the nose: y = -xi, y' = -1
    r[0::2], r[1::2] = -xi, -1.0
    cg = float(-(t_vec @ M @ r) / mass)
    rc = r + cg * t_vec                              # rotation about the CG
    inertia = float(rc @ M @ rc)
    w2, vec = linalg.eigh(K, M)
    keep = np.argsort(w2)[2:2 + n_modes]             # the two rigid modes first
    modes = vec[:, keep]
    for k in range(modes.shape[1]):
        modes[:, k] /= math.sqrt(modes[:, k] @ M @ modes[:, k]) * (1 if modes[-2, k] >= 0 else -1)
    return Beam(xi, M, K, mass, cg, inertia, np.sqrt(np.maximum(w2[keep], 0.0)), modes, length,
                length if gimbal is None else gimbal)


def vehicle_beam(t: float, length: float = 8.5, diameter: float = 0.2833, wall_thickness: float = 0.002,
                 mass_flow: float = 30.0, fill: float = 1.0, n_el: int = 170, n_modes: int = 2) -> Beam:
    """The slender vehicle at flight time ``t`` [s] as a free-free beam (see the module docstring)."""
    v = slender_mapping(length=length, diameter=diameter, fill=fill, mass_flow=mass_flow,
                        wall_thickness=wall_thickness)
    st = v["stages"][0]
    sec = st["sections"][0]
    mat = MATERIALS[sec["material"]]
    D, tw = float(st["outer_diameter"]), float(sec["wall_thickness"])
    EI = mat.youngs_modulus * math.pi * (D**4 - (D - 2 * tw) ** 4) / 64.0
    mu_wall = mat.density * math.pi * (D - tw) * tw
    tank = st["tanks"][0]
    mu_liq = tank["density"] * math.pi * tank["inner_radius"] ** 2
    bottom = -tank["top"] + tank["height"]
    h0 = tank["height"] * tank["fill_ratio"]
    h = max(h0 - mass_flow * t / mu_liq, 0.0)

    def line_mass(x: np.ndarray) -> np.ndarray:
        return mu_wall + np.where((x >= bottom - h) & (x <= bottom), mu_liq, 0.0)

    from lvgym.vehicle import slender as sl
    points = [(f * length, m) for f, m in (sl.FORWARD_EQUIPMENT, sl.AFT_EQUIPMENT)]
    eng = st["engines"][0]
    points.append((-eng["cg"], eng["mass"]))
    return free_free_beam(length, EI, line_mass, points, n_el, n_modes, gimbal=-eng["gimbal"])


def uniform_beam_check(n_el: int = 100) -> tuple[float, float]:
    """(``beta_1 L`` of the FE model of a uniform free-free beam, the analytic 4.7300)."""
    b = free_free_beam(1.0, 1.0, lambda x: np.ones_like(x), [], n_el)
    return float(math.sqrt(b.omega[0])), 4.730040745


@dataclass
class Lift:
    """Normal-force slope distribution: quadrature stations ``xi`` [m] and each point's share ``c``
    [1/rad] of CN-alpha on the reference area ``s_ref`` [m^2]."""

    xi: np.ndarray
    c: np.ndarray
    s_ref: float

    @property
    def cn_alpha(self) -> float:
        return float(self.c.sum())

    @property
    def x_cp(self) -> float:
        return float((self.c * self.xi).sum() / self.c.sum())


def ogive_radius(x: np.ndarray, nose_length: float, radius: float) -> np.ndarray:
    """Tangent ogive radius [m] at ``x`` behind the tip."""
    rho = (radius**2 + nose_length**2) / (2.0 * radius)
    return np.sqrt(rho**2 - (nose_length - x) ** 2) + radius - rho


def vehicle_lift(length: float = 8.5, diameter: float = 0.2833, mach: float = 2.0, n_nose: int = 200,
                 fins_concentrated: bool = True) -> Lift:
    """The vehicle's lift: slender-body theory over the ogive (computed here) and the fins' CN-alpha and
    CP from lvgym's Barrowman table at ``mach`` (the only lvgym aerodynamic numbers used), concentrated
    at the CP (``fins_concentrated``) or spread evenly over 5 points of their root chord."""
    from lvgym.environment import make

    v = slender_mapping(length=length, diameter=diameter)
    aero = make("aerodynamics", v["aerodynamics"])
    comps = aero.components(mach)
    R = 0.5 * diameter
    S = math.pi * R * R
    ln = float(v["aerodynamics"]["nose"]["length"])
    edges = np.linspace(0.0, ln, n_nose + 1)
    area = math.pi * ogive_radius(edges, ln, R) ** 2
    xi = 0.5 * (edges[1:] + edges[:-1])
    c = 2.0 / S * np.diff(area)
    for name, (cna, x_cp) in comps.items():
        if name.startswith("fins"):
            if fins_concentrated:
                xi, c = np.append(xi, -x_cp), np.append(c, cna)
            else:
                chord = float(v["aerodynamics"]["fins"]["root_chord"])
                pts = -x_cp + chord * np.linspace(-0.4, 0.4, 5)
                xi, c = np.append(xi, pts), np.append(c, np.full(5, cna / 5))
        elif name != "nose":
            raise ValueError(f"component {name!r} not modelled")
    return Lift(xi, c, S)


def static_stiffness(beam: Beam, lift: Lift) -> dict[str, Any]:
    """Per unit ``qbar S``: the rigid moment slope about the CG ``m0 = sum c (xi_cg - xi)`` [m/rad]
    (negative: stable), the moment per modal coordinate ``e_k = sum c (xi_cg - xi) phi_k'``, the modal
    force per angle of attack ``b_k = sum c phi_k`` and per modal coordinate ``A_kj = sum c phi_k phi_j'``
    (so that ``M / (qS) = m0 alpha - e . eta``, ``Q_eta / (qS) = b alpha - A eta``)."""
    phi, dphi = beam.shape(lift.xi)
    arm = beam.cg - lift.xi
    return {"m0": float((lift.c * arm).sum()), "e": (lift.c * arm * dphi).sum(axis=1),
            "b": (lift.c * phi).sum(axis=1), "A": np.einsum("n,kn,jn->kj", lift.c, phi, dphi),
            "omega2": beam.omega**2, "s_ref": lift.s_ref}


def elastic_moment_ratio(st: dict[str, Any], qbar: float) -> float:
    """Elastic pitching moment of the statically deflected vehicle over the rigid one at ``qbar`` [Pa]
    (-1: the weathercock stiffness is gone)."""
    qs = qbar * st["s_ref"]
    eta = np.linalg.solve(np.diag(st["omega2"]) + qs * st["A"], qs * st["b"])       # per unit alpha
    return float(-(st["e"] @ eta) / st["m0"])


def _first_sign_change(f: Any, grid: np.ndarray, xtol: float) -> float:
    """The first ``q`` of ``grid`` [Pa] where ``f`` goes from positive to non-positive, refined by Brent's
    method to ``xtol`` [Pa]; ``inf`` if it never does."""
    vals = [f(q) for q in grid]
    for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if fa > 0 >= fb:
            return float(optimize.brentq(f, a, b, xtol=xtol))
    return math.inf


def divergence_qbar(st: dict[str, Any], hi: float = 5e6) -> float:
    """Dynamic pressure [Pa] where the inertia-relieved pitch stiffness passes zero (ratio -1)."""
    return _first_sign_change(lambda q: elastic_moment_ratio(st, q) + 1.0, np.geomspace(1e3, hi, 200), 1.0)


@dataclass
class FlightCondition:
    """Flight state of a frozen time: dynamic pressure [Pa], airspeed [m/s], thrust and drag [N]."""

    qbar: float
    airspeed: float
    thrust: float
    drag: float


def dynamic_matrix(beam: Beam, lift: Lift, fc: FlightCondition, damping: float = 0.01, thrust: bool = True,
                   axial: bool = True, rate_terms: bool = True, modes: bool = True) -> np.ndarray:
    """Linear pitch-plane dynamics, states ``(v, theta, q, eta_1..K, eta_dot_1..K)``: the CG's lateral
    velocity (up) [m/s], the pitch angle (nose up) [rad] and rate, the modal coordinates. Gimbal at zero.

    ``thrust``: the follower thrust's generalised forces at the gimbal; ``axial``: the geometric stiffness
    of the axial compression; ``rate_terms``: the pitch-rate and deflection-rate incidences; ``modes``:
    False drops the modes (the rigid vehicle)."""
    K = beam.modes.shape[1] if modes else 0
    n = 3 + 2 * K
    qs, V, m, J = fc.qbar * lift.s_ref, fc.airspeed, beam.mass, beam.inertia
    phi, dphi = beam.shape(lift.xi)
    phi, dphi = phi[:K], dphi[:K]
    c, d = lift.c, lift.xi - beam.cg                       # d > 0 aft of the CG
    # incidence at each point per state: alpha_j = G_j . x
    G = np.zeros((len(c), n))
    G[:, 0] = -1.0 / V
    G[:, 1] = 1.0
    if rate_terms:
        G[:, 2] = d / V
        G[:, 3 + K:] = -phi.T / V
    G[:, 3:3 + K] = -dphi.T
    lift_f = qs * (c[:, None] * G)                          # (n_pts, n): the up force of each point
    A = np.zeros((n, n))
    A[0] = lift_f.sum(axis=0) / m
    A[0, 1] += -fc.drag / m
    A[1, 2] = 1.0
    A[2] = (-(d[:, None] * lift_f)).sum(axis=0) / J
    for k in range(K):
        A[3 + k, 3 + K + k] = 1.0
        row = 3 + K + k
        A[row] = (phi[k][:, None] * lift_f).sum(axis=0)
        A[row, 3 + k] -= beam.omega[k] ** 2
        A[row, 3 + K + k] -= 2 * damping * beam.omega[k]
    if K and thrust:
        T = fc.thrust
        pg, dg = (a[:K, 0] for a in beam.shape([beam.gimbal]))
        arm = beam.gimbal - beam.cg
        A[0, 1] += T / m
        A[0, 3:3 + K] += -T * dg / m
        A[2, 3:3 + K] += (-T * pg + T * arm * dg) / J
        A[3 + K:, 3:3 + K] += -T * np.outer(pg, dg)
    elif thrust:
        A[0, 1] += fc.thrust / m
    if K and axial:
        xq = np.linspace(0.0, beam.length, 801)
        accel = (fc.thrust - fc.drag) / m
        P = beam.compression(xq, accel, fc.drag)
        _, dq = beam.shape(xq)
        Kg = np.trapezoid(P * dq[:K, None, :] * dq[None, :K, :], xq, axis=2)
        A[3 + K:, 3:3 + K] += Kg
    return A


def growth_rate(A: np.ndarray) -> float:
    """The largest real eigenvalue [1/s] of ``A`` (the divergence; -inf if none is real)."""
    ev = np.linalg.eigvals(A)
    real = ev[np.abs(ev.imag) < 1e-9].real
    return float(real.max()) if real.size else -math.inf


# ------------------------------------------------------------------ lvgym's side of the comparison
def pinned_operating_point(t: float, diameter: float = 0.2833, length: float = 8.5,
                           wall_thickness: float = 0.002) -> Any:
    """An operating point of ``SlenderAscent-v1`` with a tube wall of ``wall_thickness`` [m] (default the
    thesis's 2 mm, the tube this module checks; the env's own default is 4.5 mm) (non-rigid, calm, gimbal
    at zero) at ``t`` [s] whose
    state is that of the same flight without the aeroelastic loads (which lasts the 10 s), and whose
    simulator, parameters and context are the aeroelastic env's: the flight with the loads diverges
    after 4 s, so its own state is no operating point beyond that. Both envs are stepped together and
    the aeroelastic one's state is overwritten by the other's after every control period."""
    import gymnasium as gym

    import lvgym  # noqa: F401
    from lvgym.baselines.design.linearize import OperatingPoint
    from lvgym.simulator import data as simdata

    opts = {"model": "nonrigid", "wind": "none", "diameter": diameter, "length": length,
            "wall_thickness_m": wall_thickness}
    on = gym.make("lvgym/SlenderAscent-v1", **opts)
    off = gym.make("lvgym/SlenderAscent-v1", aeroelastic=False, **opts)
    on.reset(seed=0)
    off.reset(seed=0)
    zero = np.zeros(on.action_space.shape, on.action_space.dtype)
    dt = float(on.unwrapped.task.control_dt_s)
    while float(on.unwrapped.state.sim.t[0]) < t - 0.5 * dt:
        on.step(zero)
        off.step(zero)
        on.unwrapped.state.sim.x[0][:] = off.unwrapped.state.sim.x[0]
    son = on.unwrapped.state.sim
    return OperatingPoint(float(son.t[0]), son.x[0].copy(), son.p[0].copy(), son.ctx[0].copy(), on.unwrapped.sim, opts,
                          on.unwrapped.task, simdata.take(son, [0]))


def lvgym_poles(op: Any, plane: str = "pitch") -> dict[str, Any]:
    """lvgym's linearised non-rigid plant at ``op``: its eigenvalues, the largest real one, the flight
    condition and the rigid properties."""
    from lvgym.baselines.design.linearize import aero_slopes, linearize

    g = linearize(op=op, plane=plane)
    ev = np.linalg.eigvals(np.asarray(g.A, float))
    real = ev[np.abs(ev.imag) < 1e-9].real
    tl = op.sim.timeline
    n_a, m_a, V, D = aero_slopes(op)
    return {"t": op.t, "poles": ev, "max_real": float(real.max()) if real.size else -math.inf,
            "fc": FlightCondition(op.condition("qbar"), float(V),
                                  op.condition("thrust"), float(D)),
            "mass": float(tl.interp("mass", [op.t])[0]), "inertia": float(tl.interp("inertia", [op.t])[0][1, 1]),
            "cg": -float(np.ravel(tl.interp("cg", [op.t])[0])[0]), "m_alpha": float(m_a), "n_alpha": float(n_a)}


def pitch_stiffness(A: np.ndarray) -> tuple[float, float]:
    """(quasi-static pitch stiffness with the modes statically deflected, rigid one) [1/s^2] of a
    :func:`dynamic_matrix`: ``-(A_q,theta - A_q,eta A_eta,eta^-1 A_eta,theta)`` and ``-A_q,theta``
    (positive: weathercock stable; the plunge held)."""
    K = (A.shape[0] - 3) // 2
    rig = -A[2, 1]
    if K == 0:
        return rig, rig
    e, s = slice(3, 3 + K), slice(3 + K, 3 + 2 * K)
    a_ee, a_et, a_qe = A[s, e], A[s, 1], A[2, e]
    return float(rig + a_qe @ np.linalg.solve(a_ee, a_et)), float(rig)


def divergence_qbar_flight(beam: Beam, lift: Lift, fc: FlightCondition, hi: float = 5e6, **options: Any) -> float:
    """Dynamic pressure [Pa] where :func:`pitch_stiffness` of :func:`dynamic_matrix` (``options``:
    ``thrust``, ``axial``) passes zero, with the beam, thrust and axial acceleration of ``fc`` frozen and
    the drag scaled with the dynamic pressure."""
    ca = fc.drag / fc.qbar

    def f(q: float) -> float:
        c = FlightCondition(q, fc.airspeed, fc.thrust, ca * q)
        return pitch_stiffness(dynamic_matrix(beam, lift, c, **options))[0]

    return _first_sign_change(f, np.geomspace(1e4, hi, 120), 10.0)


def stabilisability(op: Any, plane: str = "pitch") -> dict[str, float]:
    """What limits a TVC loop at ``op`` (docs/aerodynamics.md): the flight plant's unstable real pole
    ``p`` [1/s] and real right-half-plane zero ``z`` [1/s] (continuous equivalents of
    :func:`.flightloop.flight_plant`, gimbal command to sampled gyro), the pure delay ``theta`` [s]
    (the computational delay plus half a control period for the hold), the servo's equivalent lag
    ``2 zeta / omega`` [s], and the lower bounds on the closed loop's peak complementary sensitivity of
    any linear controller, ``Mt >= exp(p theta) (z + p) / (z - p)`` (with the delay alone: ``mt_delay``;
    with the servo counted as delay: ``mt_servo``); the TVC moment per gimbal radian ``T l`` [N m/rad]."""
    import control

    from lvgym.baselines.design.flightloop import control_timing, flight_plant

    G = flight_plant(op, plane)
    dt = float(G.dt)
    poles = np.asarray(control.poles(G), complex)
    zeros = np.asarray(control.zeros(G), complex)
    pc = np.log(poles[np.abs(poles) > 1e-12]) / dt
    zc = np.log(zeros[np.abs(zeros) > 1e-12]) / dt
    p = float(pc[np.abs(pc.imag) < 1e-9].real.max())
    rz = zc[(np.abs(zc.imag) < 1e-9) & (zc.real > 1e-3)].real
    z = float(rz.min()) if rz.size else math.inf
    _, steps = control_timing(op)
    theta = steps * dt + 0.5 * dt
    s = op.sim.servo
    lag = 2.0 * float(s.damping) / float(s.frequency)
    ratio = (z + p) / (z - p) if math.isfinite(z) and z > p else (1.0 if not math.isfinite(z) else math.inf)
    tl = op.sim.timeline
    cg = float(np.ravel(tl.interp("cg", [op.t])[0])[0])
    arm = cg - float(op.p[op.sim.layout.params["r_gimbal"]][0])
    return {"p": p, "z": z, "theta": theta, "servo_lag": lag, "p_tau": p * (theta + lag),
            "mt_delay": math.exp(p * theta) * ratio, "mt_servo": math.exp(p * (theta + lag)) * ratio,
            "tvc_moment_per_rad": op.condition("thrust") * arm,
            "servo_radps": float(s.frequency)}


def lqg_sensitivity_sweep(op: Any, plane: str = "pitch", rhos: Any = None, noises: Any = None) -> dict[str, float]:
    """The smallest peak sensitivity ``Ms`` [-] that a sweep of discrete LQG controllers reaches on the
    flight plant at ``op`` (:func:`.flightloop.flight_plant`): an output-weighted LQR (``rho C^T C``,
    unit input weight) with a predictor Kalman observer (process noise ``noise`` at the plant input, unit
    measurement noise), over ``rhos`` x ``noises`` (default 15 x 9 log-spaced); only closed-loop stable
    designs count. Returns ``ms``, its ``rho``, ``noise`` and the disk margins it implies."""
    import warnings

    import control

    from lvgym.baselines.design.flightloop import flight_plant

    G = control.ss(flight_plant(op, plane))
    A, B, C = (np.asarray(m, float) for m in (G.A, G.B, G.C))
    n, dt = A.shape[0], float(G.dt)
    z = np.exp(1j * np.geomspace(0.1, 0.999 * math.pi / dt, 500) * dt)
    rhos = np.geomspace(1e-2, 1e5, 15) if rhos is None else rhos
    noises = np.geomspace(1e-4, 1e4, 9) if noises is None else noises
    best = (math.inf, math.nan, math.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for rho in rhos:
            for qn in noises:
                try:
                    K, _, _ = control.dlqr(A, B, rho * C.T @ C + 1e-8 * np.eye(n), 1.0)
                    L, _, _ = control.dlqe(A, B, C, qn, 1.0)
                except Exception:                                   # noqa: BLE001 (a failed Riccati solve)
                    continue
                Kc = control.ss(A - B @ K - L @ C, L, K, 0.0, dt)      # u = -Kc y
                loop_ = control.series(Kc, G)
                if np.abs(np.linalg.eigvals(np.asarray(control.ss(control.feedback(loop_, 1)).A))).max() >= 1.0:
                    continue
                ms = float(np.abs(1.0 / (1.0 + np.asarray(loop_(z), complex).ravel())).max())
                if ms < best[0]:
                    best = (ms, float(rho), float(qn))
    ms = best[0]
    return {"ms": ms, "rho": best[1], "noise": best[2],
            "disk_gm_up_db": 20 * math.log10(ms / (ms - 1)) if ms > 1 else math.inf,
            "disk_gm_down_db": 20 * math.log10(ms / (ms + 1)),
            "disk_pm_deg": math.degrees(2 * math.asin(min(1.0, 1 / (2 * ms))))}
