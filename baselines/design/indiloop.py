"""The linear loop of ``indi`` (:mod:`lvgym.baselines.indi`): its open loop at the actuator, margins, mode gains
and the command rate the gyro's noise asks.

Per plane at the control period ``T`` (the law of :mod:`lvgym.baselines.indi` with the reference and the load
relief at zero), the gyro sample ``y`` [rad/s], the strapdown attitude ``theta`` [rad] and the measured actuator
position ``a`` [rad] give the command ``u`` [rad]::

    u = H a + (nu - D H y) / G,      nu = -k_q (y + k_theta theta),      theta = T z / (z - 1) y,

``H(z)`` the structural filter (the same on ``y`` and on ``a``: the synchronisation of Smeur, Chu & de Croon
2016; on ``a`` also the synchronisation sections ``S(z)``, :class:`..indikernel.SyncSections`, left out of
this line), ``D = (z - 1) / (T z)`` the backward difference and ``G`` the control power [1/s^2] of the design tables.
With ``P_y`` the discrete plant from the command to the sampled gyro (:func:`.flightloop.flight_plant`: delay,
hold, servo, vehicle, slope at the IMU, gyro filters) and ``P_a`` the path from the command to the sampled
actuator position (delay, hold, the servo's position at the sample: :func:`actuator_plant`), the loop broken at
the command (negative feedback, ``u = -L u``) is::

    L = C_y P_y - H S P_a,      C_y = (k_q (1 + k_theta T z / (z - 1)) + D H) / G.

The ``- H S P_a`` term is INDI's increment: the command starts from the filtered actuator position, positive
feedback of unit gain at zero frequency, which makes ``1 / (1 - H S P_a)`` an integrator (the incremental law's
"integral" action, with no integrator state of its own). A loop of a fixed controller around the rate plant is
the equivalent ``C_eq = C_y / (1 - H S P_a)`` on ``P_y`` (the gyro's noise sees it: :func:`noise_rate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from ..indikernel import INDIFilter, SyncSections
from .flightloop import control_timing, delay_ss, flight_plant, hold_and_sample, servo_discrete
from .lqg_row import gain_at, loop_margins
from .noise import gyro_noise, noise_rate_on_grid
from .response import frequency_response

__all__ = ["INDIRow", "actuator_plant", "equivalent_controller", "loop_plants", "noise_rate", "open_loop",
           "row_margins"]


@dataclass(frozen=True)
class INDIRow:
    """One row of the law: control power ``power`` [1/s^2] (``G``), rate gain ``k_rate`` [1/s] (``k_q``), attitude
    gain ``k_attitude`` [1/s] (``k_theta``), load-relief gain ``k_accel`` [rad/s per m/s^2] and the structural
    filter ``filt`` (``H``) on the gyro rate, the actuator position (and the reference and accelerometers), and
    ``sync`` (``S``) on the actuator position alone."""

    power: float
    k_rate: float
    k_attitude: float
    filt: INDIFilter
    k_accel: float = 0.0
    sync: SyncSections = SyncSections()

    def __post_init__(self) -> None:
        for key in ("power", "k_rate", "k_attitude", "k_accel"):
            v = getattr(self, key)
            lo_ok = v > 0.0 if key == "power" else v >= 0.0
            if not (isinstance(v, (int, float)) and math.isfinite(v) and lo_ok):
                raise ValueError(f"{key} = {v!r}: a finite number {'> 0' if key == 'power' else '>= 0'}")


def actuator_plant(op: Any, dt: float | None = None, delay_steps: int | None = None) -> control.StateSpace:
    """The discrete path from the gimbal command [rad] to the actuator position [rad] the observation samples
    (``gimbal_pitch`` times the limit): the delay, the command held over the control period, the servo's
    semi-implicit Euler map at the physics step (:func:`.flightloop.servo_discrete`), read at the period's end."""
    env_dt, env_delay = control_timing(op)
    dt = env_dt if dt is None else float(dt)
    delay_steps = env_delay if delay_steps is None else int(delay_steps)
    h = float(op.task.physics_dt_s)
    n = int(round(dt / h))
    g = hold_and_sample(control.ss(servo_discrete(op, h)), n)
    return control.ss(control.series(delay_ss(delay_steps, dt), g))


def loop_plants(op: Any, plane: str = "pitch") -> tuple[control.StateSpace, control.StateSpace]:
    """``(P_y, P_a)`` of the operating point ``op`` in ``plane`` (module docstring)."""
    return flight_plant(op, plane), actuator_plant(op)


def _parts(row: INDIRow, dt: float) -> tuple[control.StateSpace, control.StateSpace]:
    """``(C_y, H S)`` of the module docstring as discrete state spaces at ``dt`` [s]."""
    H = control.ss(row.filt.tf(dt))
    HS = control.ss(control.series(H, control.ss(row.sync.tf(dt))))
    z = control.tf([1.0, 0.0], [1.0], dt)
    D = control.ss((z - 1) / (dt * z))
    att = control.ss(row.k_rate * (1 + row.k_attitude * dt * z / (z - 1)))
    C_y = control.ss(control.parallel(att, control.series(H, D))) * (1.0 / row.power)
    return C_y, HS


def open_loop(row: INDIRow, P_y: control.StateSpace, P_a: control.StateSpace) -> control.StateSpace:
    """``L = C_y P_y - H S P_a`` (module docstring): the loop broken at the command, negative feedback."""
    C_y, H = _parts(row, float(P_y.dt))
    return control.ss(control.parallel(control.series(P_y, C_y), -control.series(P_a, H)))


def equivalent_controller(row: INDIRow, P_a: control.StateSpace) -> control.StateSpace:
    """``C_eq = C_y / (1 - H S P_a)``: the fixed controller on the gyro that the law is on the plant ``P_y``."""
    C_y, H = _parts(row, float(P_a.dt))
    one = control.ss([], [], [], [[1.0]], P_a.dt)
    return control.ss(control.series(control.feedback(one, control.series(P_a, H), +1), C_y))


def noise_rate(row: INDIRow, op: Any, P_y: control.StateSpace, P_a: control.StateSpace, n: int = 20000) -> float:
    """RMS of the commanded gimbal rate the flight gyro's white noise drives, over the servo's rate limit
    (:func:`.noise.noise_rate_on_grid` with ``C_eq``; the noise enters the rate and the strapdown attitude)."""
    sigma, rate_limit = gyro_noise(op)
    dt = float(P_y.dt)
    w = np.geomspace(1e-3, 0.99999 * math.pi / dt, n)
    C_y, H = _parts(row, dt)
    cy, h, py, pa = (frequency_response(s, w) for s in (C_y, H, P_y, P_a))
    return noise_rate_on_grid(cy / (1.0 - h * pa), py, w, dt, sigma, rate_limit)


def row_margins(row: INDIRow, op: Any, plane: str = "pitch", modes: dict[str, list[float]] | None = None,
                noise: bool = True, w: np.ndarray | None = None,
                plants: tuple[control.StateSpace, control.StateSpace] | None = None) -> dict[str, Any]:
    """Margins of the row's loop on the operating point ``op`` (:func:`.lqg_row.loop_margins`: gain, gain
    reduction and phase margin, closed-loop stability), the loop's gain [dB] at the ``modes``' frequencies
    (``slosh``, ``bending``; folded above Nyquist) and the gyro noise's command rate (fraction of the limit); ``w``:
    the frequency grid [rad/s] (default :func:`.lqg_row.frequency_grid`); ``plants``: ``(P_y, P_a)`` of ``op`` if
    already built (:func:`loop_plants`)."""
    P_y, P_a = plants if plants is not None else loop_plants(op, plane)
    L = open_loop(row, P_y, P_a)
    out = dict(loop_margins(L, w))
    out.pop("crossovers_radps", None)
    if modes is not None:
        out["slosh_db"] = gain_at(L, modes.get("slosh", []))
        out["bending_db"] = gain_at(L, modes.get("bending", []))
    if noise:
        out["noise_rate_fraction"] = noise_rate(row, op, P_y, P_a, n=20000 if w is None else len(w))
    return out
