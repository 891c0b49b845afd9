"""The shipped vehicles: they load, and their numbers are the thesis's (docs/vehicles.md).

SMILE's mass history and staging times (Table 6.10, thesis 6.3), its six slosh tanks and L/D; Stratos
III's thrust table, L/D and fill (thesis 5.1, Table 5.1); the slender vehicle at the 32 corners of
Table 6.3 and its shipped YAML equal to ``slender_vehicle()``'s defaults.
"""

import doctest
import itertools
import math

import numpy as np
import pytest
import yaml

import lvgym.environment.barrowman  # noqa: F401  (registers the 'barrowman' aerodynamics model)
from lvgym.environment.registry import make
from lvgym.errors import ConfigError
from lvgym.vehicle.beam import stack_modes
from lvgym.vehicle.config import VEHICLE_DIR, load_vehicle, parse_vehicle
from lvgym.vehicle.massmodel import MassModel
from lvgym.vehicle.sections import MATERIALS, Section, tube
import lvgym.vehicle.slender
from lvgym.vehicle.slender import DEFAULTS, TABLE_6_3, slender_mapping, slender_vehicle
from lvgym.vehicle.structure import vehicle_modes

SHIPPED = sorted(p.stem for p in VEHICLE_DIR.glob("*.yaml"))
#: Table 6.10: time [s] -> vehicle mass [kg]
SMILE_MASS = {3.0: 10165.0, 15.0: 8389.0, 28.8: 6347.0, 40.0: 4689.0, 46.0: 1867.0}


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_vehicle_loads_and_has_mass(name):
    v = load_vehicle(name)
    mm = MassModel(v)
    p = mm.properties(mm.initial_state())
    assert p.mass > 0.0 and -v.length < p.cg[0] < 0.0
    assert np.all(np.linalg.eigvalsh(p.inertia) > 0.0)


def test_our_vehicles_are_shipped():
    assert {"stratos3", "smile", "slender"} <= set(SHIPPED)


def _margin(v, t: float, mach: float) -> float:
    """Static margin [calibres] of ``v`` at time ``t`` [s] (its mass-model CG) and Mach ``mach``, from the
    Barrowman tables its ``aerodynamics`` mapping builds (positive: CP aft of the CG)."""
    aero = make("aerodynamics", v.aerodynamics)
    mm = MassModel(v)
    state, _ = mm.advance(mm.initial_state(), t)
    return (mm.properties(state).cg[0] - aero.x_cp(mach)) / aero.diameter


@pytest.mark.parametrize("name, t, mach, low", [
    ("stratos3", 0.0, 0.0, 4.0), ("stratos3", 22.8, 4.0, 1.2),      # Mach from a 1-D vertical ascent
    ("smile", 0.0, 0.0, 2.0), ("smile", 28.8, 3.1, 1.0), ("smile", 42.9, 6.0, 0.3),
    ("slender", 0.0, 0.0, 6.0)])
def test_statically_stable_along_the_ascent(name, t, mach, low):
    assert _margin(load_vehicle(name), t, mach) > low


@pytest.mark.parametrize("name", ["stratos3", "smile", "slender"])
def test_bending_modes_of_the_loaded_stack(name):
    v = load_vehicle(name)
    mm = MassModel(v)
    state = mm.initial_state()
    modes = vehicle_modes(v, state, mm.properties(state))
    f1 = modes.omega[0] / (2 * np.pi)
    assert modes.omega.size == 2
    if v.structure.first_mode_hz is not None:   # stratos3: calibrated to the thesis's 33 Hz
        assert f1 == pytest.approx(v.structure.first_mode_hz, rel=1e-9)
    else:                                       # the loaded beams of smile (9.4 Hz) and slender (11.2 Hz)
        assert 5.0 < f1 < 20.0


# ------------------------------------------------------------------------------------------ SMILE
@pytest.fixture(scope="module")
def smile():
    return load_vehicle("smile")


def test_smile_mass_history_table_6_10(smile):
    mm = MassModel(smile)
    state = mm.initial_state()
    for t, mass in SMILE_MASS.items():
        state, _ = mm.advance(state, t)
        got = mm.properties(state).mass
        assert abs(got - mass) <= 0.03 * mass, (t, got, mass)
        assert abs(got - mass) <= 0.001 * mass, (t, got, mass)     # as built: within 0.1 %


def test_smile_first_stage_flow_148(smile):
    mm = MassModel(smile)
    state, _ = mm.advance(mm.initial_state(), 10.0)
    assert mm.mass_flow(state) == pytest.approx(148.0, rel=0.01)


def test_smile_staging_at_43_and_45_s(smile):
    mm = MassModel(smile)
    state, events = mm.advance(mm.initial_state(), 50.0)
    when = {text: t for t, text in events}
    assert when["stage 'stage1' burnout"] == pytest.approx(43.0, abs=1e-6)
    assert 43.0 < when["stage 'stage1' separation"] < 45.0
    assert when["stage 'stage2' ignition"] == pytest.approx(45.0, abs=1e-6)
    assert [text for _, text in events][-1] == "stage 'stage2' ignition"
    assert mm.properties(state).stages == ("stage2", "stage3")


def test_smile_six_slosh_tanks_and_slenderness(smile):
    mm = MassModel(smile)
    p = mm.properties(mm.initial_state())
    assert mm.n_slosh == 6 and len(smile.tanks) == 6
    assert np.all(p.slosh_mass > 0.0) and np.all(p.pendulum_length > 0.0)
    assert {t.role for t in smile.tanks} == {"oxidiser", "fuel"}
    ld = smile.length / smile.stages[0].outer_diameter
    assert 14.5 <= ld <= 16.6
    assert smile.payload is not None and smile.payload.mass == pytest.approx(70.0, abs=10.0)
    assert smile.fairing is not None
    assert len(smile.stages) == 3


# -------------------------------------------------------------------------------------- Stratos III
@pytest.fixture(scope="module")
def stratos3():
    return load_vehicle("stratos3")


def test_stratos3_thrust_table_peak_and_drop(stratos3):
    table = stratos3.stages[0].engines[0].thrust_table
    t, T = table[:, 0], table[:, 1]
    assert 20e3 <= T.max() <= 22e3                                        # peak near 21 kN
    # the liquid-to-gas drop: somewhere in 20-25 s the thrust halves within 2 s
    grid = np.arange(20.0, 23.0 + 1e-9, 0.1)
    drops = [np.interp(x + 2.0, t, T) / np.interp(x, t, T) for x in grid]
    assert min(drops) < 0.5
    assert t[-1] == pytest.approx(38.0) and T[-1] == 0.0                   # the 38 s test burn


def test_stratos3_bare_beam_near_33_hz(stratos3):
    """Thesis 5.1: 33 Hz for the bare hollow beam; our bare CFRP sections give 34.1 Hz."""
    sections = [Section(s.top, s.bottom, *tube(MATERIALS[s.material], s.outer_diameter, s.wall_thickness))
                for s in stratos3.stages[0].sections]
    f1 = stack_modes(sections, n_modes=1).frequency_hz[0]
    assert f1 == pytest.approx(33.0, rel=0.05)


def test_stratos3_geometry_fill_and_burn(stratos3):
    assert stratos3.length / stratos3.stages[0].outer_diameter == pytest.approx(29.3, abs=0.05)
    (tank,) = stratos3.tanks
    assert tank.fill_ratio == 0.7 and tank.slosh and tank.role == "oxidiser"
    assert stratos3.stages[0].grain is not None
    mm = MassModel(stratos3)
    assert mm.n_slosh == 1
    state, events = mm.advance(mm.initial_state(), 40.0)
    (burnout,) = [t for t, text in events if "burnout" in text]
    assert 37.5 < burnout <= 38.0                                           # the N2O runs out at the end
    assert state.tank_mass[0] == pytest.approx(0.0, abs=1e-6)
    assert state.grain_mass[0] > 0.0                                        # a sliver is left


# ------------------------------------------------------------------------------------ slender
CORNERS = list(itertools.product(*[TABLE_6_3[k] for k in ("length", "diameter", "fill", "mass_flow",
                                                              "slosh_damping")]))


def test_slender_builds_at_all_32_corners():
    assert len(CORNERS) == 32
    for L, D, F, mdot, zeta in CORNERS:
        v = slender_vehicle(length=L, diameter=D, fill=F, mass_flow=mdot, slosh_damping=zeta)
        (tank,) = v.tanks
        assert v.length == pytest.approx(L) and v.stages[0].outer_diameter == pytest.approx(D)
        assert tank.fill_ratio == pytest.approx(F) and tank.slosh_damping == pytest.approx(zeta)
        assert v.stages[0].engines[0].mass_flow == pytest.approx(mdot)
        mm = MassModel(v)
        p = mm.properties(mm.initial_state())
        assert mm.n_slosh == 1 and p.slosh_mass[0] > 0.0 and p.mass_flow == pytest.approx(mdot)


def _same(a, b, path="") -> None:
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), path
        for k in a:
            _same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        assert math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12), (path, a, b)
    else:
        assert a == b, (path, a, b)


def test_slender_yaml_equals_function_defaults():
    with open(VEHICLE_DIR / "slender.yaml", encoding="utf-8") as fh:
        shipped = yaml.safe_load(fh)
    _same(shipped, slender_mapping())
    assert DEFAULTS == {"length": 8.5, "diameter": 0.3, "fill": 1.0, "mass_flow": 30.0, "slosh_damping": 0.5}
    _same(slender_mapping(), slender_mapping(**DEFAULTS))
    assert load_vehicle("slender").length == slender_vehicle().length


@pytest.mark.parametrize("kwargs, key", [
    ({"length": -1.0}, "length"), ({"length": "8.5"}, "length"), ({"length": math.nan}, "length"),
    ({"diameter": 0.0}, "diameter"), ({"diameter": 3.0}, "diameter"), ({"fill": 0.0}, "fill"),
    ({"fill": 1.2}, "fill"), ({"mass_flow": 0.0}, "mass_flow"), ({"mass_flow": math.inf}, "mass_flow"),
    ({"slosh_damping": -0.1}, "slosh_damping"), ({"slosh_damping": True}, "slosh_damping"),
    ({"wall_thickness": 0.0}, "wall_thickness"), ({"material": "wood"}, "material"),
    ({"density": -800.0}, "density"), ({"isp": 0.0}, "isp"), ({"colour": "red"}, "colour"),
])
def test_slender_errors_name_the_parameter(kwargs, key):
    with pytest.raises(ConfigError) as info:
        slender_vehicle(**kwargs)
    assert info.value.key == key
    assert str(info.value).startswith(f"slender_vehicle: {key} = ")


def test_lvgym_vehicle_slender_prints_the_vehicle_file(capsys):
    """``lvgym vehicle slender`` prints the shipped file at the defaults, a vehicle of the factors given, and
    refuses a factor out of range in one line naming the option."""
    from lvgym.cli.main import main

    assert main(["vehicle", "slender"]) == 0
    assert capsys.readouterr().out == (VEHICLE_DIR / "slender.yaml").read_text(encoding="utf-8")
    assert main(["vehicle", "slender", "--length", "10", "--diameter", "0.4"]) == 0
    v = parse_vehicle(yaml.safe_load(capsys.readouterr().out))
    assert v.length == pytest.approx(10.0) and v.stages[0].outer_diameter == pytest.approx(0.4)
    with pytest.raises(SystemExit) as exc:
        main(["vehicle", "slender", "--length", "100"])
    assert exc.value.code == "lvgym vehicle slender: --length = 100.0: must be in [3, 30]"


def test_slender_docstring_examples():
    result = doctest.testmod(lvgym.vehicle.slender)
    assert result.attempted > 0 and result.failed == 0
