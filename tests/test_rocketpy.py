"""The rigid simulator against RocketPy on the shipped ``stratos3`` (slow: run with ``pytest -m slow``).

The comparison itself is :mod:`lvgym.verify.rocketpy_case`; docs/rocketpy-validation.md has the numbers
(apogee within 0.14 % at 85 deg and 0.004 % vertical, maximum Mach within 0.02 %). The issue asks for 2 %.
"""

import numpy as np
import pytest

pytest.importorskip("rocketpy")

from lvgym.verify.rocketpy_case import CASES, compare  # noqa: E402
from lvgym.verify.rocketpy_flights import lvgym_simulator, rocketpy_flight  # noqa: E402

TOL = 0.02


@pytest.mark.slow
@pytest.mark.parametrize("elevation_deg, rail_length", CASES)
def test_apogee_and_max_mach_agree_with_rocketpy(elevation_deg, rail_length):
    c = compare(elevation_deg, rail_length)
    assert c.lvgym.apogee > 100e3 and c.lvgym.max_mach > 4.0        # the flight we mean to compare
    assert abs(c.relative("apogee")) < TOL, c.table()
    assert abs(c.relative("max_mach")) < TOL, c.table()
    assert abs(c.lvgym.t_apogee - c.rocketpy.t_apogee) < 1.0, c.table()


@pytest.mark.slow
def test_rocketpy_flies_lvgyms_mass_properties():
    # the set-up, not the result: RocketPy's mass, CG and inertia about the CG follow lvgym's timeline
    # (RocketPy's propellant mass is a 100-point spline of the flow integral: 0.11 kg off in the first
    # second, with its 0.5 s thrust ramp, 0.023 kg after it)
    flight, _ = rocketpy_flight()
    rocket, tl = flight.rocket, lvgym_simulator().timeline
    t = np.linspace(0.0, 45.0, 181)
    mass = np.array([rocket.total_mass(x) for x in t])
    cg = np.array([rocket.center_of_mass(x) for x in t])
    i_cg = np.array([rocket.I_11(x) for x in t]) - mass * (cg - rocket.center_of_dry_mass_position) ** 2
    assert np.allclose(mass, tl.interp("mass", t), rtol=0.0, atol=0.15)
    assert np.allclose(cg, -tl.interp("cg", t)[:, 0], rtol=0.0, atol=1e-3)
    assert np.allclose(i_cg, tl.interp("inertia", t)[:, 1, 1], rtol=1e-4)
    assert rocket.motor.burn_out_time == pytest.approx(next(t for t, e in tl.events if e.endswith("burnout")))
