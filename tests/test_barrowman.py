"""Aerodynamic tables from geometry (lvgym/environment/barrowman.py), against hand numbers from the
published formulas and against RocketPy 1.13 (test-only dependency)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from lvgym.environment import make
from lvgym.environment.aerodynamics import AxisymmetricAero
from lvgym.environment.barrowman import (NOSE_SHAPES, BarrowmanAero, FinSet, base_drag, fin_normal_slope,
                                         slender_body_wave_drag)
from lvgym.errors import ConfigError

FINS = {"count": 4, "root_chord": 0.6, "tip_chord": 0.25, "span": 0.3, "sweep": 0.35,
        "station": -6.8, "thickness": 0.006}
GEOMETRY = {"nose": {"shape": "ogive", "length": 0.9}, "body": {"diameter": 0.28, "length": 6.5},
            "fins": FINS, "boat_tail": {"length": 0.3, "aft_diameter": 0.22}}


@pytest.fixture(scope="module")
def vehicle():
    return BarrowmanAero(**GEOMETRY, x_ref=-4.0)


def rocketpy_rocket(kind):
    """The same geometry in RocketPy, nose tip at 0, positions positive aft."""
    rocketpy = pytest.importorskip("rocketpy")
    rocket = rocketpy.Rocket(radius=0.14, mass=100.0, inertia=(10.0, 10.0, 1.0), power_off_drag=0.5,
                             power_on_drag=0.5, center_of_mass_without_motor=3.0,
                             coordinate_system_orientation="nose_to_tail")
    rocket.add_nose(length=0.9, kind=kind, position=0.0)
    rocket.add_trapezoidal_fins(n=4, root_chord=0.6, tip_chord=0.25, span=0.3, position=6.8,
                                sweep_length=0.35)
    rocket.add_tail(top_radius=0.14, bottom_radius=0.11, length=0.3, position=7.4)
    return rocket


@pytest.mark.parametrize("shape, kind", [("ogive", "ogive"), ("cone", "conical"),
                                         ("von_karman", "von karman")])
def test_normal_force_slope_and_cp_match_rocketpy(shape, kind):
    # RocketPy: Rocket.total_lift_coeff_der(M) (sum of clalpha of nose, fins, tail, each scaled
    # to the rocket's reference area) and Rocket.cp_position(M) (nose-to-tail coordinate, so the
    # station is its negative). Measured here at M 0.1: CNa 11.812701 both, for all three noses;
    # CP -5.906767 m both (ogive), -5.937802 (cone), -5.912406 (von Karman).
    ours = BarrowmanAero(**(GEOMETRY | {"nose": {"shape": shape, "length": 0.9}}))
    rocket = rocketpy_rocket(kind)
    for mach in (0.1, 0.5):
        cna_rp, x_rp = rocket.total_lift_coeff_der(mach), -rocket.cp_position(mach)
        assert ours.cn_alpha(mach) == pytest.approx(cna_rp, rel=0.05)
        assert ours.x_cp(mach) == pytest.approx(x_rp, rel=0.05)
        # in fact the same formulas: agreement far inside the 5 % asked for
        assert ours.cn_alpha(mach) == pytest.approx(cna_rp, rel=1e-6)
        assert abs(ours.x_cp(mach) - x_rp) < 1e-5


def test_fin_slope_equals_barrowmans_closed_form():
    # Barrowman 1966: CNa = 4 n (s/d)^2 / (1 + sqrt(1 + (2 l_m / (a + b))^2)) (1 + R / (s + R)).
    # Mid-chord line from 0.3 m (root) to 0.35 + 0.125 m (tip) over 0.3 m of span:
    # l_m = hypot(0.3, 0.175) = 0.347311 m; 2 l_m / 0.85 = 0.817203; sqrt(1 + 0.667820) = 1.291441;
    # 16 (0.3/0.28)^2 = 18.367347; / 2.291441 = 8.015634; x (1 + 0.14/0.44) = 10.5661.
    fins = FinSet(**FINS)
    cna, single = fin_normal_slope(fins, 0.14, math.pi * 0.14 ** 2, 0.0)
    assert cna == pytest.approx(10.5661, rel=1e-5)
    assert single == pytest.approx(cna / (2.0 * (1.0 + 0.14 / 0.44)))


def test_fin_slope_is_continuous_through_mach_one():
    # Diederich's slope tends to the slender-wing value pi AR / 2 (Jones) as beta -> 0;
    # AR = 2 s^2 / A = 0.18 / 0.1275 = 1.411765: pi AR / 2 * A / S = 4.591837 per fin
    fins, s_ref = FinSet(**FINS), math.pi * 0.14 ** 2
    assert fin_normal_slope(fins, 0.14, s_ref, 1.0)[1] == pytest.approx(4.591837, rel=1e-6)
    below = fin_normal_slope(fins, 0.14, s_ref, 0.99999)[0]
    above = fin_normal_slope(fins, 0.14, s_ref, 1.00001)[0]
    assert below == pytest.approx(above, rel=1e-4)
    # Ackeret rectangular wing at M 2 (beta AR = 2.445 > 1.863): 4/beta (1 - 1/(2 beta AR))
    beta = math.sqrt(3.0)
    expected = 4.0 / beta * (1.0 - 0.5 / (beta * 1.411765)) * 0.1275 / s_ref
    assert fin_normal_slope(fins, 0.14, s_ref, 2.0)[1] == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("shape, k", [("cone", 2.0 / 3.0), ("von_karman", 0.5)])
def test_nose_cp_of_slender_body_theory(shape, k):
    # nose alone: CNa = 2, CP at L - V / A_base: 2/3 L for the cone, L/2 for von Karman
    nose = BarrowmanAero(nose={"shape": shape, "length": 1.2}, body={"diameter": 0.3, "length": 2.0})
    assert nose.cn_alpha(0.3) == pytest.approx(2.0)
    assert nose.x_cp(0.3) == pytest.approx(-k * 1.2, rel=1e-12)


def test_boat_tail_slope_and_cp():
    # conical transition d 0.28 -> 0.22 over 0.3 m from station -7.4: CNa = 2 ((0.22/0.28)^2 - 1)
    # = -0.765306; CP at the centroid of dA/dx (slender-body theory), by quadrature of x r r'
    r = lambda x: 0.14 - 0.03 * x / 0.3                    # noqa: E731, x behind the tail's top
    centroid = quad(lambda x: x * r(x), 0.0, 0.3)[0] / quad(r, 0.0, 0.3)[0]
    cna, x_cp = BarrowmanAero(**GEOMETRY).components(0.3)["boat_tail"]
    assert cna == pytest.approx(-0.765306, rel=1e-6)
    assert x_cp == pytest.approx(-7.4 - centroid, rel=1e-12)


def test_tangent_ogive_cp_from_its_volume():
    # ogive L 1, R 0.1: rho = (0.01 + 1) / 0.2 = 5.05; profile r = sqrt(rho^2 - (L - x)^2) + R - rho
    # (Crowell 1996); volume by quadrature of pi r^2: 0.0168030 m^3; CP = L - V / (pi R^2) = 0.465145 m
    rho = 5.05
    vol = quad(lambda x: math.pi * (math.sqrt(rho ** 2 - (1.0 - x) ** 2) + 0.1 - rho) ** 2, 0.0, 1.0)[0]
    nose = BarrowmanAero(nose={"shape": "ogive", "length": 1.0}, body={"diameter": 0.2, "length": 1.0})
    assert nose.x_cp(0.0) == pytest.approx(-(1.0 - vol / (math.pi * 0.01)), rel=1e-10)
    assert nose.x_cp(0.0) == pytest.approx(-0.465145, abs=1e-6)


def test_slender_body_wave_drag():
    # von Karman ogive: D/q = 4 S_b^2 / (pi L^2), i.e. C_D = 4 (R/L)^2 = 0.04 for R/L = 0.1
    assert slender_body_wave_drag("von_karman", 1.0, 0.1) == pytest.approx(0.04, rel=1e-3)
    # it is the minimum-drag nose of given length and base: the tangent ogive has more
    assert slender_body_wave_drag("ogive", 1.0, 0.1) > 0.04


def test_drag_terms_by_hand():
    cone = BarrowmanAero(nose={"shape": "cone", "length": 1.0}, body={"diameter": 0.2, "length": 4.0})
    # wetted area: cone pi R sqrt(R^2 + L^2) = 0.315730 + cylinder pi d L = 2.513274 -> 2.829004 m^2;
    # Re = 7e6 / m * 5 m = 3.5e7: 0.455 / log10(Re)^2.58 = 0.0024759 < roughness limit
    # 0.032 (20e-6 / 5)^0.2 = 0.0026646; form factor 1 + 1/(2 * 25) = 1.02; S = 0.0314159 m^2
    wet = math.pi * 0.1 * math.hypot(0.1, 1.0) + math.pi * 0.2 * 4.0
    cf = max(0.455 / math.log10(3.5e7) ** 2.58, 0.032 * (20e-6 / 5.0) ** 0.2)
    d0 = cone.drag(0.0)
    assert d0["friction"] == pytest.approx(cf * 1.02 * wet / (math.pi * 0.01), rel=1e-5)
    assert d0["friction"] == pytest.approx(0.24471, rel=1e-4)
    assert d0["base"] == pytest.approx(0.12) and d0["nose_wave"] == 0.0
    # M 2: friction x (1 + 0.6)^-0.58, base 0.25 / 2, cone wave 2.1 sin^2(phi) + 0.5 sin(phi)/sqrt(3)
    d2 = cone.drag(2.0)
    phi = math.atan(0.1)
    sp = math.sin(phi)
    assert d2["nose_wave"] == pytest.approx(2.1 * sp * sp + 0.5 * sp / math.sqrt(3.0))
    assert d2["friction"] == pytest.approx(d0["friction"] * 1.6 ** -0.58)
    assert d2["base"] == pytest.approx(0.125)
    assert base_drag(0.5) == pytest.approx(0.1525)
    assert cone.coefficients(2.0, 0.0)["CA"] == pytest.approx(d2["total"])


def test_fin_wave_drag_and_transonic_ramp(vehicle):
    # Ackeret double wedge per fin area at M 3: 4 (t/c)^2 / sqrt(8), t/c = 0.006 / MAC
    fins = vehicle.fins[0]
    expected = 4.0 * (0.006 / fins.mac) ** 2 / math.sqrt(8.0) * 4 * fins.area / vehicle.s_ref
    assert vehicle.drag(3.0)["fin_wave"] == pytest.approx(expected)
    assert vehicle.drag(0.8)["nose_wave"] == 0.0
    # halfway up the ramp (M 1.0) the smoothstep is 1/2 of the M 1.2 value
    assert vehicle.drag(1.0)["fin_wave"] == pytest.approx(0.5 * vehicle.drag(1.2)["fin_wave"])


def test_tables_are_consistent_with_the_components(vehicle):
    assert isinstance(vehicle, AxisymmetricAero)
    assert np.all(np.isfinite(vehicle.table))
    m = 0.4                                               # a grid Mach number
    h = math.radians(0.05)                                # first alpha step of the default grid
    cn = vehicle.coefficients(m, h)["CN"]
    # CNa sin h cos h + Galejs K (A_plan + (n/2) A_fin) / S sin^2 h, K = 1.1, n/2 = 2; the body
    # planform area is integrated from the model's own profile (radius against distance)
    plan = float(np.trapezoid(2.0 * vehicle._r, vehicle._xi))
    expected = (vehicle.cn_alpha(m) * math.sin(h) * math.cos(h)
                + 1.1 * (plan + 2.0 * vehicle.fins[0].area) / vehicle.s_ref * math.sin(h) ** 2)
    assert cn == pytest.approx(expected, rel=1e-9)
    # pitching moment: about x_ref the linear part is -CNa (x_ref - x_cp) / d per rad
    cm_lin = vehicle.coefficients(m, h)["Cm"] / h
    assert cm_lin == pytest.approx(vehicle.cn_alpha(m) * (vehicle.x_cp(m) + 4.0) / 0.28, rel=5e-3)
    assert vehicle.coefficients(m, 0.0)["CN"] == 0.0
    assert np.all(vehicle.table[:, 3] < 0.0) and np.all(vehicle.table[:, 4] < 0.0)   # Cmq, Clp
    # at 90 deg a finned body is still stable: Cm < 0 about the mid-length
    assert vehicle.coefficients(0.3, math.pi / 2)["Cm"] < 0.0


def test_strips_keep_total_and_centre_of_pressure(vehicle):
    for mach in (0.3, 2.0):
        x, width, cna = vehicle.strips(mach, 200)
        assert cna.sum() == pytest.approx(vehicle.cn_alpha(mach), rel=1e-12)
        assert np.all(width > 0.0) and x[0] < 0.0 and x[-1] > -vehicle.length
        assert np.sum(cna * x) / cna.sum() == pytest.approx(vehicle.x_cp(mach), abs=1e-3)


def test_damping_by_hand():
    # roll damping of one fin set alone: -2 n CNa_1 int c(r) r^2 dr / (A_fin d^2);
    # rectangular fins c 0.2, R 0.05, s 0.1: int = 0.2 (0.15^3 - 0.05^3) / 3 = 2.1667e-4 m^4
    body = {"diameter": 0.1, "length": 1.0}
    fins = {"count": 3, "root_chord": 0.2, "tip_chord": 0.2, "span": 0.1, "sweep": 0.0, "station": -1.0}
    v = BarrowmanAero(nose={"shape": "cone", "length": 0.3}, body=body, fins=fins)
    single = fin_normal_slope(v.fins[0], 0.05, v.s_ref, 0.4)[1]
    expected = -2.0 * 3 * single * (0.2 * (0.15 ** 3 - 0.05 ** 3) / 3.0) / (0.02 * 0.01)
    assert v.coefficients(0.4, 0.0)["Clp"] == pytest.approx(expected, rel=1e-9)


def test_registry_and_bad_geometry():
    model = make("aerodynamics", {"model": "barrowman", **GEOMETRY})
    assert isinstance(model, AxisymmetricAero) and model.ref_length == pytest.approx(0.28)
    bad = [({"nose": {"shape": "parabolic", "length": 1.0}}, "nose.shape = 'parabolic'"),
           ({"body": {"diameter": -0.2, "length": 5.0}}, "body.diameter = -0.2"),
           ({"fins": FINS | {"count": 2}}, r"fins\[0\].count = 2"),
           ({"fins": FINS | {"station": -7.5}}, r"fins\[0\].station = -7.5"),
           ({"fins": FINS | {"chord": 1.0}}, r"fins\[0\].chord"),
           ({"boat_tail": {"length": 0.3, "aft_diameter": 0.28}}, "boat_tail.aft_diameter"),
           ({"x_ref": 1.0}, "x_ref = 1.0")]
    for change, pattern in bad:
        with pytest.raises(ConfigError, match=pattern):
            BarrowmanAero(**(GEOMETRY | change))
    assert set(NOSE_SHAPES) == {"cone", "ogive", "von_karman"}


def test_pitch_damping_moved_to_the_cg_matches_strip_theory_about_the_cg():
    """The generator's Cmq is strip theory about x_ref; the kernel moves it to the CG with the table's
    static slopes. Built about the CG directly, strip theory must give the same damping (up to the
    table's slope at its first angle, 0.25 deg, against the true CN_alpha)."""
    from lvgym.vehicle import load_vehicle

    geometry = dict(load_vehicle("stratos3").aerodynamics)
    geometry.pop("model")
    x_cg = -5.12
    about_ref = BarrowmanAero(**geometry, x_ref=-4.1)
    about_cg = BarrowmanAero(**geometry, x_ref=x_cg)
    v = np.array([136.0, 0.0, 0.0])                     # M 0.4 at sea level, no incidence
    for rates in ([0.0, 0.3, 0.0], [0.0, 0.0, -0.2]):
        _, m_ref, _ = about_ref.loads(v, rates, 1.225, 340.0, x_cg)
        _, m_cg, _ = about_cg.loads(v, rates, 1.225, 340.0, x_cg)
        assert m_ref == pytest.approx(m_cg, rel=5e-3, abs=1e-9)   # measured: 3e-4
        assert np.dot(m_cg, rates) < 0.0               # damping opposes the rate
