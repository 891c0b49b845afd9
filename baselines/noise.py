"""The gimbal command's response to the flight gyro's noise, on the linear loop.

Protocol v1's flight computer reads a gyro whose samples carry white noise, the angle random walk
``gyro_arw_rad_per_sqrt_s`` (ARW) seen over one control period: a standard deviation of
``sigma = ARW / sqrt(dt)`` [rad/s] per sample (``lvgym.envs.functional``; 3.1e-4 rad/s for v1's
4.4e-5 rad/sqrt(s) at 50 Hz). A controller ``C(z)`` (command [rad] per rate [rad/s], negative
feedback ``u = -C (y + n)``) around the plant ``G(z)`` turns it into the command

    u_n = -C / (1 + C G) n,     rms(u_n)^2 = sigma^2 (1 / pi) int_0^pi |C / (1 + C G)|^2 d(w dt),

read here on a frequency grid (white noise has a flat spectrum over the sampled band). A loop that
amplifies it spends the actuator's travel and rate on noise: ``gs-pid-flex``'s first designs, without
this requirement, commanded 14-37 % of the gimbal limit RMS from the gyro noise alone, most of it at
20-25 Hz, where the servo (15 rad/s) does not follow; ``lqg`` 0.2-0.6 % (docs/flex-design.md).
:func:`command_noise` gives the fraction of the gimbal limit; :mod:`.flexdesign` holds every row to
``Requirements.noise_fraction``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["gyro_noise", "noise_fraction_on_grid", "command_noise"]


def gyro_noise(op: Any) -> tuple[float, float]:
    """(``sigma`` [rad/s], the gimbal limit [rad]) of the env an operating point was flown in: the gyro's
    white noise per sample (``ARW / sqrt(control_dt)``; 0 without the flight computer's gyro, e.g. the
    ideal ``state`` observation) and the limit the command is normalised by."""
    spec = op.task
    if spec is None or op.sim.servo is None:
        raise ValueError("gyro_noise: an operating point flown in an env (its task spec and its servo)")
    sigma = 0.0
    if spec.observation == "flight":
        sigma = float(spec.gyro_arw_rad_per_sqrt_s) / math.sqrt(float(spec.control_dt_s))
    return sigma, float(op.sim.servo.limit)


def noise_fraction_on_grid(C: np.ndarray, G: np.ndarray, w: np.ndarray, dt: float, sigma: float,
                           limit: float) -> float:
    """RMS of the command's response to white noise of ``sigma`` [rad/s] per sample over ``limit`` [rad],
    from the responses ``C`` and ``G`` at the frequencies ``w`` [rad/s] (ascending, up to the Nyquist
    frequency ``pi / dt``; the trapezoidal rule on the grid, which a log grid from 1e-3 rad/s resolves
    well: the noise's part below 1e-3 rad/s is at most 1e-3 dt / pi of the band)."""
    T2 = np.abs(C / (1.0 + C * G)) ** 2
    mean = float(np.trapezoid(T2, w)) * dt / math.pi       # (1/pi) int |T|^2 d(w dt)
    return sigma * math.sqrt(mean) / limit


def command_noise(C: Any, G: Any, sigma: float, limit: float, n: int = 20000) -> float:
    """:func:`noise_fraction_on_grid` of python-control systems ``C`` (the controller, command [rad] per
    rate [rad/s], negative feedback) and ``G`` (the discrete plant, rate per command) on ``n``
    log-spaced frequencies from 1e-3 rad/s to just below the Nyquist frequency."""
    if not G.dt or G.dt is True:
        raise ValueError(f"command_noise: G.dt = {G.dt!r}: a discrete plant with its sampling period [s] "
                         "(the gyro is sampled)")
    dt = float(G.dt)
    w = np.geomspace(1e-3, 0.99999 * math.pi / dt, n)
    z = np.exp(1j * w * dt)
    c = np.asarray(C(z), complex).ravel()
    g = np.asarray(G(z), complex).ravel()
    return noise_fraction_on_grid(c, g, w, dt, sigma, limit)
