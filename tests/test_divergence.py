"""The static aeroelastic divergence pressure (lvgym/simulator/divergence.py): a hand check of the pencil on one
mode and three strips, the independent study's number for the slender vehicle
(experiments/aeroelastic_divergence/divergence.py, docs/aerodynamics.md "Independent check of the
divergence"), and the family's check refusing a vehicle too close to its divergence."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lvgym.simulator.divergence import divergence_qbar, flight_divergence_qbar, pitch_stiffness_ratio


def test_one_mode_by_hand():
    # m0 + s e b / (w^2 - s A) = 0  =>  s = m0 w^2 / (m0 A - e b)
    x, c, x_cg = np.array([-0.5, -4.0, -9.5]), np.array([1.0, 0.2, 1.5]), -5.0
    phi, dphi, w = np.array([[0.02, -0.01, 0.03]]), np.array([[0.004, 0.002, -0.006]]), 60.0
    d = x - x_cg
    m0, e, b, A = c @ d, (c * d * dphi[0]).sum(), (c * phi[0]).sum(), (c * phi[0] * dphi[0]).sum()
    assert m0 < 0.0 and A < 0.0          # stable, and the modes alone never diverge here
    s_hand = m0 * w ** 2 / (m0 * A - e * b)
    s_modes = w ** 2 / A if A > 0 else math.inf
    q = divergence_qbar(x, c, 0.5, x_cg, phi, dphi, [w])
    assert q == pytest.approx(min(s_hand, s_modes) / 0.5, rel=1e-9)
    assert pitch_stiffness_ratio(0.999 * q, x, c, 0.5, x_cg, phi, dphi, [w]) > 0.0 > \
        pitch_stiffness_ratio(1.001 * q, x, c, 0.5, x_cg, phi, dphi, [w])
    # weathercock-unstable (CP ahead of the CG): only the modes' own divergence at a held attitude
    assert divergence_qbar(x, c, 0.5, -9.9, phi, dphi, [w]) == pytest.approx(s_modes / 0.5 if A > 0 else math.inf)


def test_slender_vehicle_against_the_independent_study():
    from experiments.aeroelastic_divergence import divergence as dv

    times = [3.0, 4.0, 5.0, 6.0]
    ours = flight_divergence_qbar("slender", times, np.full(4, 2.0), mode_interval=1.0)   # the shipped file
    lift = dv.vehicle_lift(length=8.5, diameter=0.3, mach=2.0)
    theirs = np.array([dv.divergence_qbar(dv.static_stiffness(dv.vehicle_beam(t, diameter=0.3), lift)) for t in times])
    # measured: 450 / 412 / 387 / 379 kPa against 497 / 460 / 440 / 440 (lvgym 9-14 % lower, conservative)
    assert np.all(ours < theirs) and np.all(ours > 0.8 * theirs)
    assert ours[0] == pytest.approx(450e3, rel=0.02) and ours[-1] == pytest.approx(379e3, rel=0.02)


def test_the_family_check_refuses_a_vehicle_near_its_divergence(monkeypatch):
    import lvgym.baselines.family as family
    from lvgym.vehicle.generator import generate

    g = generate(20_000)
    r = family.nominal_flight(g.data, seconds=20.0)
    assert r["completed"] and 0.0 < r["divergence_share"] < family.DIVERGENCE_SHARE
    assert family.flies_nominal(g.data, seconds=20.0)
    monkeypatch.setattr(family, "DIVERGENCE_SHARE", 0.5 * r["divergence_share"])     # a margin it cannot meet
    assert not family.flies_nominal(g.data, seconds=20.0)
