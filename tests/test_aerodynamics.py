"""Aerodynamic coefficient tables and loads (lvgym/environment/aerodynamics.py).

Hand numbers are computed in the comments from the conventions of the module docstring
(f_b = qbar S (-CA, CY, -CN), Cm positive nose-up about x_ref, moved to the CG by
m_cg = m_ref + (x_ref - x_cg) e_x x f_b; damping rho V S L^2 / 4 * (Clp p, Cmq q, Cnr r)).
"""

import math

import numpy as np
import pytest

from lvgym.environment import make
from lvgym.environment.aerodynamics import AxisymmetricAero, Tables6Aero
from lvgym.errors import ConfigError

# mach, alpha_deg, CA, CN, Cm, Cmq, Clp: two Mach numbers, alpha_t 0, 4, 8, 180 deg
ROWS = """mach,alpha_deg,CA,CN,Cm,Cmq,Clp
0.5,0,0.40,0,0,-30,-2
0.5,4,0.42,0.40,-0.60,-30,-2
0.5,8,0.45,0.85,-1.30,-30,-2
0.5,180,-0.40,0,0,-30,-2
1.5,0,0.60,0,0,-40,-3
1.5,4,0.62,0.50,-0.80,-40,-3
1.5,8,0.66,1.00,-1.60,-40,-3
1.5,180,-0.60,0,0,-40,-3
"""
S, L, X_REF = 0.2, 0.5, -1.0


@pytest.fixture
def csv_path(tmp_path):
    path = tmp_path / "aero_test.csv"
    path.write_text("# test table\n" + ROWS)
    return path


@pytest.fixture
def model(csv_path):
    return AxisymmetricAero(csv_path, ref_area=S, ref_length=L, x_ref=X_REF)


def flow(speed, alpha_t_deg, phi_deg):
    """v_air_b for a total angle of attack and roll orientation phi_a = atan2(v, w)."""
    at, ph = math.radians(alpha_t_deg), math.radians(phi_deg)
    return np.array([speed * math.cos(at), speed * math.sin(at) * math.sin(ph),
                     speed * math.sin(at) * math.cos(ph)])


def roll(psi):
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def test_hand_numbers_at_a_table_point(model):
    # M 0.5 (V 170 m/s, a 340 m/s), alpha_t 4 deg, phi_a 30 deg, rho 1: qbar 14450 Pa, qS 2890 N,
    # qSL 1445 N m. CA 0.42 -> fx -1213.8 N; CN 0.40 -> 1156 N against the crossflow:
    # fy -1156 sin30 = -578 N, fz -1156 cos30 = -1001.1345 N. Cm -0.60 -> -867 N m about the axis
    # (0, cos30, -sin30): (0, -750.8435, 433.5). CG at -1.5: d = x_ref - x_cg = 0.5,
    # my += -d fz = +500.5673, mz += d fy = -289. Damping kd = 0.25 * 1 * 170 * 0.2 * 0.25 = 2.125:
    # p 0.1 -> Clp -2: -0.425. Cmq -30 is about x_ref; about the CG (D/L = 0.5 / 0.5 = 1) it is
    # -30 - 4 Cm_a - 2 CN_a with the slopes at 4 deg: Cm_a = -0.60 / a4, CN_a = 0.40 / a4 -> -7.0817;
    # q 0.2 -> -3.0097, r -0.05 -> +0.7524.
    f, m, st = model.loads(flow(170.0, 4.0, 30.0), [0.1, 0.2, -0.05], 1.0, 340.0, -1.5)
    c30 = math.sqrt(3.0) / 2.0
    a4 = math.radians(4.0)
    cmq = -30.0 - 4.0 * (-0.60 / a4) - 2.0 * (0.40 / a4)
    assert f == pytest.approx([-1213.8, -578.0, -1156.0 * c30], rel=1e-12)
    assert m == pytest.approx([-0.425, -867 * c30 + 578 * c30 + 2.125 * cmq * 0.2,
                               433.5 - 289.0 + 2.125 * cmq * -0.05], rel=1e-12)
    assert cmq == pytest.approx(-7.0817, abs=1e-4)
    assert st.mach == pytest.approx(0.5) and st.qbar == pytest.approx(14450.0)
    assert st.alpha_total == pytest.approx(math.radians(4.0))
    assert st.phi_aero == pytest.approx(math.radians(30.0))
    assert st.airspeed == pytest.approx(170.0)


def test_interpolation_is_multilinear_between_grid_points(model):
    # midway in Mach (1.0) and in alpha (6 deg): mean of the four corners
    c = model.coefficients(1.0, math.radians(6.0))
    assert c["CN"] == pytest.approx((0.40 + 0.85 + 0.50 + 1.00) / 4)
    assert c["Cm"] == pytest.approx((-0.60 - 1.30 - 0.80 - 1.60) / 4)
    assert c["Cmq"] == pytest.approx(-35.0)
    # clamped outside the grid: Mach 3 gives the Mach 1.5 row
    assert model.coefficients(3.0, math.radians(4.0))["CA"] == pytest.approx(0.62)


def test_flow_angles_of_the_state(model):
    v = np.array([100.0, 20.0, 30.0])
    _, _, st = model.loads(v, np.zeros(3), 1.2, 300.0, -1.0)
    assert st.alpha == pytest.approx(math.atan2(30.0, 100.0))
    assert st.beta == pytest.approx(math.asin(20.0 / np.linalg.norm(v)))
    assert st.alpha_total == pytest.approx(math.acos(100.0 / np.linalg.norm(v)))
    assert st.phi_aero == pytest.approx(math.atan2(20.0, 30.0))


@pytest.mark.parametrize("psi_deg", [17.0, 90.0, 145.0, -60.0])
def test_roll_orientation_of_the_crossflow(model, psi_deg):
    # turning the flow about x_b turns force and moment with it (axial symmetry)
    R = roll(math.radians(psi_deg))
    v, w = flow(200.0, 6.0, 10.0), np.array([0.3, 0.1, -0.2])
    f0, m0, _ = model.loads(v, w, 1.1, 340.0, -1.7)
    f1, m1, st = model.loads(R @ v, R @ w, 1.1, 340.0, -1.7)
    np.testing.assert_allclose(f1, R @ f0, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(m1, R @ m0, rtol=1e-12, atol=1e-9)
    assert st.alpha_total == pytest.approx(math.radians(6.0))


def test_moment_sign_follows_cg_and_cp(model):
    # CP of the table at 4 deg, M 0.5: x_cp = x_ref + Cm L / CN = -1 + (-0.6)(0.5)/0.4 = -1.75 m
    v_alpha, v_beta = flow(170.0, 4.0, 0.0), flow(170.0, 4.0, 90.0)
    for x_cg, stable in ((-1.2, True), (-2.3, False)):
        f, m, _ = model.loads(v_alpha, np.zeros(3), 1.0, 340.0, x_cg)
        assert f[2] < 0.0                               # normal force against +w
        assert (m[1] < 0.0) == stable                   # nose-down when the CG is ahead of the CP
        f, m, _ = model.loads(v_beta, np.zeros(3), 1.0, 340.0, x_cg)
        assert f[1] < 0.0
        assert (m[2] > 0.0) == stable                   # weathercock: nose turns into +v
    # at the CP the moment vanishes
    _, m, _ = model.loads(v_alpha, np.zeros(3), 1.0, 340.0, -1.75)
    assert abs(m[1]) < 1e-9


def test_damping_opposes_the_rates(model):
    _, m0, _ = model.loads(flow(170.0, 0.0, 0.0), np.zeros(3), 1.0, 340.0, -1.0)
    _, m1, _ = model.loads(flow(170.0, 0.0, 0.0), [0.5, 0.5, 0.5], 1.0, 340.0, -1.0)
    assert np.all(m0 == 0.0) and np.all(m1 < 0.0)


def test_zero_airspeed_gives_zero_loads(model):
    f, m, st = model.loads(np.zeros(3), [1.0, -2.0, 3.0], 1.225, 340.0, -1.0)
    assert np.all(f == 0.0) and np.all(m == 0.0)
    assert all(np.isfinite(getattr(st, k)) for k in ("alpha", "beta", "alpha_total", "phi_aero", "mach"))
    assert st.qbar == 0.0


def test_ninety_degrees_angle_of_attack(model):
    # u = 0, w = 50: alpha = alpha_t = 90 deg, interpolated between 8 and 180 deg at M 0.147
    f, m, st = model.loads(np.array([0.0, 0.0, 50.0]), np.zeros(3), 1.0, 340.0, -1.0)
    assert np.all(np.isfinite(f)) and np.all(np.isfinite(m))
    assert st.alpha == pytest.approx(math.pi / 2) and st.alpha_total == pytest.approx(math.pi / 2)
    cn = 0.85 * (180 - 90) / (180 - 8)                 # linear between 8 deg (0.85) and 180 deg (0)
    assert f[2] == pytest.approx(-0.5 * 2500.0 * S * cn)


def test_batch_equals_single(model):
    rng = np.random.default_rng(7)
    v = rng.normal(0.0, 150.0, (6, 3))
    w = rng.normal(0.0, 0.3, (6, 3))
    rho, a, xcg = rng.uniform(0.1, 1.2, 6), rng.uniform(290, 340, 6), rng.uniform(-2, -0.5, 6)
    f, m, st = model.loads(v, w, rho, a, xcg)
    assert f.shape == (6, 3) and st.mach.shape == (6,)
    for j in range(6):
        fj, mj, sj = model.loads(v[j], w[j], rho[j], a[j], xcg[j])
        np.testing.assert_array_equal(f[j], fj)
        np.testing.assert_array_equal(m[j], mj)
        assert sj.qbar == st.qbar[j]


def test_tables6_from_axisymmetric_reproduces_loads_at_grid_nodes(model):
    t6 = model.to_tables6(np.arange(-20.0, 20.1, 4.0), np.arange(-12.0, 12.1, 4.0))
    for a_deg, b_deg in ((8.0, 0.0), (4.0, -4.0), (-12.0, 8.0)):
        a, b = math.radians(a_deg), math.radians(b_deg)
        v = 250.0 * np.array([math.cos(a) * math.cos(b), math.sin(b), math.sin(a) * math.cos(b)])
        w = np.array([0.1, -0.2, 0.3])
        # damping at the moment reference (tables6 uses its derivatives as tabulated, the axisymmetric
        # model moves them to the CG) and the static moment moved to another CG
        for rates, x_cg in ((w, X_REF), (np.zeros(3), -1.4)):
            f6, m6, s6 = t6.loads(v, rates, 0.9, 340.0, x_cg)
            f3, m3, s3 = model.loads(v, rates, 0.9, 340.0, x_cg)
            np.testing.assert_allclose(f6, f3, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(m6, m3, rtol=1e-9, atol=1e-9)
        assert s6.alpha == pytest.approx(a) and s6.beta == pytest.approx(b)


def test_tables6_hand_numbers_with_altitude(tmp_path):
    # CY 0.3 gives +y force (f_y = qS CY); CA 0.5 at 0 m and 0.3 at 10 km: 0.4 at 5 km
    lines = ["mach,alpha_deg,beta_deg,alt_m,CA,CY,CN,Cl,Cm,Cn"]
    for m in (0.0, 2.0):
        for a in (-10, 10):
            for b in (-10, 10):
                for h, ca in ((0, 0.5), (10000, 0.3)):
                    lines.append(f"{m},{a},{b},{h},{ca},0.3,0.1,0.01,-0.2,0.05")
    path = tmp_path / "aero6.csv"
    path.write_text("\n".join(lines) + "\n")
    t6 = Tables6Aero(path, ref_area=1.0, ref_length=2.0, x_ref=-3.0, cnr=-5.0)
    # V 100 along x, rho 1: qbar 5000 Pa, qS 5000 N, qSL 10000 N m; CG at x_ref: no transfer
    f, m, _ = t6.loads(np.array([100.0, 0.0, 0.0]), [0.0, 0.0, 0.1], 1.0, 340.0, -3.0, altitude=5000.0)
    assert f == pytest.approx([-2000.0, 1500.0, -500.0])
    # Cnr -5, r 0.1: kd = 0.25 * 1 * 100 * 1 * 4 = 100 -> -50 N m
    assert m == pytest.approx([100.0, -2000.0, 500.0 - 50.0])


def test_registry_builds_the_models(csv_path):
    model = make("aerodynamics", {"model": "axisymmetric", "table": str(csv_path), "ref_area": S,
                                  "ref_length": L, "x_ref": X_REF})
    assert isinstance(model, AxisymmetricAero)
    with pytest.raises(ConfigError, match="aerodynamics.area"):
        make("aerodynamics", {"model": "axisymmetric", "table": str(csv_path), "area": 1.0,
                              "ref_length": L})


def drop_column(text, name):
    rows = [line.split(",") for line in text.splitlines()]
    j = rows[0].index(name)
    return "\n".join(",".join(r[:j] + r[j + 1:]) for r in rows) + "\n"


def _write(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    return path


@pytest.mark.parametrize("edit, pattern", [
    (lambda t: t.replace(",Cm,", ",Cx,"), r"bad.csv: column 'Cx' = 'Cx'"),
    (lambda t: drop_column(t, "Cm"), "column 'Cm' = <missing>: required"),
    (lambda t: t.replace("0.85", "abc"), r"bad.csv: line 4, column 'CN' = 'abc': a finite number"),
    (lambda t: t.replace("0.42", "nan"), r"line 3, column 'CA' = 'nan'"),
    (lambda t: "# two\n# comments\n" + t.replace("0.85", "abc"), r"line 6, column 'CN' = 'abc'"),
    (lambda t: "\n".join(t.splitlines()[:-1]) + "\n", r"rows = 7: a full grid"),
    (lambda t: t.replace("0.5,0,0.40,0,0", "0.5,0,0.40,0.01,0"), r"column 'CN' at alpha_deg = 0 = 0.01"),
    (lambda t: t.replace(",0,0.40,", ",1,0.40,").replace(",0,0.60,", ",1,0.60,"), "column 'alpha_deg'"),
])
def test_bad_csv_files_name_file_column_and_value(tmp_path, edit, pattern):
    with pytest.raises(ConfigError, match=pattern):
        AxisymmetricAero(_write(tmp_path, edit(ROWS)), ref_area=S, ref_length=L)


def test_bad_options(csv_path, tmp_path):
    with pytest.raises(ConfigError, match="ref_area = -1.0: a reference area"):
        AxisymmetricAero(csv_path, ref_area=-1.0, ref_length=L)
    with pytest.raises(ConfigError, match="x_ref = 0.5"):
        AxisymmetricAero(csv_path, ref_area=S, ref_length=L, x_ref=0.5)
    with pytest.raises(ConfigError, match="cmq = -3.0: given both"):
        AxisymmetricAero(csv_path, ref_area=S, ref_length=L, cmq=-3.0)
    with pytest.raises(ConfigError, match="table = "):
        AxisymmetricAero(tmp_path / "absent.csv", ref_area=S, ref_length=L)
    lines = ["mach,alpha_deg,beta_deg,CA,CY,CN,Cl,Cm,Cn"] + [f"0,{a},{b},0,0,0,0,0,0" for a in (0, 5)
                                                            for b in (0, 95)]
    with pytest.raises(ConfigError, match="column 'beta_deg'"):
        Tables6Aero(_write(tmp_path, "\n".join(lines)), ref_area=1.0, ref_length=1.0)


def test_shipped_example_table_loads():
    from pathlib import Path

    import lvgym.environment.aerodynamics as aero
    path = Path(aero.__file__).with_name("data") / "aero_example_sounding_rocket.csv"
    model = AxisymmetricAero(path, ref_area=math.pi * 0.14 ** 2, ref_length=0.28, x_ref=-4.1)
    c = model.coefficients(0.5, 0.0)
    assert 0.2 < c["CA"] < 1.0 and c["Cmq"] < 0.0
