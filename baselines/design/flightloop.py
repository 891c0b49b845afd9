"""The TVC loop's plant as the flight computer sees it: gimbal command to sampled gyro, per plane.

:func:`.linearize.linearize` gives the vehicle from the gimbal angle in force to the body rate. The
flight computer neither commands the gimbal angle nor reads the body rate. Its path, in order:

1. the command, held over a control period (zero-order hold) after ``delay`` periods of computational
   delay (``TaskSpec.action_delay_steps``: one in protocol v1);
2. the gimbal servo, second order (``Servo.frequency`` [rad/s], ``Servo.damping``; its position and rate
   limits are not in the linear model);
3. the vehicle (rigid body, and in the non-rigid model its bending modes and slosh pendulums);
4. the rate gyro at the IMU station, which sees the body rate plus the rate of the bending slope there:
   pitch ``omega_y - sum_k phi'_k(x_imu) eta_dot_z,k``, yaw ``omega_z + sum_k phi'_k(x_imu) eta_dot_y,k``
   (as :func:`lvgym.simulator.imu.imu_end_k`), then its second-order bandwidth and the anti-aliasing
   Butterworth filter (:meth:`lvgym.simulator.imu.Imu.continuous`);
5. sampling at the control period.

:func:`sensed_plant` is steps 2-4 in continuous time (the analogue loop, for charts and for
continuous designs), :func:`flight_plant` all five as a discrete python-control system at the control
period, discretised as the simulator integrates it (the servo's semi-implicit Euler map at the physics
step, the rest by zero-order hold at the physics step, then ``z^-delay``). With the
env's ideal observation (protocol v0, ``observation="state"``: no IMU) step 4 is the body rate itself and
there is no delay. Everything is read from the operating point's env: its servo, its IMU, its control
period and its delay, so the model is of the loop the benchmark flies.
"""

from __future__ import annotations

import control
import numpy as np

from .linearize import PLANES, OperatingPoint, linearize
from .response import frequency_response  # noqa: F401  (the design tools' import of it, here as before)

#: sign of the bending slope rate in each plane's gyro (see the module docstring) and the plane of modes
_SLOPE = {"pitch": (-1.0, "z"), "yaw": (1.0, "y")}


def imu_slopes(op: OperatingPoint) -> np.ndarray:
    """Mode slopes ``phi'_k(x_imu)`` (K,) [1/(m sqrt(kg))] at the IMU station in force at ``op.t`` (the
    timeline's sensor 0 is the IMU station; the modes are those of the piece in force)."""
    tl = op.sim.timeline
    i, w = tl.locate([op.t])
    j = int(i[0] + 1 if w[0] >= 1.0 else i[0])
    return np.asarray(tl.dphi_sensor[j, 0], float)


def servo_ss(op: OperatingPoint) -> control.StateSpace:
    """The env's gimbal servo ``w^2 / (s^2 + 2 z w s + w^2)`` (one axis), or a unit gain with no servo."""
    s = op.sim.servo
    if s is None:
        return control.ss([], [], [], [[1.0]])
    w, z = float(s.frequency), float(s.damping)
    return control.ss(control.tf([w * w], [1.0, 2.0 * z * w, w * w]))


def gyro_filter_ss(op: OperatingPoint) -> control.StateSpace | None:
    """The IMU's gyro filters (bandwidth, then anti-aliasing) as one system, or None without an IMU."""
    imu = getattr(op.sim, "imu", None)
    if imu is None:
        return None
    a, b, c = imu.continuous()["gyro"]
    return control.ss(a, b, c, 0.0)


def vehicle_with_gyro_output(op: OperatingPoint, plane: str = "pitch") -> control.StateSpace:
    """:func:`.linearize.linearize` of ``plane`` with the output the gyro's input: the body rate plus
    the bending slope rate at the IMU (the body rate alone without an IMU or in the rigid model)."""
    g = linearize(op=op, plane=plane)
    if plane not in _SLOPE or getattr(op.sim, "imu", None) is None:
        return g
    sign, modes = _SLOPE[plane]
    dphi = imu_slopes(op)
    names = list(g.state_labels)
    C = np.array(g.C, float).copy()
    for k, d in enumerate(dphi):
        name = f"eta_dot_{modes}{k}"
        if name in names:
            C[0, names.index(name)] += sign * d
    return control.ss(g.A, g.B, C, g.D, inputs=g.input_labels, outputs=[f"gyro_{plane}_input"],
                      states=names)


def _check_plane(plane: str) -> None:
    if plane not in _SLOPE:
        raise ValueError(f"plane = {plane!r}: the TVC loop is in 'pitch' or 'yaw' (roll: linearize(plane='roll'))")


def gyro_chain(op: OperatingPoint, plane: str = "pitch") -> control.StateSpace:
    """Continuous chain from the gimbal angle in force [rad] to the gyro's filtered output [rad/s]: the
    vehicle, the slope at the IMU and the gyro filters (step 3-4 of the module docstring)."""
    _check_plane(plane)
    chain = vehicle_with_gyro_output(op, plane)
    f = gyro_filter_ss(op)
    return control.ss(chain if f is None else control.series(chain, f))


def sensed_plant(op: OperatingPoint, plane: str = "pitch") -> control.StateSpace:
    """Continuous chain from the gimbal command [rad] (after the delay and the hold) to the gyro's
    filtered output [rad/s]: servo, vehicle, slope at the IMU, gyro filters (steps 2-4 of the module
    docstring). Not for roll (its input is a moment, no servo)."""
    g = control.ss(control.series(servo_ss(op), gyro_chain(op, plane)))
    inp = PLANES[plane][5]
    return control.ss(g.A, g.B, g.C, g.D, inputs=[f"{inp}_command"], outputs=[f"gyro_{plane}"])


def control_timing(op: OperatingPoint) -> tuple[float, int]:
    """The env's control period [s] and computational delay [control periods]."""
    task = op.task
    if task is None:
        return 0.02, 0
    return float(task.control_dt_s), int(getattr(task, "action_delay_steps", 0))


def delay_ss(steps: int, dt: float) -> control.StateSpace:
    """``z^-steps`` at the sampling period ``dt`` [s] as a discrete state space (a unit gain for 0)."""
    if steps <= 0:
        return control.ss([], [], [], [[1.0]], dt)
    A = np.eye(steps, k=-1)
    B = np.zeros((steps, 1))
    B[0, 0] = 1.0
    C = np.zeros((1, steps))
    C[0, -1] = 1.0
    return control.ss(A, B, C, 0.0, dt)


def servo_discrete(op: OperatingPoint, h: float) -> control.StateSpace:
    """The simulator's servo at its physics step ``h`` [s] (:func:`lvgym.simulator.servo.servo_step_k`,
    limits aside): semi-implicit Euler ``r' = r + h (w^2 (c - p) - 2 z w r)``, ``p' = p + h r'``; its
    output is the updated position ``p'``, which the dynamics hold over the step. States ``(p, r)``."""
    s = op.sim.servo
    if s is None:
        return control.ss([], [], [], [[1.0]], h)
    w, z = float(s.frequency), float(s.damping)
    A = np.array([[1.0 - h * h * w * w, h * (1.0 - 2.0 * z * w * h)], [-h * w * w, 1.0 - 2.0 * z * w * h]])
    B = np.array([[h * h * w * w], [h * w * w]])
    C = np.array([[1.0, 0.0]])
    return control.ss(A, B, C @ A, C @ B, h)


def hold_and_sample(g: control.StateSpace, n: int) -> control.StateSpace:
    """``g`` (discrete at ``h``, no feed-through) with its input held over ``n`` of its steps and its
    output read every ``n`` steps: the system at ``n h`` (``A^n``, ``sum_i A^i B``, ``C``)."""
    A, B = np.asarray(g.A, float), np.asarray(g.B, float)
    Bn, P = np.zeros_like(B), np.eye(A.shape[0])
    for _ in range(n):
        Bn = Bn + P @ B
        P = P @ A
    return control.ss(P, Bn, g.C, g.D, g.dt * n)


def flight_plant(op: OperatingPoint, plane: str = "pitch", dt: float | None = None,
                 delay_steps: int | None = None) -> control.StateSpace:
    """The discrete plant the flight computer controls, at its control period: the sampled gyro output
    [rad/s] per commanded gimbal angle [rad] (steps 1-5 of the module docstring). ``dt`` [s] and
    ``delay_steps`` default to the env's. As the simulator flies it: the servo is its semi-implicit
    Euler map at the physics step (:func:`servo_discrete`), the gimbal held over each physics step into
    the vehicle and the gyro filters (ZOH at the physics step), the command held over the control
    period's physics steps and the gyro read at its end (:func:`hold_and_sample`)."""
    _check_plane(plane)
    env_dt, env_delay = control_timing(op)
    dt = env_dt if dt is None else float(dt)
    delay_steps = env_delay if delay_steps is None else int(delay_steps)
    h = float(op.task.physics_dt_s) if op.task is not None else dt
    n = int(round(dt / h))
    if n < 1 or abs(n * h - dt) > 1e-9 * dt:
        raise ValueError(f"dt = {dt!r}: a whole multiple of the physics step {h!r} s")
    g = control.series(servo_discrete(op, h), control.c2d(gyro_chain(op, plane), h, "zoh"))
    g = hold_and_sample(control.ss(g), n)
    d = control.series(delay_ss(delay_steps, dt), g)
    inp = PLANES[plane][5]
    return control.ss(d.A, d.B, d.C, d.D, dt, inputs=[f"{inp}_command"], outputs=[f"gyro_{plane}"])


def mode_frequencies(op: OperatingPoint, plane: str = "pitch") -> dict[str, list[float]]:
    """Natural frequencies [rad/s] of the plant's lightly damped modes in ``plane``: ``slosh`` and
    ``bending`` (from the non-rigid linearisation's eigenvectors: the coordinate family with the
    largest share of each oscillatory pole's eigenvector), ``rigid`` the others."""
    g = linearize(op=op, plane=plane)
    ev, vec = np.linalg.eig(np.asarray(g.A, float))
    names = list(g.state_labels)
    out: dict[str, list[float]] = {"slosh": [], "bending": [], "rigid": []}
    for lam, v in zip(ev, vec.T):
        if lam.imag <= 1e-9:
            continue
        share = {"slosh": 0.0, "bending": 0.0, "rigid": 0.0}
        for nm, a in zip(names, np.abs(v)):
            kind = "slosh" if nm.startswith(("beta_", "omega_s_")) else "bending" if nm.startswith("eta") else "rigid"
            share[kind] += a * a
        out[max(share, key=share.get)].append(float(abs(lam)))
    return {k: sorted(v) for k, v in out.items()}


