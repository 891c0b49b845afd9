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
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import control
import gymnasium as gym
import numpy as np
from scipy import optimize

import lvgym  # noqa: F401  (registers the envs)
from lvgym.simulator import flight_loads
from lvgym.packing import Field, Packed
from lvgym.rotations import quat_mul
from lvgym.simulator import CONDITIONS, CONTEXT
from lvgym.simulator import data as simdata
from lvgym.simulator.flight import flight_conditions_batch

from .response import frequency_response
from .target import ENV_IDS, design_env  # noqa: F401  (ENV_IDS: the shipped vehicles' envs, here as before)

#: the planes of :func:`linearize`: the state entries kept, the input and the rate output of each
PLANES = {"pitch": ("v_z", "theta_y", "omega_y", "z", "y", "gimbal_pitch", "omega_y"),
          "yaw": ("v_y", "theta_z", "omega_z", "y", "z", "gimbal_yaw", "omega_z"),
          "roll": (None, "theta_x", "omega_x", None, None, "moment_x", "omega_x")}
#: inputs of the full Jacobian: pitch and yaw gimbal [rad], roll moment [N m]
INPUTS = ("gimbal_pitch", "gimbal_yaw", "moment_x")


@dataclass
class OperatingPoint:
    """A flight state to linearise about: time ``t`` [s], the dynamics state ``x``, parameters ``p`` and
    simulator context ``c`` of one row, the simulator ``sim`` (its timeline, IMU and servo), the env's
    task spec ``task``, the env options it was flown with and ``data``, a copy of the row's simulator
    state (a one-row :class:`~lvgym.simulator.SimData`; :meth:`condition` reads its flight conditions)."""

    t: float
    x: np.ndarray
    p: np.ndarray
    c: np.ndarray
    sim: Any
    env_options: dict
    task: Any = None
    data: Any = None

    def condition(self, name: str) -> Any:
        """Flight condition ``name`` (:data:`lvgym.simulator.CONDITIONS`) at the operating point (a float
        for a scalar entry, else an array)."""
        if self.data is None:
            raise ValueError("this operating point holds no simulator rows (data=None)")
        value = self.sim.conditions(self.data, name)[0]
        return float(value) if np.ndim(value) == 0 else np.array(value)


#: the flights :func:`operating_point` continues inside :func:`reused_flights` (None: outside)
_FLIGHTS: dict[tuple, "_Flight"] | None = None


@dataclass
class _Flight:
    """An env flown up to some time with a policy: its last observation and info."""

    env: Any
    policy: Any
    obs: Any
    info: dict

    @classmethod
    def start(cls, env_id: str, opts: dict[str, Any], policy: Any) -> "_Flight":
        env = gym.make(env_id, **opts)
        obs, info = env.reset(seed=0)
        if policy is not None and not hasattr(policy, "act"):
            policy = policy(env)
        if policy is not None:
            policy.reset()
        return cls(env, policy, obs, info)


@contextmanager
def reused_flights() -> Iterator[None]:
    """Inside it, :func:`operating_point` flown with a policy factory that has a ``reuse_key`` (one that
    flies every design the same way, :func:`.target.privileged_flyer`) continues the flight it flew for an
    earlier operating point of the same env and options when the new time is not earlier, instead of
    flying again from lift-off: the same steps, so the same state to the bit, and a design's operating
    points cost one flight per flight model. Nested uses share the outer one's flights."""
    global _FLIGHTS
    outer = _FLIGHTS
    _FLIGHTS = {} if outer is None else outer
    try:
        yield
    finally:
        if outer is None:
            _FLIGHTS = None


def operating_point(vehicle: Any = "smile", t: float = 28.8, model: str = "rigid", protocol: str = "v0",
                    policy: Any = None, **options: Any) -> OperatingPoint:
    """The state of ``vehicle``'s env of ``protocol`` (``v0``, ``v1``) flown with the gimbal centred and
    no wind up to time ``t`` [s]. ``vehicle``: a shipped name or the path of a vehicle YAML file, flown in
    :data:`.target.FILE_ENV` of the protocol (:func:`.target.design_env`; a missing or invalid file is a
    one-line ``ConfigError``); ``options``: env keywords. In v0 the simulator flies alone; in v1 the env
    flies its zero action control period by control period, so that its coast control and settling
    thrust hold the stack through the staging coast as they do in the benchmark.

    ``policy``: fly up to ``t`` with this controller instead of the gimbal centred, a callable
    ``env -> policy`` (a benchmark policy factory such as :func:`.pid.smile_scheduled_pid`, or
    :func:`.target.schedule_flyer` of a schedule) or a policy (``reset()``, ``act(observation, info)``);
    the env then flies control period by control period in v0 too. The upper stage of ``smile_v1`` needs
    one: flown with the zero action it tumbles and the episode ends at 60.7 s; so does a vehicle that is
    unstable without control. The linearisation is still taken about the gimbal centred at the state
    reached. A factory's ``env_options`` (a mapping, e.g. :func:`.target.privileged_flyer`'s) are added to the
    env's keywords; inside :func:`reused_flights` a factory's flight may be continued."""
    env_id, file_opts = design_env(vehicle, protocol)
    opts = {"model": model, "wind": "none", **file_opts, **getattr(policy, "env_options", {}), **options}
    if env_id == ENV_IDS["v0"]["stratos3"]:
        opts.setdefault("control", "tvc")
    key = (env_id, repr(sorted(opts.items())), policy.reuse_key) \
        if _FLIGHTS is not None and getattr(policy, "reuse_key", None) else None
    flight = _FLIGHTS.get(key) if key is not None else None
    if flight is None or float(flight.env.unwrapped.state.sim.t[0]) > float(t) + 1e-9:
        flight = _Flight.start(env_id, opts, policy)
        if key is not None:
            _FLIGHTS[key] = flight
    env, task, policy = flight.env, flight.env.unwrapped, flight.policy
    sim = task.sim
    if protocol == "v0" and policy is None:
        if t > 0:
            sim.step(task.state.sim, np.zeros((1, 2)), float(t))
    else:
        zero = np.zeros(env.action_space.shape, env.action_space.dtype)
        dt = float(task.task.control_dt_s)
        while float(task.state.sim.t[0]) < float(t) - 0.5 * dt:
            action = zero if policy is None else policy.act(flight.obs, flight.info)
            flight.obs, _, term, trunc, flight.info = env.step(action)
            if (term or trunc) and key is not None:
                del _FLIGHTS[key]                  # an ended flight is not continued; the mission's end may
                #                                    be a row's time (a truncation there reached it)
            if term or (trunc and float(task.state.sim.t[0]) < float(t) - 0.5 * dt):
                how = "with the gimbal centred" if policy is None else f"with {getattr(policy, 'name', 'the policy')}"
                raise RuntimeError(f"{env_id} ({model}, vehicle {vehicle}) flown {how} ended at "
                                   f"{flight.info['time']:.2f} s before t = {t} s: {flight.info.get('termination', '')}")
    d = task.state.sim
    return OperatingPoint(float(d.t[0]), d.x[0].copy(), d.p[0].copy(), d.ctx[0].copy(), sim, opts, task.task,
                          simdata.take(d, [0]))


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


@lru_cache(maxsize=None)
def local_layout(n_modes: int, n_active: int) -> Packed:
    """The local coordinates of :func:`linearize` for ``n_modes`` modes per plane and ``n_active``
    pendulums with propellant (sizes in the field list)."""
    K, na = n_modes, n_active
    return Packed(f"local coordinates K={K} N={na}", [
        Field("v", 3, "m/s", "body-frame components (at the operating attitude) of the CG's inertial velocity"),
        Field("theta", 3, "rad", "small rotation of the body about its own axes"),
        Field("omega", 3, "rad/s", "body rates"),
        Field("eta", 2 * K, "-", "modal coordinates, y plane then z plane"),
        Field("eta_dot", 2 * K, "1/s", "modal rates"),
        Field("beta", 2 * na, "rad", "per active pendulum its rotation about its y_s and z_s axes"),
        Field("omega_s", 2 * na, "rad/s", "per active pendulum its rates"),
    ], pad=False)


class _Coords:
    """Local coordinates around an operating point (:func:`local_layout`) and the derivative in them."""

    def __init__(self, op: OperatingPoint) -> None:
        self.op = op
        self.dyn = op.sim.dynamics
        lay = self.layout = self.dyn.layout
        self.K, N = self.dyn.n_modes, self.dyn.n_slosh
        self.active = [j for j in range(N) if op.p[lay.slosh_param(j, "m")][0] > 0.0]
        self.C0 = _dcm(op.x[lay.state["q_bi"]])
        self.local = local_layout(self.K, len(self.active))
        names = [f"{f}_{a}" for f in ("v", "theta", "omega") for a in "xyz"]
        names += [f"eta_{pl}{k}" for pl in "yz" for k in range(self.K)]
        names += [f"eta_dot_{pl}{k}" for pl in "yz" for k in range(self.K)]
        names += [f"beta_{j}_{a}" for j in self.active for a in "yz"]
        names += [f"omega_s_{j}_{a}" for j in self.active for a in "yz"]
        self.names = names

    def state(self, d: np.ndarray) -> np.ndarray:
        """The full state at local coordinates ``d``."""
        lay, loc = self.layout, self.local
        x = self.op.x.copy()
        x[lay.state["v_zw_i"]] += self.C0 @ loc.view(d, "v")
        s = lay.state["q_bi"]
        x[s] = _rot(x[s], loc.view(d, "theta"))
        x[lay.state["omega_bi_b"]] += loc.view(d, "omega")
        x[lay.state["eta"]] += loc.view(d, "eta")
        x[lay.state["eta_dot"]] += loc.view(d, "eta_dot")
        q_si = lay.view(x, "state", "q_si")
        w_si = lay.view(x, "state", "omega_si_s")
        beta, omega_s = loc.view(d, "beta"), loc.view(d, "omega_s")
        for i, j in enumerate(self.active):
            q_si[j] = _rot(q_si[j], [0.0, beta[2 * i], beta[2 * i + 1]])
            w_si[j] += omega_s[2 * i:2 * i + 2]
        return x

    def rates(self, d: np.ndarray, u_in: np.ndarray | None = None) -> np.ndarray:
        """Time derivative of the local coordinates ``d`` (the kinematic rows ``theta`` and ``beta``
        left zero: :meth:`jacobian` adds them exactly) with the input ``u_in`` (:data:`INPUTS`) added
        to the operating point's."""
        lay, loc = self.layout, self.local
        x = self.state(d)
        c = self.op.c.copy()
        if u_in is not None:
            c[CONTEXT.slice("gimbal")] += u_in[0:2]          # the context's own entries lead a longer vector
            c[CONTEXT.offset("moment_b")] += u_in[2]                # about x_b
        c[CONTEXT.index("time0")] = self.op.t
        u = np.zeros(lay.n_u)
        flight_loads(0.0, x, self.op.p.copy(), c, u)
        f = self.dyn.derivative(x, self.op.p, u)
        out = loc.zeros()
        loc.view(out, "v")[:] = self.C0.T @ f[lay.state["v_zw_i"]]
        loc.view(out, "omega")[:] = f[lay.state["omega_bi_b"]]
        loc.view(out, "eta")[:] = f[lay.state["eta"]]
        loc.view(out, "eta_dot")[:] = f[lay.state["eta_dot"]]
        w_s = lay.view(f, "state", "omega_si_s")
        if self.active:
            loc.view(out, "omega_s")[:] = np.concatenate([w_s[j] for j in self.active])
        return out

    def jacobian(self, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
        """``A`` (n, n) and ``B`` (n, 3) in the local coordinates (inputs :data:`INPUTS`: pitch and yaw
        gimbal [rad], roll moment [N m]), by central differences."""
        loc = self.local
        n = loc.size
        A, B = np.zeros((n, n)), np.zeros((n, len(INPUTS)))
        v = loc.slice("v")
        for i in range(n):
            e = np.zeros(n)
            step = h * (1e3 if v.start <= i < v.stop else 1.0)            # velocities in m/s
            e[i] = step
            A[:, i] = (self.rates(e) - self.rates(-e)) / (2 * step)
        zero = np.zeros(n)
        for k, step in enumerate((h, h, 1e3 * h)):                       # the moment in N m
            du = np.zeros(len(INPUTS))
            du[k] = step
            B[:, k] = (self.rates(zero, du) - self.rates(zero, -du)) / (2 * step)
        A[loc.slice("theta"), loc.slice("omega")] += np.eye(3)              # theta_dot = omega
        A[loc.slice("beta"), loc.slice("omega_s")] += np.eye(loc.field("beta").size)   # beta_dot = omega_s
        return A, B


def plane_states(names: list[str], plane: str) -> list[int]:
    """Indices of the local coordinates ``names`` that :func:`linearize` keeps in ``plane``."""
    if plane not in PLANES:
        raise ValueError(f"plane = {plane!r}: one of {sorted(PLANES)}")
    v, theta, omega, modes, pend, _, _ = PLANES[plane]
    keep = []
    for i, nm in enumerate(names):
        if nm in (v, theta, omega) or (modes and nm.startswith((f"eta_{modes}", f"eta_dot_{modes}"))) or (
                pend and nm.startswith(("beta_", "omega_s_")) and nm.endswith(f"_{pend}")):
            keep.append(i)
    return keep


def linearize(vehicle: Any = "smile", t: float = 28.8, model: str = "rigid", op: OperatingPoint | None = None,
              full: bool = False, plane: str = "pitch", **options: Any) -> control.StateSpace:
    """State space from the gimbal angle in force [rad] (roll: the roll moment [N m]) to the body rate
    [rad/s] of ``plane`` (``pitch``, ``yaw``, ``roll``) at flight time ``t``: the rigid body, and in the
    non-rigid model the modes of that plane's deflection and the pendulums' swing in it. ``full=True``
    keeps every local coordinate (both planes and roll) with all three inputs and all three rates.
    Pitch: the z-plane modes (deflection along z_b) and the pendulums' rotations about their y_s axes;
    yaw: the y-plane modes and the rotations about z_s. The state names are those of
    :func:`local_layout`'s entries, one per coordinate."""
    op = op if op is not None else operating_point(vehicle, t, model, **options)
    co = _Coords(op)
    A, B = co.jacobian()
    names = co.names
    if full:
        C = np.zeros((3, len(names)))
        for r, a in enumerate("xyz"):
            C[r, names.index(f"omega_{a}")] = 1.0
        return control.ss(A, B, C, 0.0, inputs=list(INPUTS), outputs=["omega_x", "omega_y", "omega_z"], states=names)
    keep = plane_states(names, plane)
    *_, inp, out = PLANES[plane]
    C = np.zeros((1, len(keep)))
    C[0, keep.index(names.index(out))] = 1.0
    return control.ss(A[np.ix_(keep, keep)], B[keep][:, [INPUTS.index(inp)]], C, 0.0, inputs=[inp], outputs=[out],
                      states=[names[i] for i in keep])


def aero_slopes(op: OperatingPoint, dw: float = 0.1) -> tuple[float, float, float]:
    """Normal-force slope ``N_alpha`` [N/rad], pitch-moment slope about the CG ``M_alpha`` [N m/rad] and
    airspeed [m/s] at the operating point, from the aerodynamic model (lateral velocity +- dw)."""
    co = _Coords(op)
    out = []
    for s in (dw, -dw):
        d = co.local.zeros()
        co.local.view(d, "v")[2] = s
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


def rigid_terms(op: OperatingPoint) -> dict[str, float]:
    """The rigid body's terms at the operating point: ``mass`` [kg], pitch ``inertia`` about the CG [kg m^2],
    ``thrust`` [N], its ``vectored_share`` [-] and ``vectored_thrust`` [N], and the gimbal-to-CG ``arm`` [m]."""
    tl = op.sim.timeline
    cg = float(tl.interp("cg", [op.t])[0][0]) if np.ndim(tl.cg) == 2 else float(tl.interp("cg", [op.t])[0])
    thrust, share = float(op.condition("thrust")), float(tl.interp("vectored_share", [op.t])[0])
    return {"mass": float(tl.interp("mass", [op.t])[0]), "inertia": float(tl.interp("inertia", [op.t])[0][1, 1]),
            "thrust": thrust, "vectored_share": share, "vectored_thrust": share * thrust,
            "arm": cg - float(op.p[op.sim.layout.params["r_gimbal"]][0])}


def analytic_rigid(op: OperatingPoint) -> control.StateSpace:
    """Textbook rigid pitch-plane model, states ``(w, theta, q)``::

        m w_dot = s T delta - T theta + D theta - N_a alpha      alpha = theta + w / V
        J q_dot = s T l delta + M_a alpha                         theta_dot = q

    with mass ``m``, pitch inertia ``J`` about the CG, thrust ``T`` and the share ``s`` of it the gimbal
    turns (the vehicle's ``vectored_share``, 1 for the shipped vehicles), arm ``l`` from the gimbal to the
    CG, axial drag ``D``, normal-force and moment slopes ``N_a``, ``M_a`` from the aerodynamic model."""
    terms = rigid_terms(op)
    m, J, T, s, l = terms["mass"], terms["inertia"], terms["thrust"], terms["vectored_share"], terms["arm"]
    n_a, m_a, V, D = aero_slopes(op)
    A = np.array([[-n_a / (m * V), (-T + D - n_a) / m, 0.0], [0.0, 0.0, 1.0], [m_a / (J * V), m_a / J, 0.0]])
    B = np.array([[s * T / m], [0.0], [s * T * l / J]])
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


def margin_grid(dt: float, n: int = 20000) -> np.ndarray:
    """The frequencies [rad/s] on which :func:`margins` reads a discrete loop: ``n`` log-spaced points
    from 1e-3 rad/s to just below the Nyquist frequency ``pi / dt`` (a step of 0.06 %, about a
    twentieth of the half-power band of a mode damped at 1 %)."""
    return np.geomspace(1e-3, 0.9999 * math.pi / dt, n)


def crossings(L: control.StateSpace) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(gm, pm, wpc, wgc)`` of the discrete open loop ``L``, as python-control's
    ``stability_margins(..., returnall=True)`` gives them for a frequency response: the gain margins
    ``1/|L|`` [-] at the phase crossovers ``wpc`` [rad/s] (where the phase of ``L`` crosses -180 deg with a
    negative real part) and the phase margins [deg, in [-180, 180)] at the gain crossovers ``wgc``
    [rad/s]. The crossings are bracketed on :func:`margin_grid` and each is solved (Brent's method) on
    ``L`` itself, not on an interpolant of its response."""
    L = L if isinstance(L, control.StateSpace) else control.ss(L)
    w = margin_grid(L.dt)

    def at(wk: float) -> complex:
        return complex(frequency_response(L, np.array([wk]))[0])

    resp = frequency_response(L, w)
    arg = np.angle(-resp)                      # zero where the phase of L crosses -180 deg
    i_pc = np.where(np.diff(np.sign(arg)))[0]
    i_pc = i_pc[resp[i_pc].real <= 0.0]
    wpc = np.array([_root(lambda x: np.angle(-at(x)), w[i], w[i + 1]) for i in i_pc])
    mag = np.abs(resp) - 1.0
    i_gc = np.where(np.diff(np.sign(mag)))[0]
    wgc = np.array([_root(lambda x: abs(at(x)) - 1.0, w[i], w[i + 1]) for i in i_gc])
    with np.errstate(divide="ignore"):
        gm = np.array([1.0 / abs(at(x)) for x in wpc])
    pm = np.array([np.remainder(np.angle(at(x), deg=True), 360.0) - 180.0 for x in wgc])
    return gm, pm, wpc, wgc


def _root(f: Any, a: float, b: float) -> float:
    """The root of ``f`` in the grid's bracket ``[a, b]`` (Brent's method); where ``f`` evaluated point by
    point does not change sign over the bracket (the grid's response and the point's differ in the last
    digits at a crossing that touches a grid point), the end where ``|f|`` is smaller."""
    fa, fb = f(a), f(b)
    if fa * fb > 0.0:
        return a if abs(fa) <= abs(fb) else b
    return optimize.brentq(f, a, b, xtol=1e-12)


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
    if L.dt:                                   # python-control's polynomial method is unreliable for
        gm, pm, wpc, wgc = crossings(L)        # discrete loops of this order: a dense response, refined
    else:
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
