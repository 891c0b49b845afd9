"""The aerodynamic models of a vehicle's stages and their aeroelastic strips, built once per vehicle object.

A simulator and its timeline both need them: the timeline tabulates the mode shapes at the strips'
stations (:func:`aeroelastic_strips`, asked for before the timeline's cache is looked up), the simulator
flies the models (:func:`stage_aerodynamics`, :func:`vehicle_strips`). Generating the Barrowman tables of
a vehicle takes 1-2 ms, its strip distributions a few tenths more, so the models of the vehicle file's own
``aerodynamics`` are kept with the :class:`~lvgym.vehicle.Vehicle` object they were built for (as long as
that object lives; the envs share one per vehicle key, :func:`lvgym.envs.functional.cached_vehicle`) and
built again for any other object, even one of equal content. The models are read-only after construction.
"""

from __future__ import annotations

import threading
import weakref
from typing import Any

import numpy as np

from lvgym.environment import make
from lvgym.vehicle import Vehicle

from .strips import strip_models, strip_stations

__all__ = ["aeroelastic_strips", "stage_aerodynamics", "vehicle_strips"]

#: id of a vehicle object -> (weak reference to it, {what: built models}); the entry goes with the object
_BUILT: dict[int, tuple[weakref.ref, dict[str, list[Any]]]] = {}
_LOCK = threading.Lock()


def _built(vehicle: Vehicle) -> dict[str, list[Any]]:
    """The models built so far for this vehicle object (a new, empty record for a new object)."""
    key = id(vehicle)
    with _LOCK:
        entry = _BUILT.get(key)
        if entry is None or entry[0]() is not vehicle:
            def forget(ref: weakref.ref, key: int = key) -> None:
                with _LOCK:
                    if key in _BUILT and _BUILT[key][0] is ref:
                        del _BUILT[key]
            entry = _BUILT[key] = (weakref.ref(vehicle, forget), {})
        return entry[1]


def _build_stage_aerodynamics(vehicle: Vehicle, aerodynamics: Any) -> list[Any]:
    from_vehicle = isinstance(aerodynamics, str) and aerodynamics == "vehicle"
    if from_vehicle:
        aerodynamics = vehicle.aerodynamics or None
    first = make("aerodynamics", aerodynamics) if isinstance(aerodynamics, (str, dict)) else aerodynamics
    out = [first]
    for stage in vehicle.stages[1:]:
        own = stage.aerodynamics if from_vehicle and first is not None else None
        out.append(make("aerodynamics", own) if own else out[-1])
    return out


def stage_aerodynamics(vehicle: Vehicle, aerodynamics: Any = "vehicle") -> list[Any]:
    """The aerodynamic model of each stage (in force while it is the lowest attached one; all None
    without aerodynamics): ``"vehicle"`` gives the vehicle file's ``aerodynamics`` and each stage's own
    where it has one, else the stack's before it (built once per vehicle object, see the module
    docstring); a name, mapping or model flies the whole flight (built at each call)."""
    if not (isinstance(aerodynamics, str) and aerodynamics == "vehicle"):
        return _build_stage_aerodynamics(vehicle, aerodynamics)
    built = _built(vehicle)
    if "stages" not in built:
        built["stages"] = _build_stage_aerodynamics(vehicle, aerodynamics)
    return list(built["stages"])


def vehicle_strips(vehicle: Vehicle, stages: list[Any]) -> list[Any]:
    """:func:`.strips.strip_models` of ``stages``, kept with the vehicle object when ``stages`` are its
    own models (:func:`stage_aerodynamics` with ``"vehicle"``)."""
    built = _built(vehicle)
    own = built.get("stages")
    if own is None or len(own) != len(stages) or any(a is not b for a, b in zip(own, stages)):
        return strip_models(stages)
    if "strips" not in built:
        built["strips"] = strip_models(stages)
    return list(built["strips"])


def aeroelastic_strips(vehicle: Vehicle, aerodynamics: Any = "vehicle", aeroelastic: bool | None = None
                       ) -> np.ndarray | None:
    """The strip stations (n_stages, n) [m] a timeline needs for a simulator of ``vehicle`` with these
    options (None: no aeroelastic loads), for :func:`.tabulate.build_timeline`'s ``strip_stations``."""
    on = vehicle.structure.aeroelastic if aeroelastic is None else aeroelastic
    stages = stage_aerodynamics(vehicle, aerodynamics) if on else [None]
    return None if stages[0] is None else strip_stations(vehicle_strips(vehicle, stages))
