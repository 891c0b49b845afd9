"""The gimbal command's response to the flight gyro's noise on the linear loop (baselines.noise), against
hand numbers."""

import math

import control
import numpy as np
import pytest

from baselines.linearize import operating_point
from baselines.noise import command_noise, gyro_noise, noise_fraction_on_grid

DT = 0.02
SIGMA = 3e-4          # rad/s per sample
LIMIT = math.radians(5.0)


def _static(k: float) -> control.StateSpace:
    return control.ss([], [], [], [[k]], DT)


def test_a_constant_gain_passes_the_noise_through():
    """C = k, no plant: the command is k n, RMS k sigma (the grid's missing band below 1e-3 rad/s is
    1e-3 dt / pi of the whole, 6e-6)."""
    assert command_noise(_static(2.5), _static(0.0), SIGMA, LIMIT) == pytest.approx(2.5 * SIGMA / LIMIT, rel=1e-5)


def test_feedback_divides_by_the_return_difference():
    """C = k, G = g (constants): u = -k / (1 + k g) n."""
    k, g = 2.0, 0.75
    assert command_noise(_static(k), _static(g), SIGMA, LIMIT) == pytest.approx(k / (1 + k * g) * SIGMA / LIMIT,
                                                                               rel=1e-5)


def test_a_first_order_filter_by_hand():
    """C(z) = (1 - a) z / (z - a): white noise of variance s^2 comes out with variance
    s^2 (1 - a)^2 / (1 - a^2) = s^2 (1 - a) / (1 + a)."""
    a = 0.8
    C = control.tf([1 - a, 0.0], [1.0, -a], DT)
    expected = SIGMA * math.sqrt((1 - a) / (1 + a)) / LIMIT
    assert command_noise(C, _static(0.0), SIGMA, LIMIT) == pytest.approx(expected, rel=1e-4)


def test_the_grid_form_is_the_system_form():
    a = 0.5
    w = np.geomspace(1e-3, 0.99999 * math.pi / DT, 20000)
    z = np.exp(1j * w * DT)
    C = (1 - a) * z / (z - a)
    G = 0.3 / (z - 0.9)
    sys_c, sys_g = control.tf([1 - a, 0.0], [1.0, -a], DT), control.tf([0.3], [1.0, -0.9], DT)
    assert noise_fraction_on_grid(C, G, w, DT, SIGMA, LIMIT) == pytest.approx(
        command_noise(sys_c, sys_g, SIGMA, LIMIT), rel=1e-12)


def test_a_continuous_plant_is_refused():
    with pytest.raises(ValueError, match="discrete"):
        command_noise(_static(1.0), control.ss([], [], [], [[1.0]]), SIGMA, LIMIT)


def test_gyro_noise_reads_the_env():
    """v1's flight gyro: ARW 4.4e-5 rad/sqrt(s) over a 20 ms period, 3.11e-4 rad/s per sample; SMILE's
    5 deg gimbal limit. v0's ideal state observation has no gyro noise."""
    sigma, limit = gyro_noise(operating_point("smile", 0.5, "rigid", protocol="v1"))
    assert sigma == pytest.approx(4.4e-5 / math.sqrt(0.02), rel=1e-12)
    assert limit == pytest.approx(math.radians(5.0), rel=1e-12)
    assert gyro_noise(operating_point("smile", 0.5, "rigid", protocol="v0"))[0] == 0.0
