"""Task options of the ascent environments: one frozen, validated value per env instance.

A :class:`TaskSpec` is the vehicle, the flight model and one value of each option group of
:mod:`.options` (launch, timing, physics, atmosphere, dispersions, sensors, actuator, guidance, reward,
limits, coast). Every field of a group is also a flat keyword and a read-only attribute of the spec:
``gymnasium.make(env_id, mission_time_s=30.0)`` sets ``spec.timing.mission_time_s``, which
``spec.mission_time_s`` reads. A group can be given whole (``sensors=SensorOptions(...)``, or a mapping of
its fields). A bad value raises :class:`~lvgym.errors.ConfigError` naming the key, the value and what is
allowed; an unknown keyword names the closest one. The protocols' presets of each env are named values
(:mod:`.presets`); docs/rl.md's options table is generated from the groups' field docstrings.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import Any

from lvgym.errors import MISSING, ConfigError, check_choice, did_you_mean
from lvgym.simulator import MODELS
from lvgym.vehicle.slender import SlenderGeometry

from .dispersions import IMU_STATION_INTERVALS, IMU_STATION_SIGMA, RANDOMIZE, RANDOMIZE_V0
from .options import (CONTROLS, OBSERVATIONS, REFERENCE_VELOCITIES, REFERENCES, WIND_TIERS, ActuatorOptions,
                      AtmosphereOptions, CoastOptions, DispersionOptions, FaultOptions, GuidanceOptions, LaunchOptions,
                      LimitOptions, PhysicsOptions, RewardOptions, SensorOptions, TimingOptions)

__all__ = ["CONTROLS", "GROUPS", "IMU_STATION_INTERVALS", "IMU_STATION_SIGMA", "KEYWORDS", "MAXQ_GUST_ONSET_M",
           "OBSERVATIONS", "OPTION_GROUP", "REFERENCES", "REFERENCE_VELOCITIES", "RANDOMIZE", "RANDOMIZE_V0",
           "TaskSpec", "WIND_TIERS", "check_reset_options", "vehicle_key", "wind_spec"]

#: the onset altitudes [m] of the ``maxq_gust`` tier's gust: SMILE's max q is at 9.8 km (docs/vehicles.md)
MAXQ_GUST_ONSET_M = (8000.0, 11500.0)


def wind_spec(tier: str, mission_time: float) -> Any:
    """The wind model (a mapping for ``lvgym.environment.make``) of a wind tier.

    ``profile``: a fixed 20 m/s west wind above a power-law boundary layer; ``gust``: a 15 m/s
    1-cosine gust 200 m long at 3 km; ``turbulence``: moderate Dryden turbulence (MIL-F-8785C) over a
    10 m/s west wind; ``random``: a random jet-stream profile plus moderate Dryden turbulence.
    Protocol v1's: ``turbulence_gust``: ``turbulence`` plus a random 1-cosine gust (``random_gust``: 5-15 m/s,
    30-300 m, from any direction, onset 1-15 km); ``maxq_gust``: a random jet-stream profile plus a random
    gust whose onset lies in the max-q region (``MAXQ_GUST_ONSET_M``); ``random_gust``: the random gust of
    ``turbulence_gust`` alone (``experiments.error_budget.budget`` flies it to share out the error)."""
    profile = {"model": "profile", "altitude_m": [0.0, 1000.0, 10000.0, 100000.0],
               "speed": [5.0, 12.0, 20.0, 20.0], "direction_deg": [270.0, 270.0, 270.0, 270.0]}
    if tier == "none":
        return "none"
    if tier == "profile":
        return profile
    if tier == "gust":
        return {"model": "gust", "amplitude": 15.0, "length": 200.0, "direction_deg": 270.0, "onset": 3000.0}
    if tier == "turbulence":
        return {"model": "sum", "models": [{"model": "profile", "altitude_m": [0.0, 100000.0],
                                            "speed": [10.0, 10.0], "direction_deg": [270.0, 270.0]},
                                           {"model": "dryden", "intensity": "moderate", "wind_from_deg": 270.0}]}
    if tier == "random":
        return {"model": "sum", "models": [{"model": "jet_stream"}, {"model": "dryden", "intensity": "moderate"}]}
    if tier == "turbulence_gust":
        return {"model": "sum", "models": [*wind_spec("turbulence", mission_time)["models"], {"model": "random_gust"}]}
    if tier == "random_gust":
        return {"model": "sum", "models": [{"model": "random_gust"}]}
    if tier == "maxq_gust":
        return {"model": "sum", "models": [{"model": "jet_stream"},
                                           {"model": "random_gust", "onset_m": list(MAXQ_GUST_ONSET_M)}]}
    raise ConfigError("wind", tier, f"one of {WIND_TIERS}")


#: the option groups of a :class:`TaskSpec`, by attribute name, in the order the docs list them
GROUPS: dict[str, type] = {"launch": LaunchOptions, "timing": TimingOptions, "physics": PhysicsOptions,
                           "atmosphere": AtmosphereOptions, "dispersions": DispersionOptions, "sensors": SensorOptions,
                           "actuator": ActuatorOptions, "guidance": GuidanceOptions, "reward": RewardOptions,
                           "limits": LimitOptions, "coast": CoastOptions, "faults": FaultOptions}
#: every flat option (a field of a group) and its group
OPTION_GROUP: dict[str, str] = {f.name: group for group, cls in GROUPS.items() for f in fields(cls)}
#: what a vehicle may be (a bad one's error says so)
VEHICLES = "a shipped vehicle name, a YAML path or a SlenderGeometry(length, diameter, aero_mach, wall_thickness)"


def vehicle_key(vehicle: Any) -> str | SlenderGeometry:
    """``vehicle`` as the spec holds it (the key of :func:`~.functional.cached_vehicle`): a name or path as a
    string, a :class:`~lvgym.vehicle.slender.SlenderGeometry` as itself, and the older positional key
    ``("slender", length, diameter[, aero_mach[, wall_thickness]])`` as the geometry it names."""
    if isinstance(vehicle, SlenderGeometry):
        return vehicle
    if isinstance(vehicle, (tuple, list)) and vehicle and vehicle[0] == "slender":
        return SlenderGeometry.from_key(vehicle)
    if isinstance(vehicle, os.PathLike):
        return os.fspath(vehicle)
    if isinstance(vehicle, str) and vehicle:
        return vehicle
    raise ConfigError("vehicle", vehicle, VEHICLES)


def _group(name: str, value: Any, current: Any) -> Any:
    """The group ``name`` given as ``value``: an instance of its class, or a mapping of fields that update
    ``current``."""
    cls = GROUPS[name]
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        known = [f.name for f in fields(cls)]
        for key in value:
            if key not in known:
                raise ConfigError(f"{name}.{key}", value[key],
                                  f"unknown option of {cls.__name__}{did_you_mean(key, known)}; "
                                  f"its options: {known}")
        return replace(current, **value)
    raise ConfigError(name, value, f"a {cls.__name__} or a mapping of its options")


@dataclass(frozen=True)
class TaskSpec:
    """Options of an ascent task: the vehicle, the flight model, and one value per option group (see the
    module docstring; each group's fields are documented in :mod:`.options` and in docs/rl.md's options
    table). Build one with :meth:`build` or :meth:`with_options` from flat keywords, or directly from
    groups: ``TaskSpec("smile", timing=TimingOptions(mission_time_s=30.0))``. Every group field is also a
    read-only attribute (``spec.mission_time_s``)."""

    vehicle: Any
    """the vehicle: a shipped name (``lvgym/vehicles/<name>.yaml``), a YAML path, or a
    :class:`~lvgym.vehicle.slender.SlenderGeometry`"""
    model: str = "nonrigid"
    """the flight model: ``rigid``, ``slosh``, ``flex`` or ``nonrigid``"""
    launch: LaunchOptions = LaunchOptions()
    """where and how it leaves the ground"""
    timing: TimingOptions = TimingOptions()
    """the episode's clock"""
    physics: PhysicsOptions = PhysicsOptions()
    """the flight model's options: bending modes, aeroelastic loads, slosh dampers"""
    atmosphere: AtmosphereOptions = AtmosphereOptions()
    """the wind"""
    dispersions: DispersionOptions = DispersionOptions()
    """the Monte Carlo dispersions drawn at every reset"""
    sensors: SensorOptions = SensorOptions()
    """what the policy observes and the sensors' errors"""
    actuator: ActuatorOptions = ActuatorOptions()
    """the servo or the reaction control the policy commands"""
    guidance: GuidanceOptions = GuidanceOptions()
    """the reference the policy tracks"""
    reward: RewardOptions = RewardOptions()
    """the reward's weights"""
    limits: LimitOptions = LimitOptions()
    """the limits that terminate an episode"""
    coast: CoastOptions = CoastOptions()
    """what holds the vehicle through a staging coast"""
    faults: FaultOptions = FaultOptions()
    """the in-flight fault drawn when ``randomize`` holds ``fault``"""

    def __post_init__(self) -> None:
        object.__setattr__(self, "vehicle", vehicle_key(self.vehicle))
        check_choice("model", self.model, MODELS)
        for name, cls in GROUPS.items():
            value = getattr(self, name)
            if not isinstance(value, cls):
                object.__setattr__(self, name, _group(name, value, cls()))

    @property
    def substeps(self) -> int:
        """Physics steps per control period."""
        return self.timing.substeps

    def options(self) -> dict[str, Any]:
        """Every option by its flat keyword (``vehicle``, ``model`` and each group's fields)."""
        return {"vehicle": self.vehicle, "model": self.model,
                **{key: getattr(getattr(self, group), key) for key, group in OPTION_GROUP.items()}}

    def with_options(self, **options: Any) -> TaskSpec:
        """This spec with ``options`` changed: flat keywords, ``vehicle``, ``model``, or whole groups (an
        instance, or a mapping of its fields; a flat keyword given beside its group wins). An unknown
        keyword raises a one-line :class:`~lvgym.errors.ConfigError` with the closest one."""
        check_keywords(options)
        top = {"vehicle": self.vehicle, "model": self.model}
        groups = {name: getattr(self, name) for name in GROUPS}
        flat: dict[str, dict[str, Any]] = {}
        for key, value in options.items():
            if key in GROUPS:
                groups[key] = _group(key, value, groups[key])
            elif key in top:
                top[key] = value
            else:
                flat.setdefault(OPTION_GROUP[key], {})[key] = value
        for name, changed in flat.items():
            groups[name] = replace(groups[name], **changed)
        return TaskSpec(**top, **groups)

    @classmethod
    def build(cls, preset: TaskSpec | Mapping[str, Any] | None, overrides: Mapping[str, Any],
              also: tuple[str, ...] = ()) -> TaskSpec:
        """The ``preset`` (an env's protocol preset, :mod:`.presets`; or a mapping of flat keywords with
        ``vehicle``) updated by the user's keywords. An unknown keyword raises a one-line
        :class:`~lvgym.errors.ConfigError` with the closest option (of the options and of ``also``, the
        env's own keywords) and where the options are documented."""
        check_keywords(overrides, also)
        if isinstance(preset, TaskSpec):
            return preset.with_options(**overrides)
        options = {**(preset or {}), **overrides}
        check_keywords(options, also)
        if "vehicle" not in options:
            raise ConfigError("vehicle", MISSING, VEHICLES)
        return cls(options.pop("vehicle")).with_options(**options)


def _alias(group: str, key: str) -> property:
    return property(lambda self: getattr(getattr(self, group), key), doc=f"``{group}.{key}`` (read-only)")


for _key, _name in OPTION_GROUP.items():
    setattr(TaskSpec, _key, _alias(_name, _key))

#: every keyword a :class:`TaskSpec` takes: ``vehicle``, ``model``, the group names and the flat options
KEYWORDS: tuple[str, ...] = ("vehicle", "model", *GROUPS, *OPTION_GROUP)


def check_keywords(options: Mapping[str, Any], also: tuple[str, ...] = ()) -> None:
    """Refuse an unknown keyword: a one-line :class:`~lvgym.errors.ConfigError` with the closest of the
    known ones (and of ``also``, an env's own keywords) and where the options are documented."""
    for key in options:
        if key not in KEYWORDS:
            close = did_you_mean(key, sorted(set(KEYWORDS) | set(also)))
            raise ConfigError(key, options[key], f"unknown option{close}; "
                              f"the env options: {OPTIONS_DOC}")


#: where the env options are documented (what an unknown option's error points to)
OPTIONS_DOC = "help(lvgym.envs.TaskSpec)"
#: the keys ``reset(options=...)`` takes (none: every option is a keyword of the env's constructor)
RESET_OPTIONS: tuple[str, ...] = ()


def check_reset_options(options: Mapping[str, Any] | None) -> None:
    """Refuse a key of ``reset(options=...)`` that is not in :data:`RESET_OPTIONS`: a one-line
    :class:`~lvgym.errors.ConfigError` naming the key and the keys allowed (an option given there would
    otherwise be ignored without a word)."""
    for key, value in (options or {}).items():
        if key not in RESET_OPTIONS:
            allowed = f"one of {RESET_OPTIONS}" if RESET_OPTIONS else "none"
            hint = f"; {key!r} is an env keyword (gymnasium.make(env_id, {key}=...))" \
                if key in KEYWORDS else did_you_mean(key, RESET_OPTIONS)
            raise ConfigError(f"reset(options)[{key!r}]", value, f"unknown reset option (allowed keys: {allowed}){hint}; "
                              f"the env options: {OPTIONS_DOC}")
