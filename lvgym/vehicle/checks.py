"""Whole-vehicle consistency checks of a parsed definition (what one key alone cannot tell).

Overlapping tanks, a gimbal outside the vehicle, a tank that feeds an engine its stage does not have,
a mixture with no oxidiser, a staging sequence that skips a stage: each raises
:class:`lvgym.errors.ConfigError` naming the file, the key path, the value and what is allowed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lvgym.errors import ConfigError

if TYPE_CHECKING:
    from .config import Vehicle

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
        if abs(total - 1.0) > 1e-6:
            raise ConfigError(f"{tanks[0].key}.share", [t.share for t in tanks],
                              f"the shares of the {role!r} tanks of engine {engine.name!r} must add up to 1", src)
