"""Vehicle definitions: YAML files read into frozen, validated dataclasses (:mod:`.definition`; this module
repeats their names), checked as a whole (:mod:`.checks`).

A vehicle is a stack of stages listed in firing order (the first stage fires first and sits at the
bottom), an optional payload and fairing, a staging sequence and the options of the structural model.
Positions are stations: body-axis coordinates from the nose tip in metres, zero or negative
(``-9.0`` or ``[-9.0, 0, 0]``). The format is documented key by key in ``docs/vehicles.md``; the
shipped vehicles live in ``lvgym/vehicles/``. Every error names the file, the key path, the value and
what is allowed, e.g. ``smile.yaml, line 84: stages[0].tanks[1].fill_ratio = 1.3: must be in [0, 1]``.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError

from .checks import check_tables, check_vehicle
from .definition import (G0, MAX_TIME, TANK_ROLES, Engine, Grain, RigidPart, Section, Stage, StagingStep,
                         StructureOptions, Tank, Vehicle)
from .limits import read_qalpha_limit
from .reader import Reader
from .timetables import file_digests, read_tables, tables_beside

__all__ = ["G0", "TANK_ROLES", "VEHICLE_DIR", "Engine", "Grain", "RigidPart", "Section", "Stage", "StagingStep",
           "StructureOptions", "Tank", "Vehicle", "clear_vehicle_cache", "load_vehicle", "parse_vehicle",
           "shipped_vehicles", "vehicle_file"]

VEHICLE_DIR = Path(__file__).resolve().parent.parent / "vehicles"


def shipped_vehicles() -> list[str]:
    """Names of the vehicles shipped in ``lvgym/vehicles/``."""
    return sorted(p.stem for p in VEHICLE_DIR.glob("*.yaml"))


#: vehicles read by :func:`load_vehicle`, by (file, content digest), the latest last, each with the digests of
#: the table files it read (:func:`.timetables.file_digests`)
_LOADED: OrderedDict[tuple[str, bytes], tuple[Vehicle, tuple]] = OrderedDict()
_LOADED_MAX = 32
_LOADED_LOCK = threading.Lock()


def clear_vehicle_cache() -> None:
    """Forget the vehicles :func:`load_vehicle` keeps (the next load of each file parses it again)."""
    with _LOADED_LOCK:
        _LOADED.clear()


def vehicle_file(name_or_path: str | Path) -> Path:
    """The file of a vehicle: a shipped name (``"smile"``, ``"family/test_20000"``: ``lvgym/vehicles/<name>.yaml``)
    or a path as given (a name without its file is a :class:`ConfigError` listing the shipped vehicles)."""
    path = Path(name_or_path)
    if path.suffix:
        return path
    path = VEHICLE_DIR / f"{name_or_path}.yaml"
    if not path.exists():
        raise ConfigError("vehicle", str(name_or_path), f"one of the shipped vehicles {shipped_vehicles()} or a "
                          "YAML path")
    return path


def load_vehicle(name_or_path: str | Path) -> Vehicle:
    """Read a vehicle: a shipped name (``"smile"``) or a path to a YAML file.

    Every problem is a :class:`ConfigError` naming the file (and, where it is known, the line), the key
    path, the value and what is allowed: a missing file (with the shipped vehicles), a YAML syntax error,
    an unsafe tag, a duplicate key (:mod:`.yamlfile`), an unknown, missing or out-of-range value, and
    parts that do not fit the vehicle (:mod:`.checks`).

    The process keeps the last few vehicles it read, by file and content: loading a file again whose
    bytes (and those of the CSV files of its ``tables``) have not changed returns the same (frozen)
    :class:`Vehicle` object without parsing it, and with it the aerodynamic tables built for that object
    (:mod:`lvgym.simulator.vehicleaero`). Treat it as read-only; :func:`clear_vehicle_cache` forgets them."""
    from .yamlfile import read_yaml, with_line

    path = vehicle_file(name_or_path)
    if not path.is_file():
        what = "it is a folder" if path.is_dir() else "there is no such file"
        raise ConfigError("vehicle", str(name_or_path), f"an existing YAML file ({what}) or one of the shipped "
                          f"vehicles {shipped_vehicles()}")
    try:
        raw = path.read_bytes()
        text = raw.decode("utf-8")
    except (OSError, UnicodeDecodeError):
        raw = text = None                           # read_yaml names the problem
    key = None
    if raw is not None:
        key = (str(path.resolve()), hashlib.blake2b(raw, digest_size=16).digest())
        with _LOADED_LOCK:
            hit = _LOADED.get(key)
        if hit is not None and file_digests([f for f, _ in hit[1]]) == hit[1]:     # its table files unchanged
            with _LOADED_LOCK:
                if key in _LOADED:
                    _LOADED.move_to_end(key)
            return hit[0]
    data, lines = read_yaml(path, source=path.name, text=text)
    _tables_beside(data, path.resolve().parent)
    files = tables_beside(data, path.resolve().parent)
    try:
        vehicle = parse_vehicle(data, source=path.name)
    except ConfigError as exc:
        raise with_line(exc, lines) from None
    if key is not None:
        with _LOADED_LOCK:
            _LOADED[key] = (vehicle, file_digests(files))
            while len(_LOADED) > _LOADED_MAX:
                _LOADED.popitem(last=False)
    return vehicle


def _tables_beside(data: Any, folder: Path) -> None:
    """Resolve, in place, every relative ``table`` path of the file's aerodynamics (the top level's and each
    stage's, nested models included) against ``folder``, the folder of the YAML file that names it; an
    absolute path, or a table given inline as a mapping, stays as it is."""
    def walk(node: Any) -> None:
        if isinstance(node, dict):
            table = node.get("table")
            if isinstance(table, str) and table and not Path(table).is_absolute():
                node["table"] = str(folder / table)
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    if not isinstance(data, dict):
        return
    walk(data.get("aerodynamics"))
    for stage in data.get("stages") or []:
        if isinstance(stage, dict):
            walk(stage.get("aerodynamics"))


def parse_vehicle(data: Any, source: str | None = None) -> Vehicle:
    """Build a :class:`Vehicle` from a mapping (a parsed YAML document) and check it as a whole."""
    r = Reader(data, "", source)
    stages = tuple(Stage.read(s) for s in r.children("stages"))
    payload_r = r.child("payload", None)
    payload = RigidPart.read(payload_r, "payload") if payload_r else None
    if payload_r:
        payload_r.done()
    fairing_r = r.child("fairing", None)
    fairing, jettison = None, None
    if fairing_r:
        fairing = RigidPart.read(fairing_r, "fairing")
        jettison = fairing_r.number("jettison_time", None, lo=0.0, hi=MAX_TIME)
        fairing_r.done()
    aero = r.raw("aerodynamics", {})
    if not isinstance(aero, dict):
        raise r.error("aerodynamics", aero, "must be a mapping")
    vehicle = Vehicle(name=r.text("name"), description=r.text("description", None) or "", stages=stages,
                      payload=payload, fairing=fairing, fairing_jettison=jettison,
                      staging=tuple(StagingStep.read(s) for s in r.children("staging")),
                      structure=StructureOptions.read(r.child("structure", None)), aerodynamics=aero,
                      source=source, qalpha_limit=read_qalpha_limit(r), tables=read_tables(r))
    r.done()
    check_vehicle(vehicle)
    check_tables(vehicle)
    return vehicle
