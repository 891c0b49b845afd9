"""A vehicle known by its tables over flight time (the vehicle file's ``tables``, lvgym/vehicle/timetables.py,
applied by lvgym/simulator/tabled.py): the timeline between rows is the tables' linear interpolation, the
rigid body B and the pendulums add up to the table's stack, jumps at a separation, the flight model's and the
linear plant's bending frequency are the table's, a gimbal slope scales the shape, every bad value names
the file, line, key, value and what is allowed, and the made-up vehicle flies in the env."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import lvgym
from lvgym.errors import ConfigError
from lvgym.simulator.tabulate import build_timeline
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.massmodel import body_minus_pendulums, combine
from lvgym.vehicle.timetables import TimeTable, snap_jumps

ROOT = Path(__file__).resolve().parents[1]
#: the Kestrel of docs/own-launcher.md (one stage, two slosh tanks, two modes, 118 s burn)
KESTREL = re.findall(r"```yaml\n(.*?)```", (ROOT / "docs" / "own-launcher.md").read_text(encoding="utf-8"), re.DOTALL)[0]
#: "published" numbers: the mass drop is what Kestrel's engine burns (936 kg by 60 s, 1825 kg by 117 s)
MASS = "[[0, 2250, -5.6, 33, 17000], [60, 1314, -6.4, 31, 10500], [117, 425, -6.4, 29.5, 7800], " \
       "[130, 413, -6.35, 29.5, 7750]]"
MODE1 = "[[0, 9.0, 0.02], [60, 10.0, 0.02], [130, 13.0, 0.03]]"


def _write(tmp_path: Path, tables: str, name: str = "kestrel_tables.yaml", base: str = KESTREL) -> Path:
    path = tmp_path / name
    path.write_text(base + "tables:\n" + tables, encoding="utf-8")
    return path


@pytest.fixture
def kestrel_tables(tmp_path) -> Path:
    return _write(tmp_path, f"  mass_properties: {MASS}\n  modes:\n    - table: {MODE1}\n")


@pytest.mark.parametrize("model", ["rigid", "nonrigid"])
def test_the_timeline_between_rows_is_the_tables_interpolation(kestrel_tables, model):
    tl = build_timeline(MassModel(load_vehicle(kestrel_tables)), model, 70.0, cache=False)
    t = [30.0, 45.0]                       # between the rows at 0 and 60 s: w = 0.5 and 0.75
    np.testing.assert_allclose(tl.interp("mass", t), [1782.0, 1548.0], rtol=1e-12)
    np.testing.assert_allclose(tl.interp("cg", t)[:, 0], [-6.0, -6.2], rtol=1e-12)
    np.testing.assert_allclose(tl.interp("cg", t)[:, 1:], 0.0)
    J = tl.interp("inertia", t)
    np.testing.assert_allclose(np.diagonal(J, axis1=1, axis2=2), [[32.0, 13750.0, 13750.0], [31.5, 12125.0, 12125.0]],
                               rtol=1e-12)
    assert np.count_nonzero(J - np.diagonal(J, axis1=1, axis2=2)[:, :, None] * np.eye(3)) == 0
    p, lay = tl.params_at([30.0])[0], tl.dynamics.layout
    if model == "rigid":                   # B is the stack
        assert p[lay.params["m_b"]][0] == 1782.0
        np.testing.assert_allclose(p[lay.params["J_b"]].reshape(3, 3)[1, 1], 13750.0, rtol=1e-12)
    else:                                  # B + the pendulums = the table's stack
        m_s = sum(p[lay.slosh_param(j, "m")][0] for j in range(lay.n_slosh))
        assert m_s > 50.0
        np.testing.assert_allclose(p[lay.params["m_b"]][0] + m_s, 1782.0, rtol=1e-12)
        # the first mode flies at the table's frequency and damping (held at the row in force)
        np.testing.assert_allclose(p[lay.params["omega_modes"]][0], 2 * np.pi * 9.5, rtol=1e-12)
        np.testing.assert_allclose(p[lay.params["zeta_modes"]][0], 0.02, rtol=1e-12)
        assert p[lay.params["zeta_modes"]][1] == 0.01        # the second mode stays the beam's


def test_body_and_pendulums_add_up_to_the_stack():
    t = np.array([1.0, 2.0])
    mass, cg = np.array([1000.0, 900.0]), np.array([[-5.0, 0, 0], [-5.5, 0, 0]])
    J = np.array([np.diag([30.0, 9000.0, 9100.0]), np.diag([28.0, 8000.0, 8000.0])])
    m_s, rest = np.array([[40.0, 20.0], [30.0, 0.0]]), np.array([[[-3.0, 0, 0], [-7.0, 0, 0]]] * 2)
    m_b, r_b, J_b = body_minus_pendulums(t, mass, cg, J, m_s, rest, "tables.mass_properties", "x.yaml")
    for b in range(2):
        back = combine([(m_b[b], r_b[b], J_b[b])] + [(m_s[b, j], rest[b, j], np.zeros((3, 3))) for j in range(2)])
        np.testing.assert_allclose(back[0], mass[b], rtol=1e-13)
        np.testing.assert_allclose(back[1], cg[b], atol=1e-12)
        np.testing.assert_allclose(back[2], J[b], atol=1e-8)
    # hand numbers: 940 kg at (-5000 + 120 + 140) / 940
    np.testing.assert_allclose(r_b[0, 0], -4740.0 / 940.0, rtol=1e-13)
    with pytest.raises(ConfigError, match=r"x\.yaml: tables\.mass_properties = 't = 1 s.*holds its slosh pendulums"):
        body_minus_pendulums(t, mass, cg, J, m_s * 30.0, rest, "tables.mass_properties", "x.yaml")


def test_a_jump_takes_the_row_before_and_after_and_moves_onto_the_separation():
    table = TimeTable("k", ("t", "v"), np.array([0.0, 10.0, 10.0, 20.0]), np.array([[4.0], [3.0], [1.0], [0.0]]))
    np.testing.assert_allclose(table.at([5.0, 10.0, 10.0, 15.0, 30.0, -1.0], [0, 1, 0, 0, 0, 0])[:, 0],
                               [3.5, 3.0, 1.0, 0.5, 0.0, 4.0])
    assert snap_jumps(table, [10.4]).t.tolist() == [0.0, 10.4, 10.4, 20.0]
    with pytest.raises(ConfigError, match=r"k\[1\] = \[10\.0, 3\.0\]: a jump .* within 1 s of a separation .*: 12\.000 s"):
        snap_jumps(table, [12.0])


def test_a_staged_vehicle_jumps_at_its_separation(tmp_path):
    """SMILE (three stages, separation at 44 s): the table's jump given at 44.3 s lands on the event, the
    timeline's row before it has the stack before, the row after it the upper stack."""
    smile = (Path(lvgym.__file__).parent / "vehicles" / "smile.yaml").read_text(encoding="utf-8")
    mm = MassModel(load_vehicle("smile"))
    rows = []
    for t, t_model in ((0.0, 0.0), (20.0, 20.0), (44.3, 43.99), (44.3, 44.0), (60.0, 60.0)):
        state, _ = mm.advance(mm.initial_state(), t_model)
        p = mm.properties(state)
        rows.append([t, float(p.mass), float(p.cg[0]), *np.diag(p.inertia)])
    path = _write(tmp_path, f"  mass_properties: {np.round(rows, 6).tolist()}\n", "smile_tables.yaml", smile + "\n")
    tl = build_timeline(MassModel(load_vehicle(path)), "rigid", 50.0, cache=False)
    at = np.flatnonzero(tl.t == 44.0)
    assert at.size == 2
    np.testing.assert_allclose(tl.mass[at], [rows[2][1], rows[3][1]], rtol=1e-9)
    assert rows[2][1] - rows[3][1] > 100.0                                  # the first stage's dry mass
    np.testing.assert_allclose(tl.interp("mass", [48.0]), 0.75 * rows[3][1] + 0.25 * rows[4][1], rtol=1e-9)


def test_the_flight_model_and_the_linear_plant_have_the_tables_frequency(kestrel_tables):
    from lvgym.baselines.design.linearize import linearize, operating_point

    op = operating_point(str(kestrel_tables), 10.0, "nonrigid", protocol="v1")
    hz = 9.0 + 10.0 / 60.0                                                  # the table at 10 s
    omega = op.p[op.sim.layout.params["omega_modes"]]
    # held at the timeline's row in force: at most one row (0.05 s) of the table's 1/60 Hz/s behind
    assert hz - 0.05 / 60.0 - 1e-12 <= omega[0] / (2 * np.pi) <= hz + 1e-12
    plant = linearize(op=op)
    poles = sorted(w / (2 * np.pi) for w in plant.poles().imag if w > 0)
    nearest = min(poles, key=lambda f: abs(f - hz))
    assert abs(nearest - hz) < 0.01 * hz, poles                            # coupled to the rest: within 1 %


def test_a_gimbal_slope_scales_the_beams_shape(tmp_path):
    plain = build_timeline(MassModel(load_vehicle(_write(tmp_path, f"  modes:\n    - table: {MODE1}\n", "a.yaml"))),
                           "flex", 20.0, sensor_stations=[-3.0], cache=False)
    slope = "[[0, 9.0, 0.02, 0.05], [60, 10.0, 0.02, 0.07]]"
    scaled = build_timeline(MassModel(load_vehicle(_write(tmp_path, f"  modes:\n    - table: {slope}\n", "b.yaml"))),
                            "flex", 20.0, sensor_stations=[-3.0], cache=False)
    lay = plain.dynamics.layout
    p0, p1 = plain.params_at([15.0])[0], scaled.params_at([15.0])[0]
    want = 0.05 + 0.02 * 15.0 / 60.0
    np.testing.assert_allclose(p1[lay.params["dphi_gimbal"]][0], want, rtol=1e-12)
    factor = want / p0[lay.params["dphi_gimbal"]][0]
    np.testing.assert_allclose(p1[lay.params["phi_gimbal"]][0], factor * p0[lay.params["phi_gimbal"]][0], rtol=1e-12)
    i = np.flatnonzero(plain.t == 15.0)[0]
    np.testing.assert_allclose(scaled.dphi_sensor[i, 0, 0], factor * plain.dphi_sensor[i, 0, 0], rtol=1e-12)
    np.testing.assert_allclose(p1[lay.params["phi_gimbal"]][1], p0[lay.params["phi_gimbal"]][1])   # mode 2: the beam's


def test_a_csv_beside_the_file(tmp_path):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "mass.csv").write_text("# Kestrel, published\nt,mass,cg,Ixx,Iyy,Izz\n0,2250,-5.6,33,17000,17010\n"
                                                "60,1314,-6.4,31,10500,10510\n", encoding="utf-8")
    (tmp_path / "data" / "mode1.csv").write_text("t,hz,zeta\n0,9,0.02\n60,10,0.02\n", encoding="utf-8")
    v = load_vehicle(_write(tmp_path, "  mass_properties: data/mass.csv\n  modes:\n    - table: data/mode1.csv\n"))
    m = v.tables.mass_properties
    assert m.source == "mass.csv" and m.lines == (3, 4) and m.values[1].tolist() == [1314, -6.4, 31, 10500, 10510]
    assert v.tables.modes[0].columns == ("t", "hz", "zeta")
    (tmp_path / "data" / "mass.csv").write_text("t,mass,cg,Ixx,Iyy\n0,2250,-5.6,33,17000\n60,-3,-6.4,31,10500\n",
                                                encoding="utf-8")
    with pytest.raises(ConfigError, match=r"^mass\.csv, line 3: tables\.mass_properties\[1\] = \[60\.0, -3\.0, .*\]: "
                                          r"a mass in \(0, 1e\+08\] kg"):
        load_vehicle(tmp_path / "kestrel_tables.yaml")


@pytest.mark.parametrize("tables, message", [
    ("  mass_properties: [[0, 2250, -5.6, 33, 17000], [60, 1314, -6.4]]\n",
     r"line \d+: tables\.mass_properties\[1\] = \[60, 1314, -6\.4\]: rows \[t, mass, cg, Ixx, Iyy\(, Izz\)\]"),
    ("  mass_properties: [[0, 2250, -5.6, 33, 17000], [60, 1314, -6.4, 31, 10500], [50, 1300, -6.4, 31, 10500]]\n",
     r"tables\.mass_properties\[2\] = \[50\.0, .*\]: times non-decreasing: 50 s comes after 60 s"),
    ("  mass_properties: [[0, -2250, -5.6, 33, 17000], [60, 1314, -6.4, 31, 10500]]\n",
     r"tables\.mass_properties\[0\] = \[0\.0, -2250\.0, .*\]: a mass in \(0, 1e\+08\] kg"),
    ("  mass_properties: [[0, 2250, -5.6, 33, 17000], [60, 2314, -6.4, 31, 10500]]\n",
     r"tables\.mass_properties\[1\] = .*: a mass that never increases"),
    ("  mass_properties: [[0, 2250, -5.6, 33, 17000], [60, 1614, -6.4, 31, 10500]]\n",
     r"tables\.mass_properties\[1\] = .*: a mass drop from 0 s to 60 s .* of 636 kg: the engines burn 936 kg"),
    (("  mass_properties: [[0, 2250, -5.6, 33, 17000], [30, 1800, -6, 31, 9000], [30, 1700, -6, 31, 9000], "
      "[60, 1214, -6.4, 31, 10500]]\n"), r"tables\.mass_properties\[1\] = \[30\.0, .*\]: a jump .* \(the vehicle's: none s\)"),
    ("  mass_properties: [[0, 2250, -15.6, 33, 17000], [60, 1314, -6.4, 31, 10500]]\n",
     r"tables\.mass_properties\[0\] = .*: a CG station on the vehicle: in \[-12, 0\] m"),
    ("  mass_properties: [[0, 2250, -5.6, 33, 17000], [60, 1314, -6.4, 30000, 10500]]\n",
     r"tables\.mass_properties\[1\] = .*: moments of inertia a body can have"),
    ("  mass_properties: kestrel_missing.csv\n",
     (r"kestrel_tables\.yaml, line \d+: tables\.mass_properties = '.*kestrel_missing\.csv': an existing, readable CSV "
      r"file \(relative to the vehicle file's folder; there is no such file\)")),
    ("  modes:\n    - table: [[0, 9.0, 1.5], [60, 10.0, 0.02]]\n",
     r"tables\.modes\[0\]\.table\[0\] = \[0\.0, 9\.0, 1\.5\]: a damping ratio in \[0, 1\]"),
    ("  modes:\n    - table: [[0, 9.0, 0.02]]\n", r"tables\.modes\[0\]\.table = 1: at least two rows"),
    (f"  modes:\n    - table: {MODE1}\n    - table: {MODE1}\n    - table: {MODE1}\n",
     r"tables\.modes = 3: at most structure\.n_modes = 2 mode tables"),
    ("  mass_propertys: []\n", r"tables\.mass_propertys = \[\]: unknown key; .*did you mean 'mass_properties'"),
])
def test_bad_tables_name_the_file_line_key_value_and_what_is_allowed(tmp_path, tables, message):
    with pytest.raises(ConfigError, match=r"^kestrel_tables\.yaml, line \d+: "):
        try:
            load_vehicle(_write(tmp_path, tables))
        except ConfigError as exc:
            assert re.search(message, str(exc)), str(exc)
            raise


def test_the_made_up_vehicle_flies_a_few_seconds_in_the_env(kestrel_tables):
    env = lvgym.make_env("smile-v2", model="nonrigid", vehicle=str(kestrel_tables), wind="none", randomize=[])
    obs, info = env.reset(seed=0)
    for _ in range(100):
        obs, _reward, terminated, truncated, info = env.step(np.zeros(2, np.float32))
        assert not (terminated or truncated), info.get("termination")
    assert np.all(np.isfinite(obs)) and info["time"] > 1.0
    env.close()


def test_an_imu_slope_scales_what_the_sensors_read(tmp_path):
    """The gimbal slope scales the dynamics' shape, the IMU slope what the gyro reads: at the IMU station the
    sensor slope is the table's, at another sensor station it keeps the beam's ratio to it."""
    rows = "[[0, 9.0, 0.02, 0.05, -0.02], [60, 10.0, 0.02, 0.07, -0.03]]"
    both = _write(tmp_path, f"  modes:\n    - table: {rows}\n      imu_station: -3.0\n", "c.yaml")
    plain = _write(tmp_path, f"  modes:\n    - table: {MODE1}\n", "a.yaml")
    tl, tl0 = (build_timeline(MassModel(load_vehicle(p)), "flex", 20.0, sensor_stations=[-3.0, -8.0], cache=False)
               for p in (both, plain))
    i = np.flatnonzero(tl.t == 15.0)[0]
    imu = -0.02 - 0.01 * 15.0 / 60.0
    np.testing.assert_allclose(tl.dphi_sensor[i, 0, 0], imu, rtol=1e-9)
    np.testing.assert_allclose(tl.dphi_sensor[i, 1, 0] / imu, tl0.dphi_sensor[i, 1, 0] / tl0.dphi_sensor[i, 0, 0],
                               rtol=1e-9)
    lay = tl.dynamics.layout
    np.testing.assert_allclose(tl.params_at([15.0])[0][lay.params["dphi_gimbal"]][0], 0.05 + 0.02 * 0.25, rtol=1e-12)
    with pytest.raises(ConfigError, match=r"tables\.modes\[0\]\.imu_station = None: a station \[m\] <= 0 with a "
                                          r"slope_imu column"):
        load_vehicle(_write(tmp_path, f"  modes:\n    - table: {rows}\n", "d.yaml"))


def test_the_design_information_follows_the_tables(kestrel_tables):
    from lvgym.vehicle.designinfo import design_parameters

    p = design_parameters(load_vehicle(kestrel_tables))
    assert p["mass_kg"] == 2250.0 and p["pitch_inertia_kgm2"] == 17000.0 and p["bending_hz"] == 9.0


def test_the_own_launcher_page_shows_the_tested_tables(tmp_path, kestrel_tables):
    page = (ROOT / "docs" / "own-launcher.md").read_text(encoding="utf-8")
    block = re.findall(r"## 8\. A vehicle known by its tables.*?```text\n(.*?)```", page, re.DOTALL)[0]
    path = tmp_path / "from_page.yaml"
    path.write_text(KESTREL + block, encoding="utf-8")
    shown, tested = load_vehicle(path).tables, load_vehicle(kestrel_tables).tables
    np.testing.assert_array_equal(shown.mass_properties.values, tested.mass_properties.values)
    np.testing.assert_array_equal(shown.modes[0].values, tested.modes[0].values)


def test_the_cut_off_goes_by_the_tables_frequency(tmp_path):
    path = _write(tmp_path, "  modes:\n    - table: [[0, 80.0, 0.02], [60, 80.0, 0.02]]\n")
    tl = build_timeline(MassModel(load_vehicle(path)), "flex", 5.0, mode_cutoff_hz=50.0, cache=False)
    p, lay = tl.params_at([2.0])[0], tl.dynamics.layout
    np.testing.assert_allclose(p[lay.params["omega_modes"]][0], 2 * np.pi * 80.0)
    assert p[lay.params["phi_gimbal"]][0] == 0.0 and p[lay.params["dphi_gimbal"]][0] == 0.0    # decoupled
    assert p[lay.params["phi_gimbal"]][1] != 0.0                                              # the beam's 25 Hz


def test_a_projected_change_of_basis_carries_the_slope_scale(tmp_path):
    slope = "[[0, 9.0, 0.02, 0.05], [60, 10.0, 0.02, 0.07]]"
    tls = [build_timeline(MassModel(load_vehicle(_write(tmp_path, f"  modes:\n    - table: {rows}\n", name))), "flex",
                          12.0, mode_interval=5.0, mode_basis="projected", cache=False)
           for rows, name in ((MODE1, "a.yaml"), (slope, "b.yaml"))]
    plain, scaled = tls
    assert plain.mode_change_t.tolist() == scaled.mode_change_t.tolist() and plain.mode_change_t.size >= 2
    dphi = plain.params[:, plain.dynamics.layout.params["dphi_gimbal"]]
    c = np.ones_like(dphi)
    c[:, 0] = (0.05 + 0.02 * plain.t / 60.0) / dphi[:, 0]
    for j, tc in enumerate(plain.mode_change_t):
        after = int(np.searchsorted(plain.t, tc, side="right")) - 1
        want = plain.mode_transfer[j] / c[after][:, None] * c[after - 1][None, :]
        np.testing.assert_allclose(scaled.mode_transfer[j], want, rtol=1e-9, atol=1e-12)


def test_a_copy_under_another_name_shares_the_timeline_cache_key(tmp_path, kestrel_tables):
    from lvgym.simulator.cache import key

    copy = tmp_path / "another_name.yaml"
    copy.write_text(kestrel_tables.read_text(encoding="utf-8"), encoding="utf-8")
    a, b = (key(MassModel(load_vehicle(p)), ("nonrigid", 70.0)) for p in (kestrel_tables, copy))
    assert a == b
    other = _write(tmp_path, f"  mass_properties: {MASS.replace('17000', '17001')}\n  modes:\n    - table: {MODE1}\n",
                   "changed.yaml")
    assert key(MassModel(load_vehicle(other)), ("nonrigid", 70.0)) != a
