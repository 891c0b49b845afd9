"""Vehicle YAML errors name the file, the key path, the value and what is allowed (issue 3)."""

import copy
import re

import pytest
import yaml

from lvgym.errors import ConfigError
from lvgym.vehicle.config import VEHICLE_DIR, load_vehicle, parse_vehicle

BASE = yaml.safe_load((VEHICLE_DIR / "thesis-verification.yaml").read_text())


def _broken(edit):
    data = copy.deepcopy(BASE)
    edit(data)
    return data


def _expect(edit, pattern):
    with pytest.raises(ConfigError, match=pattern):
        parse_vehicle(_broken(edit), source="v.yaml")


def test_shipped_verification_vehicle_reads():
    v = load_vehicle("thesis-verification")
    assert v.length == 20.0
    assert [t.name for t in v.tanks] == ["oxidiser", "fuel"]
    assert v.stages[0].engines[0].mixture_ratio == 2.0


def test_unknown_key():
    _expect(lambda d: d["stages"][0]["tanks"][0].update(fill_raito=1.0),
            r"^v\.yaml: stages\[0\]\.tanks\[0\]\.fill_raito = 1\.0: unknown key; allowed here: .*fill_ratio")


def test_missing_key():
    _expect(lambda d: d["stages"][0]["tanks"][1].pop("density"),
            r"^v\.yaml: stages\[0\]\.tanks\[1\]\.density = <missing>: required$")


def test_negative_mass():
    _expect(lambda d: d["stages"][0]["structure"].update(mass=-5.0),
            r"^v\.yaml: stages\[0\]\.structure\.mass = -5\.0: must be in \[0, 1e\+07\]$")


@pytest.mark.parametrize("fill", [1.3, -0.1])
def test_fill_ratio_outside_unit_interval(fill):
    _expect(lambda d: d["stages"][0]["tanks"][0].update(fill_ratio=fill),
            rf"stages\[0\]\.tanks\[0\]\.fill_ratio = {re.escape(str(fill))}: must be in \[0, 1\]")


def test_overlapping_tanks():
    _expect(lambda d: d["stages"][0]["tanks"][1].update(top=-9.0),
            r"stages\[0\]\.tanks\[1\]\.top = -9\.0: tanks must not overlap: 'fuel' .* must be <= -10")


def test_gimbal_outside_vehicle():
    _expect(lambda d: d["stages"][0]["engines"][0].update(gimbal=-25.0),
            r"stages\[0\]\.engines\[0\]\.gimbal = -25\.0: the gimbal must lie on the vehicle: station in \[-20, 0\]")
    _expect(lambda d: d["stages"][0]["engines"][0].update(gimbal=1.0), r"gimbal = \[1\.0, 0\.0, 0\.0\]|x must be <= 0")


def test_thrust_table_not_monotonic_in_time():
    def edit(d):
        e = d["stages"][0]["engines"][0]
        e.pop("isp")
        e["thrust_table"] = [[0.0, 0.0], [1.0, 2e6], [0.5, 2e6], [3.0, 0.0]]

    _expect(edit, r"engines\[0\]\.thrust_table\[2\] = \[0\.5, 2000000\.0\]: the first column \(time\) must be "
                  r"strictly increasing")


def test_other_consistency_errors():
    _expect(lambda d: d["stages"][0]["tanks"][0].update(engine="vernier"), r"tanks\[0\]\.engine = 'vernier'")
    _expect(lambda d: d["stages"][0]["tanks"][0].update(role="coolant"), r"role = 'coolant': must be one of")
    _expect(lambda d: d["stages"][0]["tanks"][0].update(top=1.0), r"tanks\[0\]\.top = 1\.0: must be in \[-1000, 0\]")
    _expect(lambda d: d["stages"][0]["tanks"][1].update(height=11.0), r"must lie within stage 'core'")
    _expect(lambda d: d.update(staging=[]), r"staging = \[\]: one step per stage, in firing order")
    _expect(lambda d: d.update(staging=[{"stage": "core", "ignition_delay": 2.0}]),
            r"staging\[0\]\.ignition_delay = 2\.0: must be 0: the first stage ignites at lift-off")
    _expect(lambda d: d["stages"][0]["structure"].update(inertia=[1.0, -2.0, 3.0]), r"positive semi-definite")
    _expect(lambda d: d["stages"][0]["engines"][0].update(thrust_table=[[0, 1], [1, 1]]),
            r"give either isp .* or thrust_table")


def test_unknown_vehicle_name_lists_the_shipped_ones():
    with pytest.raises(ConfigError, match=r"vehicle = 'nope': one of the shipped vehicles \[.*'thesis-verification'"):
        load_vehicle("nope")


def test_staging_needs_separation_below_an_upper_stage():
    data = yaml.safe_load((VEHICLE_DIR / "smile.yaml").read_text())
    data["staging"][0].pop("separation_delay")
    with pytest.raises(ConfigError, match=r"staging\[0\]\.separation_delay = <missing>|staging\[0\]\.separation_delay = None: required"):
        parse_vehicle(data, source="smile.yaml")


def test_sections_parts_and_sensors_must_lie_on_the_vehicle():
    _expect(lambda d: d["stages"][0]["sections"][0].update(bottom=-19.5),
            r"sections\[0\]\.bottom = -19\.5: sections must reach the bottom of stage 'core': -20")
    _expect(lambda d: d.update(payload={"mass": 10.0, "cg": -30.0}), r"payload\.cg = -30\.0: must lie on the vehicle")
    _expect(lambda d: d.update(structure={"sensor_stations": [-100.0]}),
            r"structure\.sensor_stations\[0\] = -100\.0: must lie on the vehicle")
    _expect(lambda d: d.update(structure={"sensor_stations": [False]}), r"finite stations in \[-1000, 0\]")


def test_thrust_table_engines_are_not_throttled_and_need_impulse():
    def table(d, throttle=None, rows=((0.0, 0.0), (1.0, 2e6), (3.0, 0.0))):
        e = d["stages"][0]["engines"][0]
        e.pop("isp")
        e["thrust_table"] = [list(r) for r in rows]
        if throttle:
            e["throttle"] = throttle

    _expect(lambda d: table(d, [0.5, 1.0]), r"throttle = \[0\.5, 1\.0\]: a thrust-table engine cannot be throttled")
    _expect(lambda d: table(d, rows=((0.0, 0.0), (1.0, 0.0))), r"thrust_table = .*: needs a thrust > 0")


# ------------------------------------------------------------------------------- files (issue 19)
SMILE_TEXT = (VEHICLE_DIR / "smile.yaml").read_text()


def _load_text(tmp_path, text, name="bad.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return load_vehicle(path)


def _line_of(text, needle):
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


def test_yaml_syntax_error_names_the_file_and_the_line(tmp_path):
    lines = SMILE_TEXT.splitlines()
    n = _line_of(SMILE_TEXT, "outer_diameter: 1.1")
    lines[n - 1] = lines[n - 1].replace("outer_diameter: 1.1", "outer_diameter: 1.1: 2")
    with pytest.raises(ConfigError, match=rf"^bad\.yaml, line {n}: yaml = .*: valid YAML syntax") as err:
        _load_text(tmp_path, "\n".join(lines))
    assert err.value.line == n and err.value.source == "bad.yaml"
    with pytest.raises(ConfigError, match=r"^bad\.yaml, line 3: yaml = .*valid YAML syntax"):
        _load_text(tmp_path, "name: x\nstages: [\n")


def test_unsafe_tag_is_refused_with_its_line(tmp_path):
    text = SMILE_TEXT.replace("name: smile\n", "name: !!python/object/apply:os.getcwd []\n", 1)
    n = _line_of(text, "python/object")
    with pytest.raises(ConfigError, match=rf"^bad\.yaml, line {n}: name = 'tag:yaml.org,2002:python/object/apply:"
                                          r"os.getcwd': plain YAML data only"):
        _load_text(tmp_path, text)
    with pytest.raises(ConfigError, match=r"line 1: <top> = '!include'"):
        _load_text(tmp_path, "!include other.yaml\n")


def test_duplicate_key_is_named_with_both_lines(tmp_path):
    text = SMILE_TEXT.replace("    length: 9.4\n", "    length: 9.4\n    length: 8.0\n", 1)
    first = _line_of(text, "length: 9.4")
    with pytest.raises(ConfigError, match=rf"^bad\.yaml, line {first + 1}: stages\[0\]\.length = 'length': each key "
                                          rf"once per mapping: 'length' is also given at line {first}$"):
        _load_text(tmp_path, text)
    with pytest.raises(ConfigError, match=r"stages\[0\]\.tanks\[0\]\.density = 'density': each key once"):
        _load_text(tmp_path, SMILE_TEXT.replace("density: 1141.0,", "density: 1141.0, density: 1.0,", 1))


def test_value_errors_carry_the_line_of_their_key(tmp_path):
    text = SMILE_TEXT.replace("gimbal_limit_deg: 5.0", "gimbal_limit_deg: 95.0", 1)
    n = _line_of(text, "gimbal_limit_deg: 95.0")
    with pytest.raises(ConfigError, match=rf"^bad\.yaml, line {n}: stages\[0\]\.engines\[0\]\.gimbal_limit_deg = "
                                          r"95\.0: must be in \[0, 45\]$"):
        _load_text(tmp_path, text)


def test_missing_file_names_the_path_and_the_shipped_vehicles(tmp_path):
    with pytest.raises(ConfigError, match=r"vehicle = '.*nowhere\.yaml': an existing YAML file \(there is no such "
                                          r"file\) or one of the shipped vehicles \[.*'smile'.*\]"):
        load_vehicle(tmp_path / "nowhere.yaml")
    with pytest.raises(ConfigError, match=r"it is a folder"):
        load_vehicle(tmp_path / "dir.yaml" if (tmp_path / "dir.yaml").mkdir() is None else "")


def test_misspelt_required_key_suggests_the_right_one():
    def edit(d):
        d["stages"][0]["tanks"][1]["densty"] = d["stages"][0]["tanks"][1].pop("density")

    _expect(edit, r"^v\.yaml: stages\[0\]\.tanks\[1\]\.density = <missing>: required \(the mapping has 'densty': "
                  r"did you mean 'density'\?\)$")
    _expect(lambda d: d["stages"][0]["engines"][0].update(mass_flw=5.0),
            r"engines\[0\]\.mass_flw = 5\.0: unknown key; allowed here: .*; did you mean 'mass_flow'\?$")


@pytest.mark.parametrize("edit, pattern", [
    (lambda d: d["stages"][0]["tanks"][0].update(inner_radius=2.5),
     r"tanks\[0\]\.inner_radius = 2\.5: at most the outer radius of stage 'core', 2\.05 m .*fit inside its stage"),
    (lambda d: d["stages"][0]["tanks"][0].update(inner_radius=1e6), r"inner_radius = 1000000\.0: must be in \(0, 25\]"),
    (lambda d: d["stages"][0]["tanks"][0].update(inner_radius=float("nan")), r"inner_radius = nan: must be a finite"),
    (lambda d: d["stages"][0]["tanks"][0].update(density=1e6), r"density = 1000000\.0: must be in \(0, 25000\]"),
    (lambda d: d["stages"][0].update(outer_diameter=float("inf")), r"outer_diameter = inf: must be a finite number"),
    (lambda d: d["stages"][0]["engines"][0].update(gimbal=[-18.0, 3.0, 0.0]),
     r"engines\[0\]\.gimbal = \[-18\.0, 3\.0, 0\.0\]: must lie within stage 'core': at most its radius 2\.05 m"),
    (lambda d: d["stages"][0]["structure"].update(cg=[-9.0, 0.0, -2.5]), r"structure\.cg = .*at most its radius"),
    (lambda d: d["stages"][0]["engines"][0].update(nozzle_exit_area=20.0),
     r"engines\[0\]\.nozzle_exit_area = 20\.0: a nozzle exit no wider than stage 'core' \(4\.1 m\)"),
    (lambda d: d["stages"][0]["engines"][0].update(mass_flow=1e9), r"mass_flow = 1000000000\.0: must be in \(0, 100000\]"),
    (lambda d: d["stages"][0]["structure"].update(inertia=[1.0, 1.0, 5.0]),
     r"structure\.inertia = \[1\.0, 1\.0, 5\.0\]: principal moments that a body can have"),
    (lambda d: d["structure"].update(n_modes=500), r"structure\.n_modes = 500: must be an integer in \[0, 20\]"),
    (lambda d: d["stages"][0]["engines"][0].update(cg=[-19.0, 0.0, 1e9]), r"coordinates within 1000 m"),
    (lambda d: d["staging"][0].update(burn_time=1e12), r"staging\[0\]\.burn_time = 1000000000000\.0: must be in"),
])
def test_values_are_checked_for_range_and_fit(edit, pattern):
    _expect(edit, pattern)


def test_engines_and_structures_lie_within_their_stage():
    data = yaml.safe_load(SMILE_TEXT)
    data["stages"][1]["engines"][0]["cg"] = -8.0                     # in stage 1's span, not stage 2's
    with pytest.raises(ConfigError, match=r"stages\[1\]\.engines\[0\]\.cg = -8\.0: must lie within stage 'stage2': "
                                          r"station in \[-7\.1, -4\.1\]"):
        parse_vehicle(data, source="smile.yaml")
    data = yaml.safe_load(SMILE_TEXT)
    data["stages"][2]["structure"]["cg"] = -5.0
    with pytest.raises(ConfigError, match=r"stages\[2\]\.structure\.cg = -5\.0: must lie within stage 'stage3'"):
        parse_vehicle(data, source="smile.yaml")


def test_grain_wider_than_its_stage():
    data = yaml.safe_load((VEHICLE_DIR / "stratos3.yaml").read_text())
    data["stages"][0]["grain"]["outer_radius"] = 0.2
    with pytest.raises(ConfigError, match=r"grain\.outer_radius = 0\.2: at most the outer radius of stage"):
        parse_vehicle(data, source="stratos3.yaml")


def test_config_error_survives_pickling():
    import pickle
    import threading

    from lvgym.errors import MISSING

    for err in (ConfigError("stages[0].tanks[1].fill_ratio", 1.3, "must be in [0, 1]", "smile.yaml", 42),
                ConfigError("density", MISSING, "required", "v.yaml"), ConfigError("lock", threading.Lock(), "x")):
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is ConfigError and str(back) == str(err)
        assert (back.key, back.allowed, back.source, back.line) == (err.key, err.allowed, err.source, err.line)
    assert pickle.loads(pickle.dumps(ConfigError("k", MISSING, "required"))).value is MISSING
