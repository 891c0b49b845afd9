"""The gimbal rate the flight gyro's noise commands, on the linear loop.

Protocol v1's flight computer reads a gyro whose samples carry white noise, the angle random walk
``gyro_arw_rad_per_sqrt_s`` (ARW) seen over one control period: a standard deviation of
``sigma = ARW / sqrt(dt)`` [rad/s] per sample (``lvgym.envs.functional``; 3.1e-4 rad/s for v1's
4.4e-5 rad/sqrt(s) at 50 Hz). A controller ``C(z)`` (command [rad] per rate [rad/s], negative feedback
``u = -C (y + n)``) around the plant ``G(z)`` turns it into the command ``u_n = -C / (1 + C G) n``, and
asks the servo for the gimbal rate ``(u_n[k] - u_n[k-1]) / dt``, whose RMS is

    sigma / dt * sqrt( (1 / pi) int_0^pi |C / (1 + C G)|^2 |1 - e^{-j theta}|^2 d theta ),  theta = w dt,

read here on a frequency grid (white noise has a flat spectrum over the sampled band).

The rate, not the command itself: a rate loop's integral holds the attitude it integrates from the gyro,
so the command's own response to the noise holds a random walk (``|C|`` grows as ``1 / w`` at low
frequency, and so does the integral of ``|C / (1 + C G)|^2`` with the band's low end), which is the
attitude hold following the gyro's angle random walk, not actuator activity. The command's change per
period weights the spectrum by ``|1 - e^{-j theta}|^2``, which leaves that out and keeps what the
actuator is asked to do. :func:`command_noise_rate` gives it as a fraction of the servo's rate limit;
:mod:`.flexdesign` holds every ``gs-pid-flex`` row to ``Requirements.noise_rate_fraction``. Without
that requirement the first flex designs asked for 40-200 deg/s RMS of gimbal rate from the gyro's noise
alone, beyond the servo's 30 deg/s (docs/flex-design.md, "Sensor noise in the command").
"""

from __future__ import annotations

import math
from typing import Any

import control
import numpy as np

from .response import ss_response

__all__ = ["gyro_noise", "noise_rate_on_grid", "command_noise_rate"]


def gyro_noise(op: Any) -> tuple[float, float]:
    """(``sigma`` [rad/s], the servo's rate limit [rad/s]) of the env an operating point was flown in: the
    gyro's white noise per sample (``ARW / sqrt(control_dt)``; 0 without the flight computer's gyro,
    e.g. the ideal ``state`` observation) and the rate the commanded rate is compared with."""
    spec = op.task
    if spec is None or op.sim.servo is None:
        raise ValueError("gyro_noise: an operating point flown in an env (its task spec and its servo)")
    sigma = 0.0
    if spec.observation == "flight":
        sigma = float(spec.gyro_arw_rad_per_sqrt_s) / math.sqrt(float(spec.control_dt_s))
    return sigma, float(op.sim.servo.rate_limit)


def noise_rate_on_grid(C: np.ndarray, G: np.ndarray, w: np.ndarray, dt: float, sigma: float,
                       rate_limit: float) -> float:
    """RMS of the commanded gimbal rate ``(u[k] - u[k-1]) / dt`` [rad/s] that white noise of ``sigma``
    [rad/s] per sample drives, over ``rate_limit`` [rad/s], from the responses ``C`` and ``G`` at the
    frequencies ``w`` [rad/s] (ascending, up to the Nyquist frequency ``pi / dt``; trapezoidal rule)."""
    theta = w * dt
    T2 = np.abs(C / (1.0 + C * G)) ** 2 * (4.0 * np.sin(0.5 * theta) ** 2)     # |1 - e^{-j theta}|^2
    mean = float(np.trapezoid(T2, theta)) / math.pi
    return sigma * math.sqrt(mean) / dt / rate_limit


def command_noise_rate(C: Any, G: Any, sigma: float, rate_limit: float, n: int = 20000) -> float:
    """:func:`noise_rate_on_grid` of python-control systems ``C`` (the controller, command [rad] per rate
    [rad/s], negative feedback) and ``G`` (the discrete plant, rate per command) on ``n`` log-spaced
    frequencies from 1e-3 rad/s to just below the Nyquist frequency."""
    if not G.dt or G.dt is True:
        raise ValueError(f"command_noise_rate: G.dt = {G.dt!r}: a discrete plant with its sampling period [s] "
                         "(the gyro is sampled)")
    dt = float(G.dt)
    w = np.geomspace(1e-3, 0.99999 * math.pi / dt, n)
    z = np.exp(1j * w * dt)
    c, g = (ss_response(s, z) if isinstance(s, control.StateSpace) else np.asarray(s(z), complex).ravel()
            for s in (C, G))
    return noise_rate_on_grid(c, g, w, dt, sigma, rate_limit)
