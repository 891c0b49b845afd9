"""Pitch-plane linear models of a vehicle in flight, by finite differences of the nonlinear model.

:func:`operating_point` flies an env with the gimbal centred up to a flight time and takes the
simulator's state, parameters and context there. :func:`linearize` differentiates the continuous
dynamics at that point: the dynamics core (:class:`lvgym.dynamics.NonRigidModel`, through the timeline's
``dynamics``) with the simulator's compiled flight loads (:data:`lvgym.simulator.flight_loads`: gravity,
thrust and aerodynamics, all functions of the state), by central differences in local coordinates:

* ``v`` body-frame components (at the operating attitude) of the CG's inertial velocity [m/s];
* ``theta`` a small rotation of the body about its own axes, ``q_bi <- q_bi (1, theta / 2)`` [rad];
* ``omega`` body rates [rad/s]; ``eta``, ``eta_dot`` modal coordinates (y plane, then z);
* per active pendulum ``beta`` (rotation about its y_s and z_s axes) and its rates ``omega_si_s``.

Kinematic rows are exact to first order for the small rates of a vehicle near its operating point
(``theta_dot = omega``, ``beta_dot = omega_s``); the position is left out (it acts only through the
gravity gradient and the altitude). The pitch plane keeps ``v_z, theta_y, omega_y``, the z-plane modes
and each pendulum's ``beta_y, omega_s_y``; input the pitch gimbal angle [rad], output the pitch rate
[rad/s]. The rigid model (``model="rigid"``) has three states; ``nonrigid`` adds slosh and bending.

:func:`loop` closes it: the second-order servo, a zero-order hold at the control period and the discrete
PID of :mod:`.pid` (backward Euler), or the continuous PID; :func:`margins` reports gain and phase
margins with ``control.stability_margins``. :func:`analytic_rigid` is the textbook rigid pitch model
(mass, inertia, thrust, CG-gimbal arm, aerodynamic normal-force slope and centre of pressure) used to
validate the numerical one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import control
import gymnasium as gym
import numpy as np

import lvgym  # noqa: F401  (registers the envs)
from lvgym.simulator import flight_loads
from lvgym.rotations import quat_mul
from lvgym.simulator import CONDITIONS, CONTEXT
from lvgym.simulator.flight import flight_conditions_batch

ENV_IDS = {"smile": "lvgym/SmileAscent-v0", "stratos3": "lvgym/StratosIII-v0", "slender": "lvgym/SlenderAscent-v0"}


@dataclass
class OperatingPoint:
    t: float
    x: np.ndarray
    p: np.ndarray
    c: np.ndarray
    sim: Any
    env_options: dict


def operating_point(vehicle: str = "smile", t: float = 28.8, model: str = "rigid", **options: Any) -> OperatingPoint:
    """The state of ``vehicle``'s env flown with the gimbal centred and no wind up to time ``t`` [s]."""
    env_id = ENV_IDS.get(vehicle)
    if env_id is None:
        raise ValueError(f"vehicle = {vehicle!r}: one of {sorted(ENV_IDS)}")
    opts = {"model": model, "wind": "none", **options}
    if vehicle == "stratos3":
        opts.setdefault("control", "tvc")
    env = gym.make(env_id, **opts)
    env.reset(seed=0)
    sim = env.unwrapped.sim                          # its rows are the env's state
    if t > 0:
        sim.step(np.zeros((1, 2)), float(t))
    return OperatingPoint(float(sim.t[0]), sim.x[0].copy(), sim.p[0].copy(), sim.c[0].copy(), sim, opts)


def _rot(q: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """``q (1, theta/2)`` normalised: q turned by the small rotation ``theta`` about its own axes."""
    dq = np.concatenate([[1.0], 0.5 * np.asarray(theta, float)])
    out = quat_mul(q, dq)
    return out / np.linalg.norm(out)


def _dcm(q: np.ndarray) -> np.ndarray:
    """``C_ib`` of the scalar-first quaternion ``q_bi``."""
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


class _Coords:
    """Local coordinates around an operating point and the derivative in them."""

    def __init__(self, op: OperatingPoint) -> None:
        self.op = op
        self.dyn = op.sim.dynamics
        lay = self.layout = self.dyn.layout
        self.K, N = self.dyn.n_modes, self.dyn.n_slosh
        m = lay.view(op.p, "params", "slosh") if N else np.zeros(0)
        self.active = [j for j in range(N) if op.p[lay.slosh_param(j, "m")][0] > 0.0]
        self.C0 = _dcm(op.x[lay.state["q_bi"]])
        names = ["v_x", "v_y", "v_z", "theta_x", "theta_y", "theta_z", "omega_x", "omega_y", "omega_z"]
        names += [f"eta_{pl}{k}" for pl in "yz" for k in range(self.K)]
        names += [f"eta_dot_{pl}{k}" for pl in "yz" for k in range(self.K)]
        names += [f"beta_{j}_{a}" for j in self.active for a in "yz"]
        names += [f"omega_s_{j}_{a}" for j in self.active for a in "yz"]
        self.names = names
        del m

    def state(self, d: np.ndarray) -> np.ndarray:
        """The full state at local coordinates ``d``."""
        lay, K = self.layout, self.K
        x = self.op.x.copy()
        x[lay.state["v_zw_i"]] += self.C0 @ d[0:3]
        s = lay.state["q_bi"]
        x[s] = _rot(x[s], d[3:6])
        x[lay.state["omega_bi_b"]] += d[6:9]
        o = 9
        x[lay.state["eta"]] += d[o:o + 2 * K]
        x[lay.state["eta_dot"]] += d[o + 2 * K:o + 4 * K]
        o += 4 * K
        na = len(self.active)
        q_si = lay.view(x, "state", "q_si")
        w_si = lay.view(x, "state", "omega_si_s")
        for i, j in enumerate(self.active):
            q_si[j] = _rot(q_si[j], [0.0, d[o + 2 * i], d[o + 2 * i + 1]])
            w_si[j] += d[o + 2 * na + 2 * i:o + 2 * na + 2 * i + 2]
        return x

    def rates(self, d: np.ndarray, gimbal: float) -> np.ndarray:
        """Derivatives of the dynamic coordinates (v, omega, eta, eta_dot, omega_s) at ``d``."""
        lay, K = self.layout, self.K
        x = self.state(d)
        c = self.op.c.copy()
        c[CONTEXT.offset("gimbal")] += gimbal                # the pitch entry
        c[CONTEXT.index("time0")] = self.op.t
        u = np.zeros(lay.n_u)
        flight_loads(0.0, x, self.op.p.copy(), c, u)
        f = self.dyn.derivative(x, self.op.p, u)
        w_s = lay.view(f, "state", "omega_si_s")
        return np.concatenate([self.C0.T @ f[lay.state["v_zw_i"]], f[lay.state["omega_bi_b"]],
                               f[lay.state["eta"]], f[lay.state["eta_dot"]],
                               np.concatenate([w_s[j] for j in self.active]) if self.active else np.zeros(0)])

    def jacobian(self, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
        """``A`` (n, n) and ``B`` (n, 1) in the local coordinates (input: pitch gimbal [rad])."""
        K, na = self.K, len(self.active)
        n = 9 + 4 * K + 4 * na
        dyn_rows = np.r_[0:3, 6:9, 9:9 + 4 * K, 9 + 4 * K + 2 * na:n]
        A, B = np.zeros((n, n)), np.zeros((n, 1))
        for i in range(n):
            e = np.zeros(n)
            step = h * (1e3 if i < 3 else 1.0)            # velocities in m/s
            e[i] = step
            A[dyn_rows, i] = (self.rates(e, 0.0) - self.rates(-e, 0.0)) / (2 * step)
        B[dyn_rows, 0] = (self.rates(np.zeros(n), h) - self.rates(np.zeros(n), -h)) / (2 * h)
        A[3:6, 6:9] += np.eye(3)                              # theta_dot = omega
        o = 9 + 4 * K
        A[o:o + 2 * na, o + 2 * na:o + 4 * na] += np.eye(2 * na)   # beta_dot = omega_s
        return A, B


def linearize(vehicle: str = "smile", t: float = 28.8, model: str = "rigid", op: OperatingPoint | None = None,
              full: bool = False, **options: Any) -> control.StateSpace:
    """Pitch-plane state space from pitch gimbal [rad] to pitch rate [rad/s] at flight time ``t``;
    ``full=True`` keeps every local coordinate (both planes) instead."""
    op = op if op is not None else operating_point(vehicle, t, model, **options)
    co = _Coords(op)
    A, B = co.jacobian()
    names = co.names
    keep = list(range(len(names))) if full else [i for i, nm in enumerate(names) if nm in ("v_z", "theta_y", "omega_y")
                                                 or nm.startswith(("eta_z", "eta_dot_z")) or nm.endswith("_y") and
                                                 nm.startswith(("beta_", "omega_s_"))]
    C = np.zeros((1, len(keep)))
    C[0, keep.index(names.index("omega_y"))] = 1.0
    sys = control.ss(A[np.ix_(keep, keep)], B[keep], C, 0.0, inputs=["gimbal_pitch"], outputs=["omega_y"],
                     states=[names[i] for i in keep])
    return sys


def aero_slopes(op: OperatingPoint, dw: float = 0.1) -> tuple[float, float, float]:
    """Normal-force slope ``N_alpha`` [N/rad], pitch-moment slope about the CG ``M_alpha`` [N m/rad] and
    airspeed [m/s] at the operating point, from the aerodynamic model (lateral velocity +- dw)."""
    co = _Coords(op)
    out = []
    for s in (dw, -dw):
        d = np.zeros(9 + 4 * co.K + 4 * len(co.active))
        d[2] = s
        x = co.state(d)[None]
        cond = CONDITIONS.zeros(1)
        flight_conditions_batch(np.array([op.t]), x, op.p[None], op.c[None], cond)
        out.append(cond[0])
    (a, b) = out
    get = CONDITIONS.view
    V = 0.5 * (get(a, "airspeed")[0] + get(b, "airspeed")[0])
    dalpha = 2 * dw / V
    n_alpha = -(get(a, "f_aero_b")[2] - get(b, "f_aero_b")[2]) / dalpha
    m_alpha = (get(a, "m_aero_b")[1] - get(b, "m_aero_b")[1]) / dalpha
    axial = -0.5 * (get(a, "f_aero_b")[0] + get(b, "f_aero_b")[0])
    return n_alpha, m_alpha, V, axial


def analytic_rigid(op: OperatingPoint) -> control.StateSpace:
    """Textbook rigid pitch-plane model, states ``(w, theta, q)``::

        m w_dot = T (delta - theta) + D theta - N_a alpha      alpha = theta + w / V
        J q_dot = T l delta + M_a alpha                         theta_dot = q

    with mass ``m``, pitch inertia ``J`` about the CG, thrust ``T``, arm ``l`` from the gimbal to the CG,
    axial drag ``D``, normal-force and moment slopes ``N_a``, ``M_a`` from the aerodynamic model."""
    tl = op.sim.timeline
    m = float(tl.interp("mass", [op.t])[0])
    J = float(tl.interp("inertia", [op.t])[0][1, 1])
    cg = float(tl.interp("cg", [op.t])[0][0]) if np.ndim(tl.cg) == 2 else float(tl.interp("cg", [op.t])[0])
    lay = op.sim.layout
    gimbal = float(op.p[lay.params["r_gimbal"]][0])
    T = float(op.sim.conditions("thrust")[0])
    n_a, m_a, V, D = aero_slopes(op)
    l = cg - gimbal
    A = np.array([[-n_a / (m * V), (-T + D - n_a) / m, 0.0], [0.0, 0.0, 1.0], [m_a / (J * V), m_a / J, 0.0]])
    B = np.array([[T / m], [0.0], [T * l / J]])
    return control.ss(A, B, [[0.0, 0.0, 1.0]], 0.0)


# ---------------------------------------------------------------------------- the loop
def servo_tf(frequency: float = 15.0, damping: float = 0.7) -> control.TransferFunction:
    return control.tf([frequency ** 2], [1.0, 2 * damping * frequency, frequency ** 2])


def pid_tf(kp: float, ki: float, kd: float, n: float | None = None, dt: float | None = None) -> control.TransferFunction:
    """The PID of :mod:`.pid`: continuous ``Kp + Ki/s + Kd N s/(s+N)``, or (``dt``) its backward-Euler
    discretisation (``s -> (z - 1) / (z dt)``) as a discrete transfer function."""
    n = math.inf if n is None else float(n)
    if dt is None:
        s = control.tf("s")
        d = kd * s if math.isinf(n) else kd * n * s / (s + n)
        return kp + ki / s + d
    z = control.tf([1.0, 0.0], [1.0], dt)
    i = ki * dt * z / (z - 1)
    d = kd * (z - 1) / (dt * z) if math.isinf(n) else kd * n * (z - 1) / ((1 + n * dt) * z - 1)
    return kp + i + d


def loop(plant: control.StateSpace, gains: tuple[float, float, float, float | None], dt: float | None = 0.02,
         servo: tuple[float, float] = (15.0, 0.7)) -> control.LTI:
    """Open loop ``C * servo * plant`` (negative feedback of the rate). With ``dt``, the servo and the
    plant are discretised with a zero-order hold (the env holds the command over a control period)."""
    g = control.series(servo_tf(*servo), plant)
    if dt is None:
        return control.series(g, pid_tf(*gains))
    gd = control.c2d(control.ss(g), dt, "zoh")
    return control.series(gd, control.ss(pid_tf(*gains, dt=dt)))


def margins(L: control.LTI) -> dict[str, float]:
    """Margins of the open loop ``L`` (negative feedback).

    ``gain_margin_db``: the gain increase that destabilises (the smallest ``1/|L|`` over the phase
    crossovers where ``|L| < 1``); ``gain_reduction_margin_db`` (<= 0): the gain decrease that
    destabilises a conditionally stable loop (the vehicle's slow drift pole is unstable, so the loop
    needs a minimum low-frequency gain); ``phase_margin_deg``: the smallest over the gain crossovers;
    ``closed_loop_stable``: poles of ``L / (1 + L)`` (growth below 1e-4 1/s), where a pole at the origin (z = 1) is allowed: it
    is the controller's integrator cancelling the zero at the origin of pitch rate over gimbal (the rate
    loop leaves the attitude neutral); ``max_pole_real_per_s``: the largest real part of the closed-loop
    poles (continuous equivalents ``ln z / dt``), the growth rate of the slowest divergence."""
    gm, pm, _, wpc, wgc, _ = control.stability_margins(L, returnall=True)
    gm, pm, wpc, wgc = (np.atleast_1d(np.asarray(a, float)) for a in (gm, pm, wpc, wgc))
    ok = np.isfinite(gm) & (gm > 0) & (wpc > 1e-6)
    up, lo = gm[ok & (gm > 1)], gm[ok & (gm < 1)]
    i_pm = int(np.argmin(np.abs(pm))) if pm.size else None
    cl = control.feedback(L, 1)
    p = np.asarray(control.poles(cl), complex)
    s = np.log(p) / L.dt if L.dt else p
    growth = float(s.real.max())
    stable = growth < 1e-4
    return {"gain_margin_db": float(20 * np.log10(up.min())) if up.size else float("inf"),
            "gain_reduction_margin_db": float(20 * np.log10(lo.max())) if lo.size else float("-inf"),
            "phase_margin_deg": float(pm[i_pm]) if i_pm is not None else float("inf"),
            "gain_crossover_radps": float(wgc[i_pm]) if i_pm is not None else float("nan"),
            "closed_loop_stable": stable, "max_pole_real_per_s": growth}
