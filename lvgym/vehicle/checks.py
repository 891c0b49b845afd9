"""Whole-vehicle consistency checks of a parsed definition (what one key alone cannot tell).

Overlapping tanks, a gimbal outside the vehicle, a tank that feeds an engine its stage does not have,
a mixture with no oxidiser, a staging sequence that skips a stage; a tank, grain or nozzle wider than its
stage; an engine or a structure whose CG or gimbal is outside its stage (along the axis or off it); a
sensor off the stack; a file's tables over flight time against the rest of the vehicle (:func:`check_tables`:
stations on it, jumps at separations, the mass drop against the engines' flow): each raises
:class:`lvgym.errors.ConfigError` naming the file, the key path, the value and what is allowed.
"""

from __future__ import annotations

import math

import numpy as np

from lvgym.errors import ConfigError

from .definition import Vehicle
from .massmodel import MassModel
from .sections import MATERIALS
from .timetables import FLOW_ATOL_SHARE, FLOW_RTOL, JUMP_SNAP_S, TimeTable, snap_jumps

__all__ = ["check_tables", "check_vehicle", "separations"]

_TOL = 1e-9


def check_vehicle(v: Vehicle) -> None:
    """Raise :class:`ConfigError` on the first inconsistency of ``v``."""
    src = v.source
    if not v.stages:
        raise ConfigError("stages", [], "at least one stage", src)
    _unique([s.name for s in v.stages], "stages", "name", src)
    # stages stacked without overlap, first stage at the bottom
    for i in range(1, len(v.stages)):
        lower, upper = v.stages[i - 1], v.stages[i]
        if lower.top > upper.bottom + _TOL:
            raise ConfigError(f"{upper.key}.top", upper.top,
                              f"stage {upper.name!r} must sit above stage {lower.name!r} (firing order is "
                              f"bottom first): its bottom {upper.bottom:g} must be >= {lower.top:g}", src)
    length = v.length
    ranges: list[tuple[float, float, str, str]] = []
    for s in v.stages:
        engines = {e.name: e for e in s.engines}
        _unique([e.name for e in s.engines], f"{s.key}.engines", "name", src)
        for e in s.engines:
            if not -length - _TOL <= e.gimbal[0] <= 0.0:
                raise ConfigError(f"{e.key}.gimbal", float(e.gimbal[0]),
                                  f"the gimbal must lie on the vehicle: station in [{-length:g}, 0]", src)
        for t in s.tanks:
            if t.engine not in engines:
                raise ConfigError(f"{t.key}.engine", t.engine, f"one of the stage's engines {sorted(engines)}", src)
            _inside(t.top, t.bottom, s, f"{t.key}.top", src)
            ranges.append((t.top, t.bottom, f"{t.key}.top", t.name))
        if s.grain is not None:
            g = s.grain
            if g.engine not in engines:
                raise ConfigError(f"{g.key}.engine", g.engine, f"one of the stage's engines {sorted(engines)}", src)
            _inside(g.top, g.bottom, s, f"{g.key}.top", src)
            ranges.append((g.top, g.bottom, f"{g.key}.top", g.name))
        for sec in s.sections:
            _inside(sec.top, sec.bottom, s, f"{sec.key}.top", src)
        for e in s.engines:
            _check_mixture(s, e, src)
    _check_parts_and_sections(v, length, src)
    _check_fit(v, src)
    ranges.sort(key=lambda r: -r[0])
    for (top_a, bottom_a, _, name_a), (top_b, _, key_b, name_b) in zip(ranges, ranges[1:]):
        if top_b > bottom_a + _TOL:
            raise ConfigError(key_b, top_b, f"tanks must not overlap: {name_b!r} (top {top_b:g}) reaches into "
                              f"{name_a!r} ({top_a:g} to {bottom_a:g}); its top must be <= {bottom_a:g}", src)
    if v.staging and v.staging[0].ignition_delay != 0.0:
        raise ConfigError("staging[0].ignition_delay", v.staging[0].ignition_delay,
                          "must be 0: the first stage ignites at lift-off, t = 0", src)
    names = [st.stage for st in v.staging]
    expected = [s.name for s in v.stages]
    if names != expected:
        raise ConfigError("staging", names, f"one step per stage, in firing order: {expected}", src)
    for i, step in enumerate(v.staging[:-1]):
        if step.separation_delay is None:
            raise ConfigError(f"staging[{i}].separation_delay", None,
                              f"required (>= 0 s): stage {v.staging[i + 1].stage!r} above ignites only after "
                              f"{step.stage!r} separates", src)
    for i, sensor in enumerate(v.structure.sensor_stations):
        if not -length <= sensor <= 0.0:
            raise ConfigError(f"structure.sensor_stations[{i}]", sensor, f"must lie on the vehicle: [{-length:g}, 0]",
                              src)


def _check_parts_and_sections(v, length: float, src: str | None) -> None:
    """Rigid parts on the vehicle; stiffness sections of a stage tile it, stages with sections touch."""
    parts = [(f"{s.key}.structure.cg", s.structure.cg) for s in v.stages]
    parts += [(f"{e.key}.cg", e.part.cg) for s in v.stages for e in s.engines]
    parts += [(key, part.cg) for key, part in (("payload.cg", v.payload), ("fairing.cg", v.fairing)) if part]
    for key, cg in parts:
        if not -length - _TOL <= cg[0] <= 0.0:
            raise ConfigError(key, float(cg[0]), f"must lie on the vehicle: station in [{-length:g}, 0]", src)
    for s in v.stages:
        if not s.sections:
            continue
        for sec in s.sections:
            if sec.material is not None and sec.material not in MATERIALS:
                raise ConfigError(f"{sec.key}.material", sec.material, f"one of {sorted(MATERIALS)}", src)
        spans = sorted(((sec.top, sec.bottom, sec.key) for sec in s.sections), reverse=True)
        edge = s.top
        for top, bottom, key in spans:
            if abs(top - edge) > 1e-6:
                raise ConfigError(f"{key}.top", top, f"sections must tile stage {s.name!r} from {s.top:g} to "
                                  f"{s.bottom:g} without gaps or overlaps: expected {edge:g}", src)
            edge = bottom
        if abs(edge - s.bottom) > 1e-6:
            raise ConfigError(f"{spans[-1][2]}.bottom", edge, f"sections must reach the bottom of stage "
                              f"{s.name!r}: {s.bottom:g}", src)
    with_sections = [s for s in v.stages if s.sections]
    for lower, upper in zip(with_sections, with_sections[1:]):
        if abs(lower.top - upper.bottom) > 1e-6:
            raise ConfigError(f"{upper.key}.top", upper.top, f"stages with bending sections must touch: the bottom "
                              f"of {upper.name!r} ({upper.bottom:g}) must equal the top of {lower.name!r} "
                              f"({lower.top:g})", src)


def _check_fit(v, src: str | None) -> None:
    """Every part within the radius of its stage, engines and structures within their stage's stations."""
    widest = max(s.outer_diameter for s in v.stages) / 2
    for s in v.stages:
        radius = s.outer_diameter / 2
        for t in s.tanks:
            if t.inner_radius > radius + _TOL:
                raise ConfigError(f"{t.key}.inner_radius", t.inner_radius, f"at most the outer radius of stage "
                                  f"{s.name!r}, {radius:g} m (outer_diameter {s.outer_diameter:g}): a tank must fit "
                                  "inside its stage", src)
        if s.grain is not None and s.grain.outer_radius > radius + _TOL:
            raise ConfigError(f"{s.grain.key}.outer_radius", s.grain.outer_radius, f"at most the outer radius of "
                              f"stage {s.name!r}, {radius:g} m: the grain must fit inside its stage", src)
        points = [(f"{s.key}.structure.cg", s.structure.cg)]
        for e in s.engines:
            points += [(f"{e.key}.cg", e.part.cg), (f"{e.key}.gimbal", e.gimbal)]
            exit_d = math.sqrt(4.0 * e.nozzle_exit_area / math.pi)
            if exit_d > s.outer_diameter + _TOL:
                raise ConfigError(f"{e.key}.nozzle_exit_area", e.nozzle_exit_area, f"a nozzle exit no wider than "
                                  f"stage {s.name!r} ({s.outer_diameter:g} m): at most "
                                  f"{math.pi * s.outer_diameter**2 / 4:.4g} m^2 (this one is {exit_d:.3g} m across)",
                                  src)
        for key, point in points:
            x, off = float(point[0]), math.hypot(float(point[1]), float(point[2]))
            if not s.bottom - _TOL <= x <= s.top + _TOL:
                raise ConfigError(key, x, f"must lie within stage {s.name!r}: station in [{s.bottom:g}, {s.top:g}]", src)
            if off > radius + _TOL:
                raise ConfigError(key, [float(c) for c in point], f"must lie within stage {s.name!r}: at most its "
                                  f"radius {radius:g} m off the axis (this is {off:.3g} m)", src)
    for key, part in (("payload.cg", v.payload), ("fairing.cg", v.fairing)):
        if part is not None and math.hypot(float(part.cg[1]), float(part.cg[2])) > widest + _TOL:
            raise ConfigError(key, [float(c) for c in part.cg], f"must lie within the stack: at most its largest "
                              f"radius {widest:g} m off the axis", src)


def _unique(names: list[str], key: str, what: str, src: str | None) -> None:
    seen: set[str] = set()
    for i, name in enumerate(names):
        if name in seen:
            raise ConfigError(f"{key}[{i}].{what}", name, "must be unique", src)
        seen.add(name)


def _inside(top: float, bottom: float, stage, key: str, src: str | None) -> None:
    if top > stage.top + _TOL or bottom < stage.bottom - _TOL:
        raise ConfigError(key, top, f"must lie within stage {stage.name!r}, stations {stage.top:g} to "
                          f"{stage.bottom:g} (it spans {top:g} to {bottom:g})", src)


def _check_mixture(stage, engine, src: str | None) -> None:
    feeds = [t for t in stage.tanks if t.engine == engine.name]
    roles = {t.role for t in feeds}
    if stage.grain is not None and stage.grain.engine == engine.name:
        roles.add("fuel")
    if engine.mixture_ratio is None:
        if roles - {"propellant"}:
            raise ConfigError(f"{engine.key}.mixture_ratio", None,
                              f"required: the engine is fed by {sorted(roles)} (O/F > 0)", src)
        wanted = ("propellant",)
    else:
        wanted = ("oxidiser", "fuel")
        if "propellant" in roles or not set(wanted) <= roles:
            raise ConfigError(f"{engine.key}.mixture_ratio", engine.mixture_ratio,
                              "a mixture needs one or more 'oxidiser' and 'fuel' tanks (or a grain) and no "
                              f"'propellant' tank; the engine is fed by {sorted(roles)}", src)
    for role in wanted:
        tanks = [t for t in feeds if t.role == role]
        if not tanks:
            if role == "fuel" and stage.grain is not None:
                continue
            raise ConfigError(f"{engine.key}.name", engine.name, f"no {role!r} tank feeds this engine", src)
        total = sum(t.share for t in tanks)
        grain_feeds = role == "fuel" and stage.grain is not None and stage.grain.engine == engine.name
        if grain_feeds and total > 1.0 + 1e-6:
            raise ConfigError(f"{tanks[0].key}.share", [t.share for t in tanks],
                              f"the fuel tanks of engine {engine.name!r} may take at most all of the fuel flow "
                              "(the grain burns the rest)", src)
        if not grain_feeds and abs(total - 1.0) > 1e-6:
            raise ConfigError(f"{tanks[0].key}.share", [t.share for t in tanks],
                              f"the shares of the {role!r} tanks of engine {engine.name!r} must add up to 1", src)


# ---------------------------------------------------------------------------- the tables
def separations(vehicle: Vehicle, t_end: float) -> list[float]:
    """The times [s] of the separations and the fairing jettison up to ``t_end``."""
    mm = MassModel(vehicle)
    _, events = mm.advance(mm.initial_state(), t_end)
    return sorted({t for t, e in events if e.endswith("separation") or e == "fairing jettison"})


def check_tables(vehicle: Vehicle) -> None:
    """The tables against the rest of the vehicle: CG stations on it, no more mode tables than
    ``structure.n_modes``, jumps at separations, and the mass drop against the engines' flow (module
    docstring). A :class:`ConfigError` names the row, its numbers and what is allowed."""
    tables = vehicle.tables
    if tables is None:
        return
    if len(tables.modes) > vehicle.structure.n_modes:
        raise ConfigError("tables.modes", len(tables.modes), f"at most structure.n_modes = "
                          f"{vehicle.structure.n_modes} mode tables, one per mode from the first", vehicle.source)
    every = ([tables.mass_properties] if tables.mass_properties else []) + list(tables.modes)
    end = max(float(tb.t[-1]) for tb in every)
    events = separations(vehicle, end + JUMP_SNAP_S)
    for i, tb in enumerate(tables.modes):
        snap_jumps(tb, events)
        if tb.imu_station is not None and tb.imu_station < -vehicle.length:
            raise ConfigError(f"tables.modes[{i}].imu_station", tb.imu_station, f"a station on the vehicle: in "
                              f"[{-vehicle.length:g}, 0] m", vehicle.source)
    mass = tables.mass_properties
    if mass is None:
        return
    for k, x in enumerate(mass.values[:, 1]):
        if x < -vehicle.length:
            raise mass.error(k, f"a CG station on the vehicle: in [{-vehicle.length:g}, 0] m")
    _check_flow(vehicle, snap_jumps(mass, events))


def _check_flow(vehicle: Vehicle, mass: TimeTable) -> None:
    """The table's mass drop from its first row (jumps left out) against the propellant the engines burn."""
    mm = MassModel(vehicle)
    times = np.unique(mass.t)
    stretches, _ = mm.history(times)
    left = np.concatenate([s.tank_mass.sum(axis=1) + s.grain_mass.sum(axis=1) for s in stretches])
    burnt = left[0] - left[np.searchsorted(times, mass.t)]                  # [kg] per row
    m = mass.values[:, 0]
    steps = np.where(np.diff(mass.t) > 0.0, -np.diff(m), 0.0)
    drop = np.concatenate([[0.0], np.cumsum(steps)])                         # [kg] per row, jumps left out
    tol = FLOW_RTOL * burnt[-1] + FLOW_ATOL_SHARE * m[0]
    for k in range(m.size):
        if abs(drop[k] - burnt[k]) > tol:
            raise mass.error(k, f"a mass drop from {mass.t[0]:g} s to {mass.t[k]:g} s (jumps aside) of "
                             f"{drop[k]:.6g} kg: the engines burn {burnt[k]:.6g} kg by their mass flow, and the two "
                             f"must agree within {tol:.4g} kg ({FLOW_RTOL:g} of the {burnt[-1]:.6g} kg burnt over "
                             f"the table plus {FLOW_ATOL_SHARE:g} of the first mass); a staging drop is a jump "
                             "(its time given twice)")
