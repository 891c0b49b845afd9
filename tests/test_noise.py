"""The gimbal rate the flight gyro's noise commands on the linear loop (lvgym.baselines.design.noise), against hand
numbers."""

import math

import control
import numpy as np
import pytest

from lvgym.baselines.design.linearize import operating_point
from lvgym.baselines.design.noise import command_noise_rate, gyro_noise, noise_rate_on_grid

DT = 0.02
SIGMA = 3e-4                   # rad/s per sample
RATE = math.radians(30.0)      # rad/s


def _static(k: float) -> control.StateSpace:
    return control.ss([], [], [], [[k]], DT)


def test_a_constant_gain_commands_the_noise_s_differences():
    """C = k, no plant: u = k n, so u[k] - u[k-1] = k (n[k] - n[k-1]) has the RMS sqrt(2) k sigma, a
    commanded rate of sqrt(2) k sigma / dt (the grid stops 1e-5 short of the Nyquist frequency, where the
    weight |1 - e^{-j theta}|^2 is largest: 1e-5 of the integral is missing)."""
    expected = math.sqrt(2.0) * 2.5 * SIGMA / DT / RATE
    assert command_noise_rate(_static(2.5), _static(0.0), SIGMA, RATE) == pytest.approx(expected, rel=2e-5)


def test_feedback_divides_by_the_return_difference():
    """C = k, G = g (constants): u = -k / (1 + k g) n."""
    k, g = 2.0, 0.75
    expected = math.sqrt(2.0) * k / (1 + k * g) * SIGMA / DT / RATE
    assert command_noise_rate(_static(k), _static(g), SIGMA, RATE) == pytest.approx(expected, rel=2e-5)


def test_a_first_order_filter_by_hand():
    """C(z) = (1 - a) z / (z - a): u is AR(1) with variance s^2 (1 - a) / (1 + a) and lag-one
    correlation a, so u[k] - u[k-1] has the variance 2 s^2 (1 - a)^2 / (1 + a)."""
    a = 0.8
    C = control.tf([1 - a, 0.0], [1.0, -a], DT)
    expected = SIGMA * math.sqrt(2.0 * (1 - a) ** 2 / (1 + a)) / DT / RATE
    assert command_noise_rate(C, _static(0.0), SIGMA, RATE) == pytest.approx(expected, rel=1e-5)


def test_an_integrator_s_random_walk_is_not_counted():
    """C(z) = dt z / (z - 1) (the PID's integral): u is the random walk of the summed noise, whose level
    grows without bound, but its change per period is dt n: a commanded rate of sigma exactly."""
    C = control.tf([DT, 0.0], [1.0, -1.0], DT)
    assert command_noise_rate(C, _static(0.0), SIGMA, RATE) == pytest.approx(SIGMA / RATE, rel=1e-4)


def test_the_grid_form_is_the_system_form():
    a = 0.5
    w = np.geomspace(1e-3, 0.99999 * math.pi / DT, 20000)
    z = np.exp(1j * w * DT)
    C = (1 - a) * z / (z - a)
    G = 0.3 / (z - 0.9)
    sys_c, sys_g = control.tf([1 - a, 0.0], [1.0, -a], DT), control.tf([0.3], [1.0, -0.9], DT)
    assert noise_rate_on_grid(C, G, w, DT, SIGMA, RATE) == pytest.approx(
        command_noise_rate(sys_c, sys_g, SIGMA, RATE), rel=1e-12)


def test_a_continuous_plant_is_refused():
    with pytest.raises(ValueError, match="discrete"):
        command_noise_rate(_static(1.0), control.ss([], [], [], [[1.0]]), SIGMA, RATE)


def test_gyro_noise_reads_the_env():
    """v1's flight gyro: ARW 4.4e-5 rad/sqrt(s) over a 20 ms period, 3.11e-4 rad/s per sample; SMILE's
    servo rate limit 30 deg/s. v0's ideal state observation has no gyro noise."""
    sigma, rate = gyro_noise(operating_point("smile", 0.5, "rigid", protocol="v1"))
    assert sigma == pytest.approx(4.4e-5 / math.sqrt(0.02), rel=1e-12)
    assert rate == pytest.approx(math.radians(30.0), rel=1e-12)
    assert gyro_noise(operating_point("smile", 0.5, "rigid", protocol="v0"))[0] == 0.0
