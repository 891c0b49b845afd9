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
            r"^v\.yaml: stages\[0\]\.structure\.mass = -5\.0: must be in \[0, inf\]$")


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
    _expect(lambda d: d["stages"][0]["tanks"][0].update(top=1.0), r"tanks\[0\]\.top = 1\.0: must be in \[-inf, 0\]")
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
    _expect(lambda d: d.update(structure={"sensor_stations": [False]}), r"finite stations <= 0")


def test_thrust_table_engines_are_not_throttled_and_need_impulse():
    def table(d, throttle=None, rows=((0.0, 0.0), (1.0, 2e6), (3.0, 0.0))):
        e = d["stages"][0]["engines"][0]
        e.pop("isp")
        e["thrust_table"] = [list(r) for r in rows]
        if throttle:
            e["throttle"] = throttle

    _expect(lambda d: table(d, [0.5, 1.0]), r"throttle = \[0\.5, 1\.0\]: a thrust-table engine cannot be throttled")
    _expect(lambda d: table(d, rows=((0.0, 0.0), (1.0, 0.0))), r"thrust_table = .*: needs a thrust > 0")
