"""The load objective of the flex design: a row's load relief chosen by the design tool itself
(``python -m lvgym.baselines.design.flexdesign --load-objective qalpha|accel``; docs/flex-design.md, "The load
objective").

The plain design (:mod:`.flexproblem`) sees the loop from the gimbal command to the sampled gyro only. Here
the same linearisation (:class:`.linearize._Coords`) and the same flight-loop chain (:mod:`.flightloop`:
servo, zero-order hold at the physics step, hold and sampling at the control period, the computational
delay, the IMU's filters) give a plant with two inputs and three outputs (:func:`load_plant`):

- inputs: the commanded gimbal angle [rad] and a lateral wind [m/s] along the body axis of the plane (``+z_b``
  pitch, ``+y_b`` yaw, at the operating attitude). The wind enters as the negative of the CG's velocity
  in the aerodynamic loads: every dependence of the loads on the CG's velocity is aerodynamic (gravity
  depends on the position, thrust on neither), so its column is minus the velocity's column;
- outputs: the gyro (as :func:`.flightloop.flight_plant`), the aerodynamic angle of the plane (the
  simulator's flight condition ``alpha`` pitch, ``beta`` yaw [rad], by central differences) and the
  accelerometer's lateral specific force [m/s^2] at the IMU (as :func:`lvgym.simulator.imu.imu_end_k`
  forms it: the CG's ``C_bi^T (a - g)``, the lever arm ``omega_dot x r`` and the modal acceleration
  ``sum_k phi_k(x_imu) eta_ddot_k``, through the anti-aliasing filter).

The controller of :mod:`.pid` with ``accel_gain`` ``k_a`` flies ``u = -C(z) (y_gyro - k_a s y_f)`` (``s`` the
plane's sign, :data:`..pid.ACCEL_SIGNS`), so the rate loop broken at the gimbal is the SISO loop of the
effective plant ``G_gyro - k_a s G_f`` (:func:`effective_plant`): its margins are the relieved loop's.

The load measure (:meth:`LoadProblem.evaluate`, ``load``): the RMS, in a lateral Dryden turbulence of
1 m/s RMS (the transverse spectrum of :func:`lvgym.environment.turbulence.dryden_psd`, medium/high altitude
scale ``L = 1750 ft``, at the row's airspeed), of

- ``qalpha``: ``qbar alpha`` [Pa deg per m/s of wind], ``qbar`` the row's dynamic pressure;
- ``accel``: the accelerometer's lateral specific force [m/s^2 per m/s of wind],

on the closed loop of the row's own time and plane pitch, the mean of the rigid and non-rigid loops (as the
disturbance objective ``J``). :class:`LoadProblem` adds ``accel_gain`` to the nine parameters (``ki`` stays
free: the integral is given up as far as the objective asks) and minimises
``log J + weight log load`` under every requirement of :class:`.flexproblem.Requirements` but the drift,
which may be as fast as the vehicle's own and no faster (:data:`.flexproblem.DRIFT_MODES`, as the load-relief
rows of :func:`.flexdesign.relief_row`).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import control
import numpy as np

from lvgym.environment.turbulence import dryden_psd
from lvgym.errors import ConfigError
from lvgym.simulator import CONDITIONS
from lvgym.simulator.flight import flight_conditions_batch

from .flexproblem import Requirements, RowProblem, _controller_poly, controller, design_row
from .flightloop import (control_timing, delay_ss, gyro_filter_ss, hold_and_sample, servo_discrete,
                         vehicle_with_gyro_output)
from .linearize import INPUTS, PLANES, OperatingPoint, _Coords, plane_states
from .response import frequency_response

__all__ = ["ACCEL_GAIN", "OBJECTIVES", "SCALE_M", "LoadProblem", "check_load_options", "effective_plant",
           "load_plant", "load_row", "wind_rms"]

#: the load objectives: ``qalpha`` (the RMS of q alpha) and ``accel`` (of the accelerometer's lateral specific force)
OBJECTIVES = ("qalpha", "accel")
#: the load-relief gain as the optimiser holds it: (name, lower, upper [rad/s per m/s^2], log-scaled)
ACCEL_GAIN = ("accel_gain", 1e-5, 0.1, True)
#: the Dryden scale length of the design turbulence [m] (MIL-F-8785C, medium/high altitude: 1750 ft)
SCALE_M = 1750.0 * 0.3048
#: the axis (body y 1, z 2) of each plane's wind and specific force, the flight condition of its
#: aerodynamic angle and the sign ``s`` of the load-relief term (:data:`..pid.ACCEL_SIGNS`)
_AXES = {"pitch": (2, "alpha", 1.0), "yaw": (1, "beta", -1.0)}


def check_load_options(objective: Any, weight: Any) -> None:
    """Refuse a load objective other than None or one of :data:`OBJECTIVES` and a weight that is not a
    finite number > 0 (:class:`lvgym.errors.ConfigError`, naming the key, the value and what is allowed)."""
    if objective is not None and objective not in OBJECTIVES:
        raise ConfigError("load_objective", objective, f"None or one of {', '.join(repr(o) for o in OBJECTIVES)}")
    if not (isinstance(weight, (int, float)) and not isinstance(weight, bool) and math.isfinite(weight)
            and 0.0 < weight <= 100.0):
        raise ConfigError("load_weight", weight, "a number in (0, 100]")


def _skew(f: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -f[2], f[1]], [f[2], 0.0, -f[0]], [-f[1], f[0], 0.0]])


def _condition_row(co: _Coords, name: str, index: int = 0) -> np.ndarray:
    """d(condition ``name``[index]) / d(local coordinates) (n,) by central differences."""
    op, loc = co.op, co.local
    v = loc.slice("v")
    row = np.zeros(loc.size)
    for i in range(loc.size):
        if not (v.start <= i < v.stop or loc.slice("theta").start <= i < loc.slice("theta").stop):
            continue                                 # the aerodynamic angles depend on velocity and attitude only
        step = 1e-3 if v.start <= i < v.stop else 1e-6
        out = []
        for s in (step, -step):
            d = loc.zeros()
            d[i] = s
            cond = CONDITIONS.zeros(1)
            flight_conditions_batch(np.array([op.t]), co.state(d)[None], op.p[None], op.c[None], cond)
            out.append(np.ravel(CONDITIONS.view(cond[0], name))[index])
        row[i] = (out[0] - out[1]) / (2 * step)
    return row


def load_plant(op: OperatingPoint, plane: str = "pitch") -> control.StateSpace:
    """The discrete plant of the row at the control period: inputs the gimbal command [rad] and the lateral
    wind [m/s]; outputs the sampled gyro [rad/s], the aerodynamic angle of ``plane`` [rad] and the
    accelerometer's filtered lateral specific force [m/s^2] (module docstring). Its gimbal-to-gyro part is
    :func:`.flightloop.flight_plant`'s."""
    if plane not in _AXES:
        raise ValueError(f"plane = {plane!r}: 'pitch' or 'yaw'")
    axis, angle, _ = _AXES[plane]
    gyro = vehicle_with_gyro_output(op, plane)
    co = _Coords(op)
    A, B = co.jacobian()
    names, loc = co.names, co.local
    keep = plane_states(names, plane)
    v_name, _, _, modes, _, inp, _ = PLANES[plane]
    i_v = names.index(v_name)
    # the specific force at the IMU, a row over the rates (M) plus the rotation of the CG's
    # specific force f0 into the turned body, [f0 x] theta
    g_i = op.condition("g_i")
    f0 = loc.view(co.rates(loc.zeros()), "v") - co.C0.T @ np.asarray(g_i, float)
    lay = op.sim.layout
    imu = getattr(op.sim, "imu", None)
    r = -np.asarray(op.p[lay.params["r_cg"]], float)
    tl = op.sim.timeline
    phi = np.zeros(0)
    if imu is not None:
        r[0] += float(imu.station_m)
        i, w = tl.locate([op.t])
        j = int(i[0] + 1 if w[0] >= 1.0 else i[0])
        phi = np.asarray(tl.phi_sensor[j, 0], float)
    M = np.zeros(loc.size)
    M[names.index(f"v_{'xyz'[axis]}")] = 1.0
    M[loc.slice("omega")] = -_skew(r)[axis]                  # omega_dot x r
    for k, p in enumerate(phi):
        name = f"eta_dot_{modes}{k}"
        if name in names:
            M[names.index(name)] += p
    F = M @ A
    F[loc.slice("theta")] += _skew(f0)[axis]
    F_u = float(M @ B[:, INPUTS.index(inp)])
    a_row = _condition_row(co, angle)
    if not np.allclose(np.asarray(gyro.A), A[np.ix_(keep, keep)], rtol=1e-9, atol=1e-12):
        raise RuntimeError("the load plant's linearisation differs from the gyro plant's")
    Bv = np.column_stack([np.asarray(gyro.B)[:, 0], -A[keep, i_v]])
    Cv = np.vstack([np.asarray(gyro.C)[0], a_row[keep], F[keep]])
    Dv = np.array([[0.0, 0.0], [0.0, -a_row[i_v]], [F_u, -F[i_v]]])
    vehicle = control.ss(np.asarray(gyro.A), Bv, Cv, Dv)
    one = control.ss([], [], [], [[1.0]])
    gf = gyro_filter_ss(op)
    if imu is not None:
        a_acc, b_acc, c_acc = imu.continuous()["accel"]
        vehicle = control.series(vehicle, control.append(gf, one, control.ss(a_acc, b_acc, c_acc, 0.0)))
    dt, delay = control_timing(op)
    h = float(op.task.physics_dt_s) if op.task is not None else dt
    n = round(dt / h)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = control.series(control.append(servo_discrete(op, h), control.ss([], [], [], [[1.0]], h)),
                           control.c2d(control.ss(vehicle), h, "zoh"))
        g = hold_and_sample(control.ss(g), n)
        g = control.series(control.append(delay_ss(delay, dt), control.ss([], [], [], [[1.0]], dt)), g)
    return control.ss(g.A, g.B, g.C, g.D, dt, inputs=[f"{inp}_command", f"wind_{'xyz'[axis]}"],
                      outputs=[f"gyro_{plane}", angle, f"accel_{'xyz'[axis]}"])


def _sub(g: control.StateSpace, out: int, inp: int) -> control.StateSpace:
    return control.ss(g.A, np.asarray(g.B)[:, [inp]], np.asarray(g.C)[[out]], np.asarray(g.D)[[out]][:, [inp]], g.dt)


def effective_plant(g: control.StateSpace, accel_gain: float, plane: str = "pitch") -> control.StateSpace:
    """The rate loop's plant with the load-relief term: from the gimbal command to ``y_gyro - k_a s y_f``
    (:func:`load_plant`'s ``g``; ``accel_gain`` ``k_a`` [rad/s per m/s^2]), whose loop ``C(z)`` closes with
    negative feedback as it closes the gyro plant (module docstring)."""
    s = _AXES[plane][2]
    C = np.asarray(g.C)[0] - accel_gain * s * np.asarray(g.C)[2]
    D = np.asarray(g.D)[0, 0] - accel_gain * s * np.asarray(g.D)[2, 0]
    return control.ss(g.A, np.asarray(g.B)[:, [0]], C[None], [[D]], g.dt)


def wind_rms(resp: np.ndarray, w: np.ndarray, airspeed: float, length: float = SCALE_M, sigma: float = 1.0,
             component: str = "w") -> float:
    """The RMS of an output whose response to the wind [output per m/s] is ``resp`` at the frequencies ``w``
    [rad/s] (increasing), in Dryden turbulence of RMS ``sigma`` [m/s] and scale ``length`` [m] (component
    ``u``: first order; ``v``, ``w``: transverse) flown through at ``airspeed`` [m/s]: the square root of
    ``integral |resp|^2 Phi(w) dw``, ``Phi(w) = dryden_psd(w / V) / V`` (trapezoidal on the grid)."""
    V = max(float(airspeed), 1.0)
    psd = dryden_psd(np.asarray(w, float) / V, sigma, length, component) / V
    return float(math.sqrt(max(np.trapezoid(np.abs(resp) ** 2 * psd, w), 0.0)))


class LoadProblem(RowProblem):
    """:class:`.flexproblem.RowProblem` of the relieved loop: the cases' plants are :func:`load_plant`s
    (``cases``: (plants by model, modes, dynamic pressure [Pa], airspeed [m/s], plane), the first the
    row's own pitch loop), the parameters :data:`.flexproblem.PARAMETERS` and :data:`ACCEL_GAIN`;
    the margins, modes and drift are those of the effective plant (:func:`effective_plant`), ``J`` the
    rate's disturbance response, ``load`` the load measure of ``objective`` (module docstring) and the
    cost ``10 sum(penalty^2) + log J + weight log load``."""

    def __init__(self, cases: list[tuple[dict[str, control.StateSpace], dict, float, float, str]], req: Requirements,
                 objective: str = "qalpha", weight: float = 10.0, noise: tuple[float, float] = (0.0, 1.0),
                 drift: str = "vehicle", **kw: Any) -> None:
        check_load_options(objective, weight)
        gyro = [({m: _sub(g, 0, 0) for m, g in plants.items()}, modes) for plants, modes, *_ in cases]
        super().__init__(gyro, req, drift=drift, noise=noise, **kw)
        self.params = self.params + (ACCEL_GAIN,)
        self.objective, self.weight = objective, float(weight)
        self.extra = []
        for plants, _, qbar, airspeed, plane in cases:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                resp = {m: [[frequency_response(_sub(g, o, i), self.w) for i in (0, 1)] for o in range(3)]
                        for m, g in plants.items()}
            mats = {m: (np.asarray(g.C)[0], np.asarray(g.C)[2]) for m, g in plants.items()}
            self.extra.append((resp, mats, float(qbar), float(airspeed), _AXES[plane][2]))
        self._gyro_cases = self.cases

    def evaluate(self, values: dict[str, float]) -> dict[str, Any]:
        k = float(values.get("accel_gain", 0.0))
        cases = []
        for (G, band, mats), (resp, cm, *_, s) in zip(self._gyro_cases, self.extra):
            cases.append(({m: resp[m][0][0] - k * s * resp[m][2][0] for m in G}, band,
                          {m: (A, B, (cm[m][0] - k * s * cm[m][1])[None]) for m, (A, B, _c) in mats.items()}))
        self.cases = cases
        try:
            out = super().evaluate(values)
        finally:
            self.cases = self._gyro_cases
        gains, filt = controller(values, self.notch_radps)
        b, a = _controller_poly(gains, filt, self.dt)
        C = np.polyval(b, self.z) / np.polyval(a, self.z)
        resp, _, qbar, airspeed, s = self.extra[0]
        J, load = 0.0, 0.0
        for r in resp.values():
            geff_u, geff_w = r[0][0] - k * s * r[2][0], r[0][1] - k * s * r[2][1]
            S = 1.0 / (1.0 + C * geff_u)
            J += float(np.sum(np.abs(r[0][0] * S) ** 2 * self.dw)) / len(resp)
            o = 1 if self.objective == "qalpha" else 2
            t = r[o][1] - r[o][0] * C * geff_w * S       # the output's response to the wind, loop closed
            scale = qbar * 180.0 / math.pi if self.objective == "qalpha" else 1.0
            load += scale * wind_rms(t, self.w, airspeed) / len(resp)
        out["J"], out["load"] = J, load
        return out

    def cost_of(self, e: dict[str, Any]) -> float:
        """The row's cost plus ``weight`` times the log of the load measure."""
        return super().cost_of(e) + self.weight * math.log(max(e["load"], 1e-300))


#: the load-relief gains [rad/s per m/s^2] the design starts from, besides the plain design's none
STARTS = (1e-4, 1e-3, 1e-2)


def load_row(cases: list, req: Requirements, plain: dict[str, Any], objective: str, weight: float = 10.0,
             also: list[dict[str, float]] = (), noise: tuple[float, float] = (0.0, 1.0),
             maxiter: int = 3000) -> dict[str, Any]:
    """The load-objective design of a row whose plain design is ``plain`` (:func:`.flexproblem.design_row`'s
    result on the same plants' gyro loops): :class:`LoadProblem` minimised by Nelder-Mead from the plain
    design with each load-relief gain of :data:`STARTS` and from each parameter set of ``also``. The result
    (:func:`.flexproblem.design_row`'s) adds ``load_plain`` and ``J_plain``: the plain design's load measure
    and ``J`` on this problem (no load relief)."""
    problem = LoadProblem(cases, req, objective, weight, noise)
    warms = [dict(plain["values"], accel_gain=g) for g in STARTS] + [dict(w) for w in also]
    e = design_row(problem, warms, np.random.default_rng(0), starts=0, maxiter=maxiter)
    base = problem.evaluate(dict(plain["values"], accel_gain=0.0))
    e["load_plain"], e["J_plain"] = base["load"], base["J"]
    return e
