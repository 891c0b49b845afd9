"""The linear design of ``eso`` (active disturbance rejection control, :mod:`..eso`): the discrete extended-state
observer, the law, the compensator they make from the flight computer's samples to the gimbal command, and its
margins and noise on the linear flight loop of :mod:`.flightloop`.

Per plane the observer's model is the rigid attitude with everything it does not know lumped into one
disturbance angular acceleration ``f`` [rad/s^2] (J. Han, "From PID to active disturbance rejection control",
IEEE Trans. Industrial Electronics 56(3), 2009): ``theta_dot = omega``, ``omega_dot = f + b0 delta``,
``f_dot = 0`` with ``b0`` [1/s^2] the control power (vectored thrust times the gimbal-to-CG arm over the pitch
inertia, from the vehicle's design tables over the flight) and ``delta`` [rad] the gimbal angle the servo holds
(the observation's actuator position: the servo's lag, its rate limit and the computational delay are then
outside the observer's model). Discretised exactly at the control period ``dt`` with the gimbal taken as the
mean of its samples at both ends of the period::

    x_bar = Phi x_hat[k-1] + Gam b0 (delta[k-1] + delta[k]) / 2      Phi = [[1, dt, dt^2/2], [0, 1, dt], [0, 0, 1]]
    x_hat = x_bar + L (theta_m[k] - x_bar[0])                         Gam = [dt^2/2, dt, 0]

with ``theta_m`` the attitude error through the structural filter. ``L`` places the three eigenvalues of the
estimation error's map ``(I - L C) Phi`` at ``z = exp(-w_o dt)``: Gao's bandwidth parameterisation, one observer
bandwidth ``w_o`` [rad/s] (Z. Gao, "Scaling and bandwidth-parameterization based controller tuning", Proc.
American Control Conference, 2003), the discrete image of ``(s + w_o)^3``. The law is a PD on the estimates
with the disturbance estimate cancelled, ``u = -(kp theta_hat + kd omega_hat + f_hat) / b0`` with
``kp = w_c^2`` and ``kd = 2 w_c`` (the controller bandwidth ``w_c``: a double pole at ``-w_c`` on the plant the
observer assumes).

:func:`compensator` is that law, from the gyro sample and the gimbal sample to the command, with the flight
computer's strapdown attitude modelled as the trapezoidal integral of the gyro samples (as
:mod:`lvgym.envs.flightcomputer` propagates it); :func:`sampled_plant` is :func:`.flightloop.flight_plant` with the
gimbal position as a second output; :func:`assess` the margins of the loop broken at the command (the rules of
:class:`.lqg_design.MarginTargets`), the loop's gain at the modes and the gimbal rate the gyro's noise commands
(:mod:`.noise`).
"""

from __future__ import annotations

import math
from typing import Any

import control
import numpy as np

from lvgym.errors import ConfigError

from ..eso import eso_model, notch_section, observer_gain, observer_matrices

from .flightloop import control_timing, delay_ss, gyro_chain, hold_and_sample, servo_discrete
from .linearize import PLANES, OperatingPoint
from .lqg_row import closed_loop_growth, frequency_grid, gain_at, margins_from_response, response

__all__ = ["RowFilter", "assess", "compensator", "eso_model", "law_gains", "observer_gain", "row_design", "sampled_plant"]


def _positive(key: str, value: float) -> float:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
        raise ConfigError(key, value, "a finite number > 0")
    return float(value)


def law_gains(wc: float) -> tuple[float, float]:
    """``(kp, kd)`` [1/s^2, 1/s] of the controller bandwidth ``wc`` [rad/s]: ``s^2 + kd s + kp = (s + wc)^2``."""
    wc = _positive("controller_bandwidth_radps", wc)
    return wc * wc, 2.0 * wc


def core(b0: float, wc: float, wo: float, dt: float, *, observer: str = "attitude", zeta: float = 1.0,
         stiffness: float = 0.0, damping: float = 0.0) -> control.StateSpace:
    """The observer (:func:`..eso.observer_matrices` of ``observer``, the model's known ``stiffness`` [1/s^2] and
    ``damping`` [1/s]) and the law (``kp = wc^2 - stiffness``, ``kd = 2 zeta wc - damping``) as a discrete system
    from ``(theta_k, omega_k, delta_k)`` [rad, rad/s, rad] to the command [rad] (states: the last estimate and
    the last gimbal sample)."""
    b0 = _positive("control_power_per_s2", b0)
    F, H, G = observer_matrices(observer, _positive("observer_bandwidth_radps", wo), dt, stiffness, damping)
    wc = _positive("controller_bandwidth_radps", wc)
    k = np.array([[wc * wc - stiffness, 2.0 * _positive("controller_damping", zeta) * wc - damping, 1.0]]) / b0
    g2 = (G * 0.5 * b0).reshape(3, 1)
    A = np.block([[F, g2], [np.zeros((1, 4))]])
    B = np.block([[H, g2], [np.array([[0.0, 0.0, 1.0]])]])
    C = -k @ np.hstack([F, g2])
    D = -k @ np.hstack([H, g2])
    return control.ss(A, B, C, D, dt)


def input_model(dt: float, delay_steps: int, servo: tuple[float, float] | None) -> control.StateSpace:
    """The gimbal angle the observer assumes from its own commands: ``delay_steps`` control periods of delay,
    then (``servo``: natural frequency [rad/s], damping [-]) the servo's second order, zero-order held at
    ``dt`` [s]; strictly proper (at least one period of delay)."""
    if int(delay_steps) < 1:
        raise ConfigError("delay_steps", delay_steps, "at least one control period (the command acts after the sample)")
    m = delay_ss(int(delay_steps), dt)
    if servo is not None:
        w, z = servo
        s = control.c2d(control.ss(control.tf([w * w], [1.0, 2.0 * z * w, w * w])), dt, "zoh")
        m = control.series(m, s)
    return control.ss(m)


def close_input(c: control.StateSpace, m: control.StateSpace) -> control.StateSpace:
    """:func:`core` ``c`` with its gimbal input fed from its own command through ``m`` (:func:`input_model`):
    a system from ``theta_m`` alone to the command."""
    A, B, C, D = (np.asarray(x, float) for x in (c.A, c.B, c.C, c.D))
    Am, Bm, Cm = (np.asarray(x, float) for x in (m.A, m.B, m.C))
    b1, b2, d1, d2 = B[:, :-1], B[:, -1:], D[:, :-1], D[:, -1:]
    Ac = np.block([[A, b2 @ Cm], [Bm @ C, Am + Bm @ d2 @ Cm]])
    Bc = np.vstack([b1, Bm @ d1])
    Cc = np.hstack([C, d2 @ Cm])
    return control.ss(Ac, Bc, Cc, d1, c.dt)


def compensator(b0: float, wc: float, wo: float, dt: float, filt: Any = None,
                model: control.StateSpace | None = None, **row: Any) -> control.StateSpace:
    """The whole law, unclipped: the structural filter ``filt`` (a :class:`..filters.StructuralFilter` or series;
    None: none) on the gyro sample, the strapdown attitude (trapezoidal integral of the gyro samples), then
    :func:`core` (``row``: its keywords) on (attitude, rate). ``model`` None: the gimbal sample is the law's second
    input (from ``(gyro sample [rad/s], gimbal sample [rad])`` to the command [rad]); else the gimbal angle is the
    law's own command through ``model`` (:func:`input_model`; from the gyro sample alone)."""
    integ = control.ss(control.tf([0.5 * dt, 0.5 * dt], [1.0, -1.0], dt))
    one = control.ss([], [], [], [[1.0]], dt)
    split = control.ss(np.asarray(integ.A), np.asarray(integ.B), np.vstack([np.asarray(integ.C), np.zeros((1, 1))]),
                       np.vstack([np.asarray(integ.D), [[1.0]]]), dt)               # g -> (theta, g)
    path = split if filt is None else control.series(control.ss(filt.tf(dt)), split)
    c = core(b0, wc, wo, dt, **row)
    if model is not None:
        return control.ss(control.series(path, close_input(c, model)))
    pre = control.append(path, one)
    return control.ss(control.series(pre, c))


class RowFilter:
    """A schedule row's slosh notch (:func:`..eso.notch_section`) with the :meth:`tf` :func:`compensator` takes."""

    def __init__(self, notch: Any, dt: float) -> None:
        self.b, self.a = notch_section(notch, dt)
        self.dt = dt

    def tf(self, dt: float) -> control.TransferFunction:
        if dt != self.dt:
            raise ConfigError("dt", dt, f"the period the notch was made at, {self.dt} s")
        return control.tf(self.b, self.a, dt)


def row_design(row: dict[str, Any]) -> dict[str, Any]:
    """A schedule row as :func:`compensator`'s keywords (``observer``, ``zeta``, ``stiffness``, ``damping``)."""
    return {"observer": str(row.get("observer", "attitude")), "zeta": float(row.get("controller_damping", 1.0)),
            "stiffness": float(row.get("stiffness_per_s2", 0.0)), "damping": float(row.get("damping_per_s", 0.0))}


def sampled_plant(op: OperatingPoint, plane: str = "pitch") -> control.StateSpace:
    """:func:`.flightloop.flight_plant` (command [rad] to the gyro sample [rad/s], the delay included) with a
    second output, the gimbal position the servo holds at the sample [rad] (the observation's actuator
    position times the gimbal limit)."""
    dt, steps = control_timing(op)
    h = float(op.task.physics_dt_s)
    n = int(round(dt / h))
    s = servo_discrete(op, h)
    g = control.c2d(gyro_chain(op, plane), h, "zoh")
    As, Bs, Cs, Ds = (np.asarray(m, float) for m in (s.A, s.B, s.C, s.D))
    Ag, Bg, Cg = (np.asarray(m, float) for m in (g.A, g.B, g.C))
    ns, ng = As.shape[0], Ag.shape[0]
    A = np.block([[As, np.zeros((ns, ng))], [Bg @ Cs, Ag]])
    B = np.vstack([Bs, Bg @ Ds])
    C = np.block([[np.zeros((1, ns)), Cg], [np.array([[1.0] + [0.0] * (ns - 1)]), np.zeros((1, ng))]])
    sys = hold_and_sample(control.ss(A, B, C, np.zeros((2, 1)), h), n)
    d = control.series(delay_ss(steps, dt), sys)
    inp = PLANES[plane][5]
    return control.ss(d.A, d.B, d.C, d.D, dt, inputs=[f"{inp}_command"], outputs=[f"gyro_{plane}", f"{inp}_position"])


def open_loop(comp: control.StateSpace, plant: control.StateSpace) -> control.StateSpace:
    """``L = -K(z) G(z)``: the loop broken at the command (negative feedback), ``G`` of :func:`sampled_plant`
    (its gyro output alone for a compensator of one input)."""
    if comp.ninputs == 1:
        plant = control.ss(plant.A, plant.B, plant.C[:1], plant.D[:1], plant.dt)
    return control.ss(control.series(plant, -comp))


def noise_rate(comp: control.StateSpace, plant: control.StateSpace, sigma: float, rate_limit: float,
               w: np.ndarray) -> float:
    """The RMS of the commanded gimbal rate [-, of ``rate_limit``] that white gyro noise of ``sigma`` [rad/s]
    per sample drives through the closed loop: ``K_y / (1 + L)`` (:mod:`.noise`'s measure; ``w`` [rad/s]
    ascending to Nyquist)."""
    dt = float(comp.dt)
    ky = response(control.ss(comp.A, comp.B[:, :1], comp.C, comp.D[:, :1], dt), w)
    lr = response(open_loop(comp, plant), w)
    theta = w * dt
    t2 = np.abs(ky / (1.0 + lr)) ** 2 * 4.0 * np.sin(0.5 * theta) ** 2
    return sigma * math.sqrt(float(np.trapezoid(t2, theta)) / math.pi) / dt / rate_limit


def assess(comp: control.StateSpace, plants: dict[str, control.StateSpace], modes: dict[str, list[float]],
           sigma: float, rate_limit: float, w: np.ndarray | None = None) -> dict[str, Any]:
    """Margins of ``comp`` on each of ``plants`` (:func:`sampled_plant`s by name, ``rigid`` and ``nonrigid``
    among them; conventions of :func:`.lqg_row.loop_margins`), the non-rigid loop's gain [dB] at the slosh and
    bending frequencies [rad/s] of ``modes`` (:func:`.flightloop.mode_frequencies`; ``slosh_db``,
    ``bending_db``) and the commanded gimbal rate of white gyro noise of ``sigma`` [rad/s] per sample on the
    non-rigid loop (``noise_rate``, a share of the servo's ``rate_limit`` [rad/s]; :func:`.noise.gyro_noise`)."""
    w = frequency_grid(float(comp.dt), 5000) if w is None else w
    out: dict[str, Any] = {}
    for name, g in plants.items():
        L = open_loop(comp, g)
        growth = closed_loop_growth(L)
        out[name] = {**margins_from_response(response(L, w), w), "closed_loop_stable": growth < 1e-4,
                     "max_pole_real_per_s": growth}
    L = open_loop(comp, plants["nonrigid"])
    out["slosh_db"] = gain_at(L, modes["slosh"])
    out["bending_db"] = gain_at(L, modes["bending"])
    out["noise_rate"] = noise_rate(comp, plants["nonrigid"], sigma, rate_limit, w)
    return out


def schedule_document(rows: list[dict[str, float]], power_source: str = "smile_pd_relief") -> dict[str, Any]:
    """The ``eso`` schedule: the design ``rows`` (``time_s``, ``controller_bandwidth_radps``,
    ``observer_bandwidth_radps``, and the row's margins as measured) and the control power over the flight, taken
    from the ``gs-pd-relief`` schedule of the same vehicle (``control_power_per_s2`` of its rows: the rigid terms
    at every second of burning flight, flown with the privileged reference, :mod:`.pdrelief`)."""
    import yaml

    from ..pid import SCHEDULES

    src = yaml.safe_load((SCHEDULES / f"{power_source}.yaml").read_text())
    power = {"time_s": [float(r["time_s"]) for r in src["rows"]],
             "per_s2": [float(r["control_power_per_s2"]) for r in src["rows"]], "source": f"{power_source}.yaml"}
    return {"law": ("u = -((wc^2 - m) theta_hat + (2 zeta wc - c) omega_hat + f_hat) / b0; observer 'attitude': "
                    "full order on the attitude, triple pole exp(-wo dt); 'rate': reduced order on the gyro rate, "
                    "double pole; notch on attitude and rate"),
            "rows": rows, "control_power": power}
