"""A family of small launchers: from a seed, a physically consistent single-stage LOX/RP-1 vehicle file.

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

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.errors import ConfigError

from .config import parse_vehicle

__all__ = ["FamilyRanges", "GeneratedVehicle", "SPLITS", "generate", "split_seeds"]

G0 = 9.80665
#: the seeds of each split of the family (disjoint)
SPLITS = {"train": (0, 10_000), "validation": (10_000, 20_000), "test": (20_000, 30_000)}
#: the wall's allowed axial stress before the safety factor [Pa] (2219-T87 yields at about 390 MPa; a thin
#: tube buckles first, so a preliminary sizing takes much less)
WALL_STRESS_PA = 120e6
MIN_WALL_M = 0.0015
STRUCTURE_FACTOR = 1.6
ENGINE_THRUST_TO_WEIGHT = 60.0
ISP_S, EXIT_PRESSURE_PA, SEA_LEVEL_PA = 255.0, 70e3, 101325.0
EXIT_AREA_PER_FLOW = 0.07 / 15.6            # [m^2 per kg/s], a small pressure-fed-class engine
MIXTURE, RHO_LOX, RHO_RP1 = 2.35, 1141.0, 810.0
MAX_ATTEMPTS = 50


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

    def __post_init__(self) -> None:
        for key, value in asdict(self).items():
            if key == "finned_share":
                if not 0.0 <= value <= 1.0:
                    raise ConfigError("finned_share", value, "a share in [0, 1]")
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
    """One draw: the vehicle file (a mapping) and its design numbers."""
    D, ld, tw = _u(rng, r.diameter_m), _u(rng, r.slenderness), _u(rng, r.thrust_to_weight)
    share, fill, safety = _u(rng, r.tank_share), _u(rng, r.fill_ratio), _u(rng, r.wall_safety)
    zeta, nose, pay_share = _u(rng, r.slosh_damping), _u(rng, r.nose_calibres) * D, _u(rng, r.payload_share)
    finned = bool(rng.uniform() < r.finned_share)
    span = _u(rng, r.fin_span_calibres) * D
    L, r_in = ld * D, 0.48 * D
    h = share * L
    h_lox = h * (MIXTURE / RHO_LOX) / (MIXTURE / RHO_LOX + 1.0 / RHO_RP1)
    h_rp1 = h - h_lox
    m_prop = fill * math.pi * r_in ** 2 * (h_lox * RHO_LOX + h_rp1 * RHO_RP1)
    thrust_per_flow = ISP_S * G0 - (SEA_LEVEL_PA - EXIT_PRESSURE_PA) * EXIT_AREA_PER_FLOW
    m0, wall = 1.2 * m_prop, MIN_WALL_M
    for _ in range(50):                                     # the sizing's fixed point (a contraction)
        thrust = tw * m0 * G0
        wall = max(MIN_WALL_M, safety * thrust / (math.pi * D * WALL_STRESS_PA))
        m_struct = STRUCTURE_FACTOR * 2840.0 * math.pi * D * wall * L
        m_engine = thrust / (G0 * ENGINE_THRUST_TO_WEIGHT)
        m0 = (m_struct + m_prop + m_engine) / (1.0 - pay_share)
    m_pay = pay_share * m0
    flow = tw * m0 * G0 / thrust_per_flow
    top_lox = -(nose + 0.1 * D)
    top_rp1 = top_lox - h_lox - 0.05 * D
    bay = L + top_rp1 - h_rp1                               # below the tanks: the engine bay [m]
    j_engine = m_engine / 60.0 * (D / 0.6) ** 2              # scaled from a 60 kg engine of a 0.6 m vehicle
    engine = {"name": "main", "mass": round(m_engine, 3), "cg": round(-(L - 0.2 * bay), 4),
              "inertia": [round(1.5 * j_engine, 4), round(3.0 * j_engine, 4), round(3.0 * j_engine, 4)],
              "gimbal": round(-(L - 0.3 * bay), 4), "gimbal_limit_deg": 6.0, "mass_flow": round(flow, 4),
              "isp": ISP_S, "nozzle_exit_area": round(EXIT_AREA_PER_FLOW * flow, 6),
              "nozzle_exit_pressure": EXIT_PRESSURE_PA, "mixture_ratio": MIXTURE}
    tank = {"engine": "main", "inner_radius": round(r_in, 4), "fill_ratio": round(fill, 4), "slip_factor": 0.95,
            "slosh_damping": round(zeta, 5)}
    data: dict[str, Any] = {
        "name": f"family_{seed}",
        "description": f"lvgym's launcher family, seed {seed}: L/D {ld:.1f}, thrust-to-weight {tw:.2f}"
                       f"{', four fins' if finned else ', finless'}",
        "stages": [{
            "name": "stage1", "top": 0.0, "length": round(L, 4), "outer_diameter": round(D, 4),
            "structure": {"mass": round(m_struct, 3), "cg": round(-0.52 * L, 4),
                          "inertia": [round(m_struct * (D / 2) ** 2, 3),
                                      *[round(m_struct * (L ** 2 / 12 + D ** 2 / 8), 3)] * 2]},
            "sections": [{"top": 0.0, "bottom": round(-L, 4), "material": "al2219_t87",
                          "wall_thickness": round(wall, 6)}],
            "engines": [engine],
            "tanks": [{"name": "lox", "role": "oxidiser", "height": round(h_lox, 4), "top": round(top_lox, 4),
                       "density": RHO_LOX, **tank},
                      {"name": "rp1", "role": "fuel", "height": round(h_rp1, 4), "top": round(top_rp1, 4),
                       "density": RHO_RP1, **tank}]}],
        "payload": {"mass": round(m_pay, 3), "cg": round(-0.6 * nose, 4),
                    "inertia": [round(0.5 * m_pay * (0.4 * D) ** 2, 4),
                                *[round(m_pay * ((0.6 * nose) ** 2 / 12 + (0.4 * D) ** 2 / 4), 4)] * 2]},
        "staging": [{"stage": "stage1"}],
        "structure": {"n_modes": 2, "damping": 0.01},
        "aerodynamics": {"model": "barrowman", "nose": {"shape": "ogive", "length": round(nose, 4)},
                         "body": {"diameter": round(D, 4), "length": round(L - nose, 4)}},
    }
    if finned:
        root = D
        data["aerodynamics"]["fins"] = {"count": 4, "root_chord": round(root, 4), "tip_chord": round(0.5 * root, 4),
                                        "span": round(span, 4), "sweep": round(0.5 * span, 4),
                                        "station": round(-(L - root - 0.05 * D), 4),
                                        "thickness": round(0.01 * D / 0.6, 5)}
    design = {"slenderness": ld, "thrust_to_weight": tw, "diameter_m": D, "length_m": L, "lift_off_mass_kg": m0,
              "propellant_kg": m_prop, "structure_kg": m_struct, "engine_kg": m_engine, "payload_kg": m_pay,
              "burn_time_s": m_prop / flow, "wall_thickness_m": wall, "finned": finned}
    return data, design


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
        if not r.burn_time_s[0] <= design["burn_time_s"] <= r.burn_time_s[1]:
            continue
        try:
            parse_vehicle(data, source=f"family_{seed}.yaml")
        except ConfigError:
            continue
        if check is not None and not check(data):
            continue
        return GeneratedVehicle(int(seed), attempt, data, design)
    raise ConfigError("seed", seed, f"a seed with a vehicle in {MAX_ATTEMPTS} attempts (widen the ranges)")
