"""The task's options in groups (lvgym/envs/options.py, spec.py), the protocol presets as values
(presets.py) and the slender vehicle's geometry as a value: the presets against the dict merges they
replaced, every flat keyword against its group, one-line errors, the docs table against the fields."""

from __future__ import annotations

import dataclasses
import pickle

import gymnasium as gym
import pytest

import lvgym  # noqa: F401
from lvgym.commandline import field_docs
from lvgym.envs import ENVS, SensorOptions, TaskSpec, TimingOptions
from lvgym.envs.options import rule_of
from lvgym.envs.spec import GROUPS, KEYWORDS, OPTION_GROUP
from lvgym.errors import ConfigError
from lvgym.vehicle.slender import SlenderGeometry

# the env classes' option dicts as they were merged before the presets (ascent.py's DEFAULTS, V1_OPTIONS)
_FLIGHT = {"observation": "flight", "gyro_bias_radps": 1.5e-5, "accel_noise_mps2": 0.02}
_V1 = {**_FLIGHT, "reference_velocity": "earth", "action_delay_steps": 1, "aeroelastic": None, "mode_interval_s": 2.0,
       "mode_basis": "projected", "slosh_frequency": "specific_force"}
_SMILE = {"vehicle": "smile", "site": "andoya", "mission_time_s": 60.0, "rate_weights": (0.0, 1.0, 1.0)}
_STRATOS = {"vehicle": "stratos3", "site": "el_arenosillo", "elevation_deg": 85.0, "rail_length_m": 10.0,
            "mission_time_s": 30.0, "control": "rcs", "rate_weights": (1.0, 1.0, 1.0), "qalpha_limit_pa_deg": 150e3,
            "controller_on_after_s": 1.0}
_SLENDER = {"site": "andoya", "mission_time_s": 10.0, "rate_weights": (0.0, 1.0, 1.0)}
MERGED = {
    "lvgym/SmileAscent-v0": _SMILE,
    "lvgym/SmileAscent-v1": {**_SMILE, **_V1, "vehicle": "smile_v1", "mission_time_s": 70.0, "coast_control": True,
                             "settling_thrust_n": 18000.0},
    "lvgym/StratosIII-v0": _STRATOS,
    "lvgym/StratosIII-v1": {**_STRATOS, **_V1, "control": "tvc", "rate_weights": (0.0, 1.0, 1.0)},
    "lvgym/SlenderAscent-v0": {**_SLENDER, "vehicle": ("slender", 8.5, 0.3, 2.0)},
    "lvgym/SlenderAscent-v1": {**_SLENDER, **_V1, "vehicle": ("slender", 8.5, 0.2833, 2.0, 0.0045)},
}


@pytest.mark.parametrize("env_id", list(MERGED))
def test_each_preset_is_the_dict_merge_it_replaced(env_id):
    preset = ENVS[env_id].PRESET
    assert preset == TaskSpec.build(MERGED[env_id], {})
    assert hash(preset) == hash(TaskSpec.build(MERGED[env_id], {}))
    assert gym.make(env_id).unwrapped.task == preset                  # no keyword: the preset itself


def test_every_flat_keyword_is_its_groups_field():
    assert len(set(KEYWORDS)) == len(KEYWORDS)                        # unique: a keyword names one field
    assert len(OPTION_GROUP) == 54 and not set(GROUPS) & set(OPTION_GROUP)
    base = TaskSpec("smile")
    for key, group in OPTION_GROUP.items():
        default = getattr(getattr(base, group), key)
        assert getattr(base, key) == default
    changed = base.with_options(mission_time_s=30.0, wind="gust", randomize=["mass"], observation="flight",
                                rate_weights=[1, 2, 3], coast_control=True, model="rigid")
    assert changed.timing.mission_time_s == changed.mission_time_s == 30.0
    assert changed.atmosphere.wind == "gust" and changed.dispersions.randomize == frozenset({"mass"})
    assert changed.sensors.observation == "flight" and changed.reward.rate_weights == (1.0, 2.0, 3.0)
    assert changed.coast.coast_control and changed.model == "rigid" and changed.control_dt_s == 0.02
    assert changed.options() == {**base.options(), "mission_time_s": 30.0, "wind": "gust", "randomize": frozenset({"mass"}),
                                 "observation": "flight", "rate_weights": (1.0, 2.0, 3.0), "coast_control": True,
                                 "model": "rigid"}
    assert base == TaskSpec("smile")                                  # with_options made a new value


def test_a_group_is_given_whole_or_as_a_mapping():
    spec = TaskSpec.build(ENVS["lvgym/SmileAscent-v1"].PRESET, {"sensors": SensorOptions(), "history": 2})
    assert spec.observation == "state" and spec.history == 2          # the flat keyword wins over its group
    spec = TaskSpec("smile", timing={"mission_time_s": 5.0})
    assert spec.timing == TimingOptions(mission_time_s=5.0)
    env = gym.make("lvgym/SmileAscent-v0", timing=TimingOptions(mission_time_s=0.5))
    assert env.unwrapped.task.mission_time_s == 0.5
    with pytest.raises(ConfigError, match=r"^timing\.mision_time_s = 5: unknown option of TimingOptions \(did you "
                                          r"mean 'mission_time_s'\?\)"):
        TaskSpec("smile", timing={"mision_time_s": 5})
    with pytest.raises(ConfigError, match=r"^sensors = 'flight': a SensorOptions or a mapping of its options$"):
        TaskSpec("smile").with_options(sensors="flight")


def _bad(rule):
    if rule.choices is not None:
        return "nonsense"
    if rule.boolean:
        return "yes"
    return rule.hi * 2 + 1


@pytest.mark.parametrize("key", [k for k, g in OPTION_GROUP.items()
                                 if rule_of(GROUPS[g].__dataclass_fields__[k]) is not None])
def test_a_bad_value_names_the_key_the_value_and_what_is_allowed(key):
    rule = rule_of(GROUPS[OPTION_GROUP[key]].__dataclass_fields__[key])
    value = _bad(rule)
    with pytest.raises(ConfigError) as err:
        TaskSpec("smile").with_options(**{key: value})
    text = str(err.value)
    assert text.startswith(f"{key} = {value!r}: ") and "\n" not in text
    assert err.value.key == key and err.value.value == value
    assert pickle.loads(pickle.dumps(err.value)).args == err.value.args      # survives a worker process


@pytest.mark.parametrize("options, message", [
    ({"control_dt_s": 0.015}, "control_dt_s = 0.015: a whole multiple of physics_dt_s = 0.01"),
    ({"kick_start_s": 20.0}, "kick_end_s = 15.0: a time after kick_start_s = 20.0"),
    ({"randomize": ["mass", "gravity"]}, "randomize = 'gravity': True (the v0 set"),
    ({"rate_weights": (1.0, -1.0, 0.0)}, "rate_weights = (1.0, -1.0, 0.0): three numbers >= 0"),
    ({"site": "mars"}, "site = 'mars': one of ['andoya', 'el_arenosillo', 'flat'] or a LaunchSite"),
    ({"n_modes": 11}, "n_modes = 11: None or an integer in [0, 10]"),
    ({"aeroelastic": "yes"}, "aeroelastic = 'yes': true, false or None"),
    ({"vehicle": 3}, "vehicle = 3: a shipped vehicle name, a YAML path or a SlenderGeometry"),
    ({"model": "elastic"}, "model = 'elastic': one of ('rigid', 'slosh', 'flex', 'nonrigid')"),
])
def test_the_checks_between_fields_and_of_the_groups_own(options, message):
    with pytest.raises(ConfigError) as err:
        TaskSpec("smile").with_options(**options)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_every_field_has_its_docstring_in_the_docs_table():
    import importlib.util
    from pathlib import Path

    docs = Path(__file__).resolve().parents[1] / "docs"
    spec = importlib.util.spec_from_file_location("gen_tables", docs / "gen_tables.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    page = (docs / "rl.md").read_text(encoding="utf-8")
    block = page.split("<!-- generated: options -->\n")[1].split("<!-- end: options -->")[0]
    assert block == gen.options() + "\n"
    for group, cls in GROUPS.items():
        docs_of = field_docs(cls)
        assert set(docs_of) == {f.name for f in dataclasses.fields(cls)}, group       # every field documented
        for f in dataclasses.fields(cls):
            assert docs_of[f.name] and f"| `{group}` | `{f.name}` |" in block
    assert set(field_docs(TaskSpec)) == {f.name for f in dataclasses.fields(TaskSpec)}


def test_the_slender_geometry_is_a_value():
    g = SlenderGeometry(8.5, 0.2833, aero_mach=2, wall_thickness=0.0045)
    assert g == SlenderGeometry(8.5, 0.2833, 2.0, 0.0045) and hash(g) == hash(SlenderGeometry(8.5, 0.2833, 2.0, 0.0045))
    assert isinstance(g.aero_mach, float) and pickle.loads(pickle.dumps(g)) == g
    assert SlenderGeometry.from_key(("slender", 8.5, 0.3)) == SlenderGeometry(8.5, 0.3, None, 0.002)
    assert SlenderGeometry.from_key(("slender", 8.5, 0.2833, 2.0, 0.0045)) == g
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.length = 9.0                                                               # type: ignore[misc]
    with pytest.raises(ConfigError, match=r"^slender_vehicle: aero_mach = 40: must be in \[0, 25\]$"):
        SlenderGeometry(8.5, 0.3, aero_mach=40)
    with pytest.raises(ConfigError, match=r"^slender_vehicle: diameter = 3.0: must be in"):
        SlenderGeometry(8.5, 3.0)
    # the older positional key still names the same vehicle
    spec = TaskSpec.build(None, {"vehicle": ("slender", 8.5, 0.2833, 2.0, 0.0045)})
    assert spec.vehicle == g == ENVS["lvgym/SlenderAscent-v1"].PRESET.vehicle
    from lvgym.envs.functional import cached_vehicle
    assert cached_vehicle(g) is cached_vehicle(SlenderGeometry(8.5, 0.2833, 2.0, 0.0045))
    assert cached_vehicle(g).stages[0].sections[0].wall_thickness == 0.0045


def test_the_slender_keywords_change_the_geometry():
    env = gym.make("lvgym/SlenderAscent-v0", diameter=(0.26, 0.3), aero_mach=None, mission_time_s=0.1).unwrapped
    assert [s.vehicle for s in env.specs] == [SlenderGeometry(8.5, d, None, 0.002) for d in env.diameters]
    assert env.diameters[0] == 0.26 and env.diameters[-1] == 0.3
    with pytest.raises(ConfigError, match=r"^diameter = \(0.2, 0.3, 0.4\): a diameter \[m\] > 0 or a \(low, high\) pair"):
        gym.make("lvgym/SlenderAscent-v0", diameter=(0.2, 0.3, 0.4))
    with pytest.raises(ConfigError, match=r"^diameter = \(0.26, 0.3\): one diameter \[m\]"):
        gym.make_vec("lvgym/SlenderAscent-v1", num_envs=2, vectorization_mode="vector_entry_point", diameter=(0.26, 0.3))
    v = gym.make_vec("lvgym/SlenderAscent-v1", num_envs=2, vectorization_mode="vector_entry_point",
                     wall_thickness_m=None, length=9.0, mission_time_s=0.1)
    assert v.task.vehicle == SlenderGeometry(9.0, 0.2833, 2.0, 0.0045)     # no wall: the preset's


def test_a_snapshot_names_the_options_that_differ():
    a = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=0.2).unwrapped
    b = gym.make("lvgym/SmileAscent-v0", model="rigid", mission_time_s=0.3).unwrapped
    a.reset(seed=0)
    b.reset(seed=0)
    with pytest.raises(ValueError, match=r"options \['mission_time_s'\] differ \(\{'mission_time_s': 0.2\}\)"):
        b.set_state(a.get_state())
