"""What a design is made for: a shipped vehicle's env, or a user's vehicle file flown in a protocol's env;
and how the design's operating points are flown there.

Every design tool (:mod:`.linearize`, :mod:`.tune`, :mod:`.flexdesign`, :mod:`.lqg_design`,
:mod:`.charts`) goes through :func:`design_env`: a shipped name (``smile``, ``stratos3``, ``slender``) is
its own env of the protocol (:data:`ENV_IDS`); anything else is a vehicle YAML file, read and checked
here (a missing or invalid file is a one-line :class:`~lvgym.errors.ConfigError` naming the file, before
any flight), and flown in :data:`FILE_ENV` of the protocol with the file as the env's ``vehicle``
(``gymnasium.make(FILE_ENV[protocol], vehicle=path)``: SMILE's launch, timing, physics, sensors and delay
of that protocol; env keywords change any of them).

An operating point is flown up to its flight time either with the gimbal centred (``fly="centred"``, what
the shipped designs do) or with a stabilising controller (:func:`schedule_flyer`: a gain-scheduled PID of a
rigid schedule; :func:`privileged_flyer`: the privileged reference, which needs no design for the vehicle
since it reads the true state, and so flies every operating point of every design the same way): a vehicle
that is unstable without control (a launcher in the atmosphere with its centre of pressure ahead of its
centre of mass) tumbles with the gimbal centred and never reaches max q.
:func:`fly_mode` says which a tool uses by default: centred for a shipped vehicle (its results unchanged),
a stabilising controller for a file.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

from lvgym.errors import ConfigError

#: the env of each shipped vehicle per protocol version (the vehicle's own file in v1: ``smile_v1`` for SMILE)
ENV_IDS = {"v0": {"smile": "lvgym/SmileAscent-v0", "stratos3": "lvgym/StratosIII-v0", "slender": "lvgym/SlenderAscent-v0"},
           "v1": {"smile": "lvgym/SmileAscent-v1", "stratos3": "lvgym/StratosIII-v1", "slender": "lvgym/SlenderAscent-v1"}}
#: the env a vehicle file is flown in, per protocol (its preset with the file as the vehicle)
FILE_ENV = {"v0": "lvgym/SmileAscent-v0", "v1": "lvgym/SmileAscent-v1"}
#: how operating points are flown: ``centred`` (the gimbal at zero), ``rows`` (the rigid PID schedule of
#: the rows designed so far, :mod:`.tune`), ``pid`` (a rigid PID schedule designed first), ``privileged``
#: (the privileged reference, :func:`privileged_flyer`), or a schedule file or shipped schedule name
FLY_MODES = ("auto", "centred", "rows", "pid", "privileged")


def _allowed(protocol: str) -> str:
    return f"one of the shipped vehicles {sorted(ENV_IDS[protocol])} or the path of a vehicle YAML file"


def is_shipped(vehicle: Any, protocol: str = "v1") -> bool:
    """Whether ``vehicle`` is a shipped vehicle's name (of ``protocol``'s envs)."""
    return isinstance(vehicle, str) and vehicle in ENV_IDS.get(protocol, {})


def check_vehicle(vehicle: Any, protocol: str = "v1") -> str:
    """``vehicle`` as a design tool takes it: a shipped name as itself, else a vehicle file's path, read and
    checked (:func:`lvgym.vehicle.config.load_vehicle`: a missing file, a YAML error or a bad value is a
    one-line :class:`~lvgym.errors.ConfigError` naming the file, line, key, value and what is allowed)."""
    if protocol not in ENV_IDS:
        raise ConfigError("protocol", protocol, f"one of {sorted(ENV_IDS)}")
    if is_shipped(vehicle, protocol):
        return vehicle
    if not isinstance(vehicle, (str, os.PathLike)) or not os.fspath(vehicle):
        raise ConfigError("vehicle", vehicle, _allowed(protocol))
    path = os.fspath(vehicle)
    if not Path(path).suffix:                         # a name that is not a shipped vehicle of the protocol
        raise ConfigError("vehicle", path, _allowed(protocol))
    from lvgym.vehicle.config import load_vehicle

    load_vehicle(path)
    return path


def design_env(vehicle: Any, protocol: str = "v1") -> tuple[str, dict[str, Any]]:
    """The env id and env keywords that fly ``vehicle`` (a shipped name or a vehicle file, see the module
    docstring) in ``protocol`` (``v0``, ``v1``)."""
    v = check_vehicle(vehicle, protocol)
    if is_shipped(v, protocol):
        return ENV_IDS[protocol][v], {}
    return FILE_ENV[protocol], {"vehicle": v}


def stem(vehicle: Any) -> str:
    """The name a design's output files carry: a shipped vehicle's name, or a vehicle file's stem."""
    return vehicle if is_shipped(vehicle) or is_shipped(vehicle, "v0") else Path(os.fspath(vehicle)).stem


def check_fly(fly: str, option: str = "fly") -> str:
    """``fly``: one of :data:`FLY_MODES`, or a gain schedule (a shipped schedule's name or a YAML path)
    that loads."""
    if fly in FLY_MODES:
        return fly
    from ..pid import GainSchedule

    try:
        GainSchedule.load(fly)
    except (OSError, KeyError, ValueError) as exc:
        raise ConfigError(option, fly, f"one of {list(FLY_MODES)} or a readable gain schedule ({exc})") from None
    return fly


def fly_mode(fly: str, vehicle: Any) -> str:
    """``fly`` with ``auto`` resolved: ``centred`` for a shipped vehicle, a stabilising controller for a file
    (``default``, the tool's own)."""
    if fly != "auto":
        return fly
    return "centred" if is_shipped(vehicle) or is_shipped(vehicle, "v0") else "pid"


def schedule_flyer(schedule: Any, name: str = "gs-pid") -> Callable[[Any], Any]:
    """A policy factory ``env -> policy`` flying the gain-scheduled PID of ``schedule`` (a
    :class:`~lvgym.baselines.pid.GainSchedule`, a mapping with ``rows`` as :mod:`.tune` writes them, a
    shipped schedule's name or a YAML path), as :func:`.linearize.operating_point` takes it."""
    from ..pid import GainSchedule, GainScheduledPIDPolicy

    if isinstance(schedule, dict):
        schedule = GainSchedule.from_dict(schedule)
    elif not isinstance(schedule, GainSchedule):
        schedule = GainSchedule.load(schedule)
    return lambda env: GainScheduledPIDPolicy(schedule, env=env, name=name)


def privileged_flyer() -> Callable[[Any], Any]:
    """A policy factory ``env -> policy`` flying the privileged reference (:mod:`lvgym.baselines.privileged`),
    as :func:`.linearize.operating_point` takes it; its ``env_options`` (``privileged_info=True``, which
    adds keys to the info and changes nothing of the flight) are the env keywords it needs."""
    from ..privileged import PrivilegedPolicy

    def factory(env: Any) -> Any:
        return PrivilegedPolicy(env)

    factory.env_options = {"privileged_info": True}
    factory.reuse_key = "privileged"                 # the same flight for every design (linearize.reused_flights)
    return factory


def flyer(fly: str) -> Callable[[Any], Any] | None:
    """The policy factory of a resolved ``fly`` mode that flies every operating point the same way: None
    for ``centred``, :func:`privileged_flyer` for ``privileged``, :func:`schedule_flyer` for a schedule
    (``rows`` and ``pid`` depend on the tool's own rows: the tools build those)."""
    if fly == "centred":
        return None
    if fly == "privileged":
        return privileged_flyer()
    return schedule_flyer(fly)


def describe(fly: str) -> str:
    """One line saying how the operating points were flown (the outputs carry it)."""
    return {"centred": "gimbal centred (no control) up to each flight time",
            "rows": "the rigid PID schedule of the rows designed so far (the first row with the gimbal centred)",
            "pid": "a rigid PID schedule designed first (lvgym design pid on the same vehicle and times)",
            "privileged": "the privileged reference (true state, no design needed) up to each flight time"}.get(
        fly, f"the gain-scheduled PID of the schedule {fly}")


def vehicle_option(option: str, value: str) -> str:
    """A command line's ``--vehicle`` (an :func:`lvgym.commandline.arg` check): a shipped vehicle's name or the
    path of a vehicle file that reads (its errors name the file, line, key, value and what is allowed)."""
    try:
        return check_vehicle(value)
    except ConfigError as exc:
        if exc.key == "vehicle":
            raise ConfigError(option, exc.value, exc.allowed) from None
        raise


def fly_option(option: str, value: str) -> str:
    """A command line's ``--fly`` (an :func:`lvgym.commandline.arg` check): :func:`check_fly`."""
    return check_fly(value, option)


#: rows of a vehicle file's default schedule (:func:`file_times`)
FILE_ROWS = 8


def burn_phases(vehicle: Any, protocol: str = "v1", option: str = "times") -> tuple[tuple[float, float], ...]:
    """The thrusting phases ``(start, end)`` [s] of ``vehicle`` with the controller on, in ``protocol``'s env
    (:func:`design_env`): the stretches of its timeline where an engine burns, between the controller's
    switch-on and the end of the mission. Fewer than 1 s of them: a ``ConfigError`` naming ``option``."""
    import gymnasium as gym
    import numpy as np

    env_id, kw = design_env(vehicle, protocol)
    func = gym.make(env_id, **kw).unwrapped.func
    t = np.asarray(func.timeline.tables.t, dtype=float)
    spec = func.spec
    on = (np.asarray(func.timeline.tables.burning) != 0.0) & (t >= spec.controller_on_after_s) & \
        (t <= spec.mission_time_s)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(np.int8), [0]])))
    phases = tuple((round(float(t[a]), 2), round(float(t[b - 1]), 2)) for a, b in zip(edges[::2], edges[1::2])
                   if t[b - 1] > t[a])
    if sum(b - a for a, b in phases) < 1.0:
        raise ConfigError(option, None, f"the flight times [s] of the rows: {vehicle} burns for less than 1 s "
                          f"between {spec.controller_on_after_s:g} s and {spec.mission_time_s:g} s, give them")
    return phases


def file_times(vehicle: Any, n: int = FILE_ROWS, protocol: str = "v1", option: str = "times") -> tuple[float, ...]:
    """``n`` flight times [s] for the rows of a vehicle file's schedule: the centres of ``n`` equal parts of
    its :func:`burn_phases` taken end to end (a coast counts for nothing), to 0.1 s."""
    import numpy as np

    phases = burn_phases(vehicle, protocol, option)
    lengths = np.array([b - a for a, b in phases])
    ends = np.cumsum(lengths)
    out = []
    for x in (np.arange(n) + 0.5) / n * ends[-1]:
        k = min(int(np.searchsorted(ends, x)), len(phases) - 1)
        out.append(round(float(phases[k][0] + x - (ends[k] - lengths[k])), 1))
    return tuple(sorted(set(out)))
