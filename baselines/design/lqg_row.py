"""One row of the LQG schedule: the plant, the regulator, the Kalman filter, the compensator and its margins.

:mod:`.lqg_design` searches the weights of every row and writes the schedule; :mod:`.lqg` flies it.

The plant of a row (:func:`delayed_plant`) is :func:`.flightloop.flight_plant` with the computational
delay written as its own states, so that a disturbance can enter after it: gimbal command ``u_k`` [rad]
to the sampled gyro ``y_k`` [rad/s], ``x_{k+1} = A x_k + B u_k``, ``y_k = C x_k`` (the servo, the
vehicle with its slosh pendulums and bending modes, the bending slope at the IMU, the gyro filters, the
hold and the one-period delay of protocol v1: everything a control period of the env does).

Regulator (:func:`regulator`). The plant is augmented with the integral of the rate error
``xi_{k+1} = a xi_k - dt y_k`` (``e = -y``: the observation holds ``rate - reference``; ``dt`` the
control period [s]) and ``control.dlqr`` minimises
``sum q_rate y_k^2 + q_int xi_k^2 + q_modes |mode rates|^2 + r_gimbal u_k^2``. The rate over the
gimbal angle has a zero at ``z = 1`` (a held gimbal angle leaves a constant attitude, not a constant
rate), which an exact integrator (``a = 1``) would cancel into an uncontrollable mode on the unit circle, where the Riccati
equation has no stabilising solution; the design therefore uses a leaky integrator
``a = exp(-dt / integrator_leak_s)``, and the compensator flies it too (design and flight are one
system; the leak's time constant is far beyond the flight's dynamics, so it rejects a constant
disturbance as an integrator would over the flight).

The integral of the attitude error (``integral="attitude"``, the ``lqi`` design, docs/lqi.md) takes the
place of the rate's: ``xi_{k+1} = xi_k - dt e_k`` with ``e = C_e x`` the attitude error (the vehicle's
``theta_y`` or ``theta_z``: :func:`attitude_output`; in flight the observation's strapdown attitude error),
without a leak. The attitude over the gimbal has no zero at ``z = 1`` (a held gimbal angle against the
aerodynamic moment holds an attitude), so the pure integrator is controllable and ``dlqr`` has its
stabilising solution; ``q_attitude`` weights ``e^2`` beside it (the place ``q_int`` takes in the rate design,
whose integral of the rate is the attitude change), and ``q_int`` now weights the attitude's integral
[1/(rad s)^2]. A constant disturbance moment then leaves no attitude offset: at rest ``xi`` is constant only
where ``e = 0``. The compensator has two inputs, the gyro sample and the attitude error (:func:`compensator`):
the attitude error also stands for the estimate's attitude state (the rate-only filter's attitude drifts with
any moment it does not model, and the regulator's attitude gain would fly that drift); its loop is assessed on
the plant with both outputs (:func:`loop_plant`).

Estimator (:func:`kalman_gain`): the steady-state Kalman filter of the plant with process noise at the
gimbal, after the delay (variance ``w_gimbal`` [rad^2] per control period: what stands in for the wind,
the misalignment and the model's errors) and on the rates of the slosh pendulums and bending modes
(``w_modes``: their frequencies drift through a row's interval and are dispersed in the benchmark), and
measurement noise the v1 gyro's angle random walk, ``ARW^2 / dt`` [(rad/s)^2] (the env's
``gyro_arw_rad_per_sqrt_s``, :data:`GYRO_ARW_RAD_PER_SQRT_S` by default). The regulator may weight the
same mode rates (``q_modes``), which damps the compensator's own copies of the modes.

Current-estimator form: the command of step ``k`` uses the sample of step ``k`` (the env applies it
one period later, and the delay state carries it; the filter knows the command it sent)::

    x_f = x_p + M (y_k - C x_p)                 measurement update, M = P C^T (C P C^T + V)^-1
    u_k = -K_x x_f - K_i xi_k                   the regulator on the filtered state
    x_p <- A x_f + B u_k                        time update with the command the plant gets (clipped)
    xi  <- a xi - dt y_k

The compensator from ``y`` to ``u`` (:func:`compensator`) is a discrete system; its loop broken at the
plant input, ``L(z) = -K(z) G(z)`` (negative feedback), is assessed by :func:`loop_margins` on a dense
frequency grid and by the closed loop's eigenvalues (``control.stability_margins``' polynomial method
is not reliable at the 50-55 states of these loops; the grid method is checked against
:func:`.linearize.margins` on a low-order loop in the tests).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import control
import numpy as np
import scipy.linalg as sla

from lvgym.errors import ConfigError, check_number

from .flightloop import (control_timing, flight_plant, frequency_response, gyro_filter_ss, servo_discrete,
                         vehicle_with_gyro_output)
from .linearize import OperatingPoint

#: the v1 gyro's angle random walk [rad/sqrt(s)] (docs/sensors.md, ``gyro_arw_rad_per_sqrt_s``)
GYRO_ARW_RAD_PER_SQRT_S = 4.4e-5


@dataclass(frozen=True)
class LQGWeights:
    """Weights of one row's design (module docstring). Units: ``q_rate`` [1/(rad/s)^2], ``q_int``
    [1/rad^2], ``r_gimbal`` [1/rad^2], ``q_modes`` [1/(1/s)^2 on each modal
    and pendulum rate], ``w_gimbal`` [rad^2 per control period], ``w_modes`` [(1/s)^2
    per control period, on each modal and pendulum rate], ``integrator_leak_s`` [s] (the rate integral's),
    ``q_attitude`` [1/rad^2] on the attitude error (the attitude integral's design; ``q_int`` is then in
    [1/(rad s)^2])."""

    q_rate: float = 1.0
    q_int: float = 1.0
    r_gimbal: float = 1.0
    q_modes: float = 0.0
    w_gimbal: float = 1e-6
    w_modes: float = 0.0
    integrator_leak_s: float = 100.0
    q_attitude: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            lo_open = f.name in ("r_gimbal", "integrator_leak_s")
            object.__setattr__(self, f.name, check_number(f"lqg.{f.name}", getattr(self, f.name), 0.0, 1e12,
                                                          lo_open=lo_open))
        if self.q_rate + self.q_int <= 0.0:
            raise ConfigError("lqg.q_rate", self.q_rate, "q_rate or q_int must be > 0 (nothing to regulate)")


@dataclass
class RowDesign:
    """One row's compensator and the plant it was designed on: plant ``A, B, C`` (delay states
    included), regulator gains ``K_x`` (1, n) [rad per state unit] and ``K_i`` [rad/rad], Kalman gain
    ``M`` (n, 1) [state unit per rad/s], integrator factor ``a`` per control period ``dt`` [s]."""

    t: float
    plane: str
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    Kx: np.ndarray
    Ki: float
    M: np.ndarray
    a: float
    dt: float
    weights: LQGWeights
    state_labels: tuple[str, ...]
    integral: str = "rate"
    """what the integral integrates (:data:`INTEGRALS`): the rate error (leaky) or the attitude error (pure)"""

    def compensator(self) -> control.StateSpace:
        """The compensator from the gyro sample ``y`` [rad/s] (and, integrating the attitude, the attitude
        error ``e`` [rad]) to the command ``u`` [rad] (states: the predicted estimate ``x_p`` and the integral
        ``xi``), unclipped."""
        return compensator(self)


def plant_labels(op: OperatingPoint, plane: str = "pitch") -> tuple[str, ...]:
    """Names of the states of :func:`delayed_plant`, in order: the servo's ``servo_position`` and
    ``servo_rate``, the vehicle's (:func:`.flightloop.vehicle_with_gyro_output`), the gyro filters'
    ``gyro_filter_<i>``, the delay's ``command_delay_<i>``."""
    return _once("plant_labels", op, plane, lambda: _plant_labels(op, plane))


def _plant_labels(op: OperatingPoint, plane: str) -> tuple[str, ...]:
    servo = servo_discrete(op, float(op.task.physics_dt_s)).nstates
    vehicle = list(vehicle_with_gyro_output(op, plane).state_labels)
    f = gyro_filter_ss(op)
    _, steps = control_timing(op)
    return tuple(["servo_position", "servo_rate"][:servo] + vehicle
                 + [f"gyro_filter_{i}" for i in range(0 if f is None else f.nstates)]
                 + [f"command_delay_{i}" for i in range(steps)])


#: what :func:`_once` keeps: (function, id of the operating point, plane) -> (the operating point, value)
_KEPT: OrderedDict = OrderedDict()
_KEEP = 64


def _once(kind: str, op: OperatingPoint, plane: str, make: Callable[[], Any]) -> Any:
    """``make()``, or its value for the same operating point object and plane made before (the last
    :data:`_KEEP` of them): a row's search designs hundreds of weight sets on the same plants, and each
    plant is a numerical linearisation (:func:`.linearize.linearize`). An operating point is not changed
    after it is made (:func:`dispersed` makes a new one), so its object identifies its plants."""
    key = (kind, id(op), plane)
    hit = _KEPT.get(key)
    if hit is not None and hit[0] is op:
        _KEPT.move_to_end(key)
        return hit[1]
    value = make()
    _KEPT[key] = (op, value)
    while len(_KEPT) > _KEEP:
        _KEPT.popitem(last=False)
    return value


def delayed_plant(op: OperatingPoint, plane: str = "pitch") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``A, B, C`` of :func:`.flightloop.flight_plant` with the delay as its last states
    (``d_{k+1} = u_k`` for one period; a chain for more) and ``G_w`` (n, 1), the gimbal disturbance's
    input matrix (after the delay). The state order is :func:`plant_labels`' (python-control's
    ``series`` stacks the first system's states first; checked here on the servo's block). Made once per
    operating point and plane (:func:`_once`); the arrays returned are copies."""
    return tuple(m.copy() for m in _once("delayed_plant", op, plane, lambda: _delayed_plant(op, plane)))


def _delayed_plant(op: OperatingPoint, plane: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    g0 = flight_plant(op, plane, delay_steps=0)
    A0, B0, C0 = (np.asarray(m, float) for m in (g0.A, g0.B, g0.C))
    if np.any(np.asarray(g0.D, float) != 0.0):
        raise ValueError("the undelayed flight plant has feed-through; the delayed form needs D = 0")
    h = float(op.task.physics_dt_s)
    dt, steps = control_timing(op)
    servo = servo_discrete(op, h)
    ns = servo.nstates
    if ns and not np.allclose(A0[:ns, :ns], np.linalg.matrix_power(np.asarray(servo.A, float), int(round(dt / h)))):
        raise RuntimeError("flight_plant's state order is not servo first: plant_labels would misname the states")
    n0 = A0.shape[0]
    if steps < 1:
        return A0, B0, C0, B0.copy()
    n = n0 + steps
    A = np.zeros((n, n))
    A[:n0, :n0] = A0
    A[:n0, n - 1:n] = B0                      # the oldest command acts on the plant
    A[n0 + 1:n, n0:n - 1] += np.eye(steps - 1)
    B = np.zeros((n, 1))
    B[n0, 0] = 1.0
    C = np.zeros((1, n))
    C[:, :n0] = C0
    Gw = np.zeros((n, 1))
    Gw[:n0] = B0
    return A, B, C, Gw


#: what a row's integral integrates (:data:`lvgym.baselines.lqgkernel.INTEGRAL_SOURCES`, in the same order)
INTEGRALS = ("rate", "attitude")


def check_integral(integral: str) -> str:
    """``integral`` if it is one of :data:`INTEGRALS`, else a :class:`~lvgym.errors.ConfigError`."""
    if integral not in INTEGRALS:
        raise ConfigError("integral", integral, f"one of {INTEGRALS}")
    return integral


def attitude_output(labels: tuple[str, ...]) -> np.ndarray:
    """``C_e`` (1, n): the attitude error of the plant of state names ``labels`` (its one ``theta_y`` or
    ``theta_z``, the plane's attitude [rad]; the strapdown attitude error integrates the gyro's rate error,
    whose rigid part is this state's rate)."""
    at = [i for i, name in enumerate(labels) if name in ("theta_y", "theta_z")]
    if len(at) != 1:
        raise ValueError(f"one attitude state (theta_y or theta_z) among the plant's states, found {len(at)}")
    out = np.zeros((1, len(labels)))
    out[0, at[0]] = 1.0
    return out


def integral_input(C: np.ndarray, labels: tuple[str, ...], integral: str) -> np.ndarray:
    """The output row the integral integrates (its input ``C_i x``): the gyro's ``C`` or the attitude's."""
    return C if check_integral(integral) == "rate" else attitude_output(labels)


def _mode_rates(labels: tuple[str, ...]) -> list[int]:
    """Indices of the bending (``eta_dot_*``) and pendulum (``omega_s_*``) rates among ``labels``."""
    return [i for i, name in enumerate(labels) if name.startswith(("eta_dot_", "omega_s_"))]


def regulator_problem(A: np.ndarray, B: np.ndarray, C: np.ndarray, w: LQGWeights, dt: float,
                      labels: tuple[str, ...] = (), integral: str = "rate"
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """The regulator's problem (module docstring): the plant augmented with the leaky integral of ``-y``
    (``integral="attitude"``: the pure integral of ``-e``, the attitude of ``labels``), ``Aa`` (n+1, n+1),
    ``Ba`` (n+1, 1), its state weight ``Q`` (n+1, n+1) (``q_modes`` on the mode rates of ``labels``,
    ``q_attitude`` on the attitude), the command weight ``R`` (1, 1) [1/rad^2] and the integrator factor
    ``a``. The MPC (:mod:`lvgym.baselines.mpc`) minimises the same cost under the gimbal's limits."""
    n = A.shape[0]
    a = math.exp(-dt / w.integrator_leak_s) if check_integral(integral) == "rate" else 1.0
    Ci = integral_input(C, labels, integral)
    Aa = np.block([[A, np.zeros((n, 1))], [-dt * Ci, np.array([[a]])]])
    Ba = np.vstack([B, [[0.0]]])
    Q = np.zeros((n + 1, n + 1))
    Q[:n, :n] = w.q_rate * C.T @ C
    Q[n, n] = w.q_int
    for i in _mode_rates(labels):
        Q[i, i] += w.q_modes
    if w.q_attitude > 0.0:
        Ce = attitude_output(labels)
        Q[:n, :n] += w.q_attitude * Ce.T @ Ce
    return Aa, Ba, Q, np.array([[w.r_gimbal]]), a


def regulator(A: np.ndarray, B: np.ndarray, C: np.ndarray, w: LQGWeights, dt: float,
              labels: tuple[str, ...] = (), integral: str = "rate") -> tuple[np.ndarray, float, float]:
    """LQR gains ``(K_x, K_i, a)`` on the plant augmented with the leaky integral of ``-y`` (``integral``:
    or the pure integral of the attitude error, :func:`regulator_problem`); ``q_modes`` weights the mode
    rates of ``labels``."""
    n = A.shape[0]
    Aa, Ba, Q, R, a = regulator_problem(A, B, C, w, dt, labels, integral)
    K, _, _ = control.dlqr(Aa, Ba, Q, R)
    K = np.asarray(K, float)
    return K[:, :n], float(K[0, n]), a


def kalman_gain(A: np.ndarray, C: np.ndarray, Gw: np.ndarray, w: LQGWeights, dt: float,
                labels: tuple[str, ...], arw: float = GYRO_ARW_RAD_PER_SQRT_S,
                extra_noise: np.ndarray | None = None) -> np.ndarray:
    """Steady-state current-estimator gain ``M`` (n, 1) (module docstring); ``w_modes`` acts on the
    states named ``eta_dot_*`` (bending rates) and ``omega_s_*`` (pendulum rates) of ``labels``: the
    modes' uncertainty, which keeps the filter following a mode whose frequency is not the model's.
    ``arw``: the gyro's angle random walk [rad/sqrt(s)]; ``extra_noise``: a further process noise
    covariance (n, n) per control period (e.g. a disturbance model's states, ``experiments.lqg_headroom.headroom``)."""
    n = A.shape[0]
    V = np.array([[arw ** 2 / dt]])
    W = w.w_gimbal * Gw @ Gw.T
    for i in _mode_rates(labels):
        W[i, i] += w.w_modes
    if extra_noise is not None:
        W = W + extra_noise
    W = W + 1e-14 * np.eye(n)                          # keeps the Riccati equation regular on the delay state
    P = sla.solve_discrete_are(A.T, C.T, W, V)
    return P @ C.T / (C @ P @ C.T + V).item()


def design_row(op: OperatingPoint, plane: str, w: LQGWeights, integral: str = "rate") -> RowDesign:
    """The LQG design of ``plane`` at the operating point ``op`` (use the non-rigid model's); ``integral``:
    the leaky integral of the rate error (``lqg``) or the pure integral of the attitude error (``lqi``)."""
    A, B, C, Gw = delayed_plant(op, plane)
    dt, _ = control_timing(op)
    labels = plant_labels(op, plane)
    if len(labels) != A.shape[0]:
        raise RuntimeError(f"{len(labels)} state names for {A.shape[0]} states")
    Kx, Ki, a = regulator(A, B, C, w, dt, labels, integral)
    arw = float(getattr(op.task, "gyro_arw_rad_per_sqrt_s", GYRO_ARW_RAD_PER_SQRT_S))
    M = kalman_gain(A, C, Gw, w, dt, labels, arw)
    return RowDesign(float(op.t), plane, A, B, C, Kx, Ki, M, a, dt, w, labels, integral)


def compensator(d: RowDesign) -> control.StateSpace:
    """The linear compensator of a :class:`RowDesign` (module docstring), unclipped: ``y -> u``, or with the
    attitude integral ``(y, e) -> u`` (the gyro sample [rad/s] and the attitude error [rad]; the estimate's
    attitude state is then the measured ``e`` after the measurement update, as :mod:`.lqgkernel` flies it)."""
    A, B, C, Kx, M = d.A, d.B, d.C, d.Kx, d.M
    n = A.shape[0]
    F = np.eye(n) - M @ C
    Acl = A - B @ Kx
    Ac = np.block([[Acl @ F, -B * d.Ki], [np.zeros((1, n)), np.array([[d.a]])]])
    Cc = np.hstack([-Kx @ F, [[-d.Ki]]])
    if check_integral(d.integral) == "rate":
        Bc = np.vstack([Acl @ M, [[-d.dt]]])
        Dc = -Kx @ M
        return control.ss(Ac, Bc, Cc, Dc, d.dt, inputs=["gyro"], outputs=["command"])
    # the estimate's attitude state replaced by the measured attitude error: x_f = S (F x_p + M y) + c e
    c = attitude_output(d.state_labels).T
    S = np.eye(n) - c @ c.T
    Ac = np.block([[Acl @ S @ F, -B * d.Ki], [np.zeros((1, n)), np.array([[d.a]])]])
    Bc = np.block([[Acl @ S @ M, Acl @ c], [np.array([[0.0, -d.dt]])]])
    Cc = np.hstack([-Kx @ S @ F, [[-d.Ki]]])
    Dc = np.hstack([-Kx @ S @ M, -Kx @ c])
    return control.ss(Ac, Bc, Cc, Dc, d.dt, inputs=["gyro", "attitude"], outputs=["command"])


def loop_plant(op: OperatingPoint, plane: str = "pitch", integral: str = "rate") -> control.StateSpace:
    """The plant a row's compensator is closed on: :func:`.flightloop.flight_plant` (gimbal command to gyro
    sample), or for the attitude integral the same plant (:func:`delayed_plant`) with the attitude error
    (:func:`attitude_output`) as its second output."""
    if check_integral(integral) == "rate":
        return flight_plant(op, plane)
    A, B, C, _ = delayed_plant(op, plane)
    Ce = attitude_output(plant_labels(op, plane))
    return control.ss(A, B, np.vstack([C, Ce]), np.zeros((2, 1)), float(control_timing(op)[0]),
                      inputs=["command"], outputs=["gyro", "attitude"])


def loop_response(comp: control.StateSpace, plant: control.StateSpace, w: np.ndarray,
                  plant_response: np.ndarray | None = None) -> np.ndarray:
    """``L(e^{j w dt}) = -K G`` on ``w`` [rad/s]: the loop broken at the plant input, summed over the plant's
    outputs (the compensator's inputs). ``plant_response``: the plant's response per output (p, len(w)), if
    already computed (:func:`plant_responses`; a SISO plant's may be one row)."""
    gr = plant_responses(plant, w) if plant_response is None else np.atleast_2d(plant_response)
    p = gr.shape[0]
    out = np.zeros(len(w), complex)
    for i in range(p):
        out = out + (-response(_siso(comp, 0, i), w)) * gr[i]
    return out


def plant_responses(plant: control.StateSpace, w: np.ndarray) -> np.ndarray:
    """The response (p, len(w)) of each output of the single-input ``plant`` on ``w`` [rad/s]."""
    return np.array([response(_siso(plant, i, 0), w) for i in range(plant.noutputs)])


def _siso(sys_: control.StateSpace, out: int, inp: int) -> control.StateSpace:
    """Output ``out`` over input ``inp`` of ``sys_`` (itself when it is SISO)."""
    if sys_.ninputs == 1 and sys_.noutputs == 1:
        return sys_
    return control.ss(sys_.A, sys_.B[:, inp:inp + 1], sys_.C[out:out + 1, :], sys_.D[out:out + 1, inp:inp + 1],
                      sys_.dt)


def closed_loop(A: np.ndarray, B: np.ndarray, C: np.ndarray,
                comp: control.StateSpace) -> tuple[np.ndarray, np.ndarray]:
    """The sampled plant ``(A, B, C)`` closed by the compensator ``comp`` (gyro sample ``y`` -> command
    ``u``, :func:`compensator`): ``A_cl`` over the plant's states, then the compensator's, and ``B_y``, the
    input matrix of a noise added to the sample ``y``."""
    Ak, Bk, Ck, Dk = (np.asarray(m, float) for m in (comp.A, comp.B, comp.C, comp.D))
    return np.block([[A + B @ Dk @ C, B @ Ck], [Bk @ C, Ak]]), np.vstack([B @ Dk, Bk])


def open_loop(comp: control.StateSpace, plant: control.StateSpace) -> control.StateSpace:
    """``L = -K(z) G(z)``: the loop broken at the plant input, for negative feedback."""
    return control.ss(control.series(plant, -comp))


# ---------------------------------------------------------------------------- margins
def frequency_grid(dt: float, n: int = 20000) -> np.ndarray:
    """``n`` logarithmically spaced frequencies [rad/s] from 1e-5 rad/s to just below Nyquist (``pi / dt``)."""
    return np.logspace(-5, math.log10(math.pi / dt * 0.9999), n)


def response(sys_: control.StateSpace, w: np.ndarray) -> np.ndarray:
    """Complex response of the discrete SISO ``sys_`` at ``w`` [rad/s] (:func:`.flightloop.frequency_response`)."""
    return frequency_response(sys_, w)


def margins_from_response(r: np.ndarray, w: np.ndarray) -> dict[str, Any]:
    """Gain, gain-reduction and phase margins of an open loop from its response ``r`` on the grid ``w``
    [rad/s] (conventions of :func:`loop_margins`), and every gain crossover ``crossovers_radps``."""
    mag = np.abs(r)
    im, re = r.imag, r.real
    gm_up, gm_lo = [], []
    for i in np.nonzero(np.sign(im[:-1]) != np.sign(im[1:]))[0]:     # angle through +-180 deg where Re < 0
        f = im[i] / (im[i] - im[i + 1])
        x = re[i] + f * (re[i + 1] - re[i])
        if x < 0.0:
            g = -20.0 * math.log10(abs(x))
            (gm_up if abs(x) < 1.0 else gm_lo).append(g)
    pms, wcs = [], []
    lm = np.log(mag)
    for i in np.nonzero(np.sign(lm[:-1]) != np.sign(lm[1:]))[0]:
        f = lm[i] / (lm[i] - lm[i + 1])
        z = r[i] + f * (r[i + 1] - r[i])
        pm = math.degrees(math.atan2(z.imag, z.real)) + 180.0
        pms.append(pm - 360.0 if pm > 180.0 else pm)
        wcs.append(float(w[i] + f * (w[i + 1] - w[i])))
    i_pm = int(np.argmin(np.abs(pms))) if pms else None
    return {"gain_margin_db": min(gm_up) if gm_up else math.inf,
            "gain_reduction_margin_db": max(gm_lo) if gm_lo else -math.inf,
            "phase_margin_deg": pms[i_pm] if i_pm is not None else math.inf,
            "gain_crossover_radps": wcs[i_pm] if i_pm is not None else math.nan,
            "crossovers_radps": wcs}


def loop_margins(L: control.StateSpace, w: np.ndarray | None = None) -> dict[str, Any]:
    """Margins of the discrete open loop ``L`` (negative feedback) on a frequency grid ``w`` [rad/s]
    (default 20,000 points, 1e-5 rad/s to Nyquist), in the conventions of :func:`.linearize.margins`:
    ``gain_margin_db`` the smallest ``-20 log|L|`` at phase crossovers with ``|L| < 1``,
    ``gain_reduction_margin_db`` the largest ``-20 log|L|`` at those with ``|L| > 1`` (-inf: none),
    ``phase_margin_deg`` the one of smallest magnitude over the gain crossovers (``180 + angle L``,
    wrapped to (-180, 180]) with its ``gain_crossover_radps``, ``closed_loop_stable`` from the
    eigenvalues of the closed loop (a pole at ``z = 1`` within 1e-4 1/s allowed, as
    :func:`.linearize.margins`) and ``max_pole_real_per_s``."""
    w = frequency_grid(L.dt) if w is None else np.asarray(w, float)
    out = margins_from_response(response(L, w), w)
    growth = closed_loop_growth(L)
    return {**out, "closed_loop_stable": growth < 1e-4, "max_pole_real_per_s": growth}


def closed_loop_growth(L: control.StateSpace) -> float:
    """The largest real part [1/s] of the closed loop's poles (continuous equivalents ``ln z / dt``)."""
    p = np.linalg.eigvals(np.asarray(control.feedback(L, 1).A, float)).astype(complex)
    return float((np.log(p) / L.dt).real.max())


def gain_at(L: control.StateSpace, freqs: list[float], width: float = 0.05) -> list[float]:
    """The largest ``20 log|L|`` [dB] within ``+-width`` (relative) of each frequency [rad/s]; a
    frequency above Nyquist is folded back (the sampled loop sees its alias)."""
    nyq = math.pi / L.dt
    grids = []
    for f in freqs:
        fa = f % (2 * nyq)
        fa = 2 * nyq - fa if fa > nyq else fa
        grids.append(np.linspace(fa * (1 - width), min(fa * (1 + width), nyq * 0.9999), 400))
    if not grids:
        return []
    mag = np.abs(response(L, np.concatenate(grids))).reshape(len(grids), -1)    # one evaluation for all
    return [float(20 * np.log10(m.max())) for m in mag]
