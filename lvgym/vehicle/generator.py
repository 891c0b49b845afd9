"""A family of small launchers: from a seed, a physically consistent vehicle file: one or two stages, each
LOX/RP-1 or a solid motor (:mod:`.familystages`; shares ``two_stage_share`` and ``solid_share``).

Each draw picks, uniformly within :class:`FamilyRanges`, the diameter, the slenderness L/D, the share of the
length the two tanks fill and their fill, the lift-off thrust-to-weight, the wall's safety factor on its
axial load, the slosh damping, the nose, and whether the vehicle has fins (and their size). The rest follows
from them, as a preliminary sizing would do it:

- the propellant is what the tanks hold (LOX over RP-1 at a mixture ratio of 2.35, their heights in the
  ratio of their volumes);
- the wall (aluminium 2219-T87, a tube over the whole length) carries the lift-off thrust with the drawn
  safety factor on :data:`WALL_STRESS_PA`, no thinner than :data:`MIN_WALL_M`; the dry structure is
  :data:`STRUCTURE_FACTOR` times the wall (rings, bulkheads, avionics);
- the engine weighs its thrust over :data:`ENGINE_THRUST_TO_WEIGHT`, its mass flow gives the drawn
  thrust-to-weight at sea level (Isp 255 s with a 0.7 bar nozzle exit, the exit area in proportion);
- the payload is a drawn share of the lift-off mass; inertias are those of thin tubes and short cylinders.

The thrust, and so the wall and the engine, depend on the lift-off mass: the sizing iterates to a fixed point.
A draw whose burn time falls outside ``burn_time_s``, or whose file fails the vehicle checks, or that a
given ``check`` refuses (the flight check, :func:`lvgym.baselines.family.flies_nominal`, which flies it), is
redrawn from the next generator of the seed's sequence (``numpy.random.SeedSequence((seed, attempt))``), so
the vehicle of a seed is reproducible. The seeds of the train, validation and test vehicles are disjoint
ranges (:data:`SPLITS`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.errors import ConfigError

from .config import parse_vehicle
from .familystages import G0, stage_file, stage_geometry, stage_masses

__all__ = ["FamilyRanges", "GeneratedVehicle", "SPLITS", "generate", "nominal", "nominal_ranges", "split_seeds"]

#: the seeds of each split of the family (disjoint)
SPLITS = {"train": (0, 10_000), "validation": (10_000, 20_000), "test": (20_000, 30_000)}
MAX_ATTEMPTS = 50
#: a two-stage vehicle's coast from first-stage burnout to separation, and from separation to the second
#: stage's ignition [s]
SEPARATION_DELAY_S, IGNITION_DELAY_S = 0.5, 0.5
_SHARES = ("finned_share", "two_stage_share", "solid_share")


@dataclass(frozen=True)
class FamilyRanges:
    """The ranges a draw is uniform in (each ``(low, high)``), the share of finned vehicles and the burn times
    accepted [s]."""

    diameter_m: tuple[float, float] = (0.4, 1.0)
    slenderness: tuple[float, float] = (10.0, 40.0)
    thrust_to_weight: tuple[float, float] = (1.2, 2.5)
    tank_share: tuple[float, float] = (0.5, 0.65)
    fill_ratio: tuple[float, float] = (0.85, 0.97)
    wall_safety: tuple[float, float] = (1.5, 3.0)
    slosh_damping: tuple[float, float] = (0.005, 0.02)
    nose_calibres: tuple[float, float] = (2.0, 3.5)
    payload_share: tuple[float, float] = (0.02, 0.05)
    fin_span_calibres: tuple[float, float] = (0.5, 0.9)
    finned_share: float = 0.5
    burn_time_s: tuple[float, float] = (30.0, 200.0)
    two_stage_share: float = 0.3
    solid_share: float = 0.3
    upper_share: tuple[float, float] = (0.3, 0.45)
    upper_thrust_to_weight: tuple[float, float] = (1.0, 1.8)
    solid_tail: tuple[float, float] = (0.5, 1.0)

    def __post_init__(self) -> None:
        for key, value in asdict(self).items():
            if key in _SHARES:
                if not 0.0 <= value <= 1.0:
                    raise ConfigError(key, value, "a share in [0, 1]")
            elif not (len(value) == 2 and 0.0 < value[0] <= value[1]):
                raise ConfigError(key, value, "(low, high) with 0 < low <= high")


@dataclass(frozen=True)
class GeneratedVehicle:
    """A drawn vehicle: its ``seed``, the ``attempt`` that passed, the vehicle file as a mapping (``data``) and
    what was drawn or sized (``design``: L/D, thrust-to-weight, masses, burn time, wall, finned)."""

    seed: int
    attempt: int
    data: dict[str, Any]
    design: dict[str, Any]

    def write(self, folder: str | Path) -> Path:
        """Write the vehicle file ``family_<seed>.yaml`` into ``folder``; returns its path."""
        path = Path(folder) / f"family_{self.seed}.yaml"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(yaml.safe_dump(self.data, sort_keys=False), encoding="utf-8")
        return path


def split_seeds(split: str, count: int) -> list[int]:
    """The first ``count`` vehicle seeds of ``split`` (``train``, ``validation`` or ``test``)."""
    if split not in SPLITS:
        raise ConfigError("split", split, f"one of {sorted(SPLITS)}")
    lo, hi = SPLITS[split]
    if not 0 < count <= hi - lo:
        raise ConfigError("count", count, f"an integer in [1, {hi - lo}]")
    return list(range(lo, lo + count))


def _u(rng: np.random.Generator, pair: tuple[float, float]) -> float:
    return float(rng.uniform(pair[0], pair[1]))


def _draw(rng: np.random.Generator, r: FamilyRanges, seed: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """One draw: the vehicle file (a mapping) and its design numbers. The draws of the single-stage liquid
    vehicle come first and in their original order, then those of the kinds (stages, motors), always all of
    them: a draw that comes out single-stage and liquid is the vehicle the generator gave before the kinds."""
    D, ld, tw = _u(rng, r.diameter_m), _u(rng, r.slenderness), _u(rng, r.thrust_to_weight)
    share, fill, safety = _u(rng, r.tank_share), _u(rng, r.fill_ratio), _u(rng, r.wall_safety)
    zeta, nose, pay_share = _u(rng, r.slosh_damping), _u(rng, r.nose_calibres) * D, _u(rng, r.payload_share)
    finned = bool(rng.uniform() < r.finned_share)
    span = _u(rng, r.fin_span_calibres) * D
    two = bool(rng.uniform() < r.two_stage_share)
    solid = [bool(rng.uniform() < r.solid_share) for _ in range(2)]
    upper, tw2 = _u(rng, r.upper_share), _u(rng, r.upper_thrust_to_weight)
    tails = [_u(rng, r.solid_tail) for _ in range(2)]
    L = ld * D
    L2 = nose + upper * (L - nose) if two else 0.0
    # the stages from the bottom: (name, top station, length, has the nose, solid, tail)
    stages = [("stage1", -L2, L - L2, not two, solid[0], tails[0])]
    if two:
        stages.append(("stage2", 0.0, L2, True, solid[1], tails[1]))
    # the tanks fill ``share`` of a single stage's length (nose included, as before the kinds), of the
    # first stage's, and of the second stage's below the nose
    geo = [stage_geometry(D, top, length, nose if has_nose else 0.0,
                          share * (length - (nose if two and has_nose else 0.0)), fill, is_solid)
           for _, top, length, has_nose, is_solid, _ in stages]
    m0 = 1.2 * sum(g["propellant"] for g in geo)
    m_up = 1.2 * geo[-1]["propellant"] if two else m0
    for _ in range(50):                                     # the sizing's fixed point (a contraction)
        thrusts = [tw * m0 * G0] + ([tw2 * m_up * G0] if two else [])
        loads = [thrusts[0]] + ([max(thrusts[0] * m_up / m0, thrusts[1])] if two else [])
        parts = [stage_masses(D, g, loads[i], thrusts[i], safety) for i, g in enumerate(geo)]
        dry = [p["structure"] + g["propellant"] + p["engine"] for p, g in zip(parts, geo)]
        m0 = sum(dry) / (1.0 - pay_share)
        m_up = pay_share * m0 + dry[-1] if two else m0
    m_pay = pay_share * m0
    thrusts = [tw * m0 * G0] + ([tw2 * m_up * G0] if two else [])       # of the sized masses
    built = [stage_file(name, D, g, p, thrusts[i], tail, zeta, i == 1)
             for i, ((name, _, _, _, is_solid, tail), g, p) in enumerate(zip(stages, geo, parts))]
    kind = ("two-stage " if two else "") + "/".join("solid" if st[4] else "liquid" for st in stages)
    data: dict[str, Any] = {
        "name": f"family_{seed}",
        "description": f"lvgym's launcher family, seed {seed}: L/D {ld:.1f}, thrust-to-weight {tw:.2f}"
                       f"{', four fins' if finned else ', finless'}" + (f", {kind}" if kind != "liquid" else ""),
        "stages": [b[0] for b in built],
        "payload": {"mass": round(m_pay, 3), "cg": round(-0.6 * nose, 4),
                    "inertia": [round(0.5 * m_pay * (0.4 * D) ** 2, 4),
                                *[round(m_pay * ((0.6 * nose) ** 2 / 12 + (0.4 * D) ** 2 / 4), 4)] * 2]},
        "staging": ([{"stage": "stage1", "separation_delay": SEPARATION_DELAY_S},
                     {"stage": "stage2", "ignition_delay": IGNITION_DELAY_S}] if two else [{"stage": "stage1"}]),
        "structure": {"n_modes": 2, "damping": 0.01},
        "aerodynamics": {"model": "barrowman", "nose": {"shape": "ogive", "length": round(nose, 4)},
                         "body": {"diameter": round(D, 4), "length": round(L - nose, 4)}},
    }
    if two:                                                  # the upper stack after separation: no fins
        data["stages"][1]["aerodynamics"] = {"model": "barrowman",
                                             "nose": {"shape": "ogive", "length": round(nose, 4)},
                                             "body": {"diameter": round(D, 4), "length": round(L2 - nose, 4)}}
    if finned:
        root = D
        data["aerodynamics"]["fins"] = {"count": 4, "root_chord": round(root, 4), "tip_chord": round(0.5 * root, 4),
                                        "span": round(span, 4), "sweep": round(0.5 * span, 4),
                                        "station": round(-(L - root - 0.05 * D), 4),
                                        "thickness": round(0.01 * D / 0.6, 5)}
    burn = [b[1] for b in built]
    design = {"slenderness": ld, "thrust_to_weight": tw, "diameter_m": D, "length_m": L, "lift_off_mass_kg": m0,
              "propellant_kg": sum(g["propellant"] for g in geo), "structure_kg": sum(p["structure"] for p in parts),
              "engine_kg": sum(p["engine"] for p in parts), "payload_kg": m_pay, "burn_time_s": burn[0],
              "wall_thickness_m": parts[0]["wall"], "finned": finned, "stages": len(stages),
              "motors": ["solid" if st[4] else "liquid" for st in stages], "burn_times_s": burn,
              "walls_m": [p["wall"] for p in parts]}
    if two:
        design |= {"upper_share": upper, "upper_thrust_to_weight": tw2, "upper_stack_kg": m_up,
                   "separation_s": burn[0] + SEPARATION_DELAY_S,
                   "upper_ignition_s": burn[0] + SEPARATION_DELAY_S + IGNITION_DELAY_S}
    return data, design


def nominal_ranges(ranges: FamilyRanges | None = None) -> FamilyRanges:
    """``ranges`` (default the family's) with every range drawn from collapsed to its middle (the burn times
    accepted stay as they are), finless, single-stage and liquid-fuelled: the family's nominal member, whose design the ``fixed`` baselines fly on every vehicle
    (most launchers fly without fins; SMILE is the finned exception)."""
    r = FamilyRanges() if ranges is None else ranges
    mid = {k: (0.5 * (v[0] + v[1]),) * 2 for k, v in asdict(r).items() if k not in (*_SHARES, "burn_time_s")}
    return FamilyRanges(**mid, finned_share=0.0, two_stage_share=0.0, solid_share=0.0)


def nominal(ranges: FamilyRanges | None = None) -> GeneratedVehicle:
    """The family's nominal member (:func:`nominal_ranges`), seed 0 (every draw is then its range's middle)."""
    g = generate(0, nominal_ranges(ranges))
    data = {**g.data, "name": "family_nominal",
            "description": "lvgym's launcher family, the nominal member: every range at its middle, "
                           f"L/D {g.design['slenderness']:.1f}, thrust-to-weight {g.design['thrust_to_weight']:.2f}, finless"}
    return GeneratedVehicle(g.seed, g.attempt, data, g.design)


def generate(seed: int, ranges: FamilyRanges | None = None,
             check: Callable[[dict[str, Any]], bool] | None = None) -> GeneratedVehicle:
    """The vehicle of ``seed`` (module docstring): the first draw of ``SeedSequence((seed, attempt))``,
    attempt 0, 1, ..., whose burn time is in range, whose file passes the vehicle checks and, with ``check``
    (a function of the vehicle file's mapping, e.g. :func:`lvgym.baselines.family.flies_nominal`), that
    ``check`` accepts."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ConfigError("seed", seed, "an integer >= 0")
    r = FamilyRanges() if ranges is None else ranges
    for attempt in range(MAX_ATTEMPTS):
        rng = np.random.default_rng(np.random.SeedSequence((int(seed), attempt)))
        data, design = _draw(rng, r, int(seed))
        if not all(r.burn_time_s[0] <= b <= r.burn_time_s[1] for b in design["burn_times_s"]):
            continue
        try:
            parse_vehicle(data, source=f"family_{seed}.yaml")
        except ConfigError:
            continue
        if check is not None and not check(data):
            continue
        return GeneratedVehicle(int(seed), attempt, data, design)
    raise ConfigError("seed", seed, f"a seed with a vehicle in {MAX_ATTEMPTS} attempts (widen the ranges)")
