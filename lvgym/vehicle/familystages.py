"""The stages of the launcher family (:mod:`.generator`): the preliminary sizing of one stage, liquid
(LOX/RP-1, thrust equation) or solid (a thrust table), and its part of the vehicle file.

A **liquid** stage holds a LOX tank over an RP-1 tank (mixture ratio :data:`MIXTURE`, their heights in the
ratio of their volumes) and one engine whose mass flow gives the stage's thrust at sea level (Isp
:data:`ISP_S` with a :data:`EXIT_PRESSURE_PA` nozzle exit, the exit area in proportion to the flow).

A **solid** stage holds its grain as one non-sloshing ``propellant`` tank of :data:`RHO_SOLID` (the schema's
``grain`` is a hybrid's fuel, burnt with an oxidiser; a solid's propellant is a column that drains as a
liquid would, so its CG moves down the case, where a real grain burns from the port outwards: a
simplification), ``fill_ratio`` its volumetric loading, ``slip_factor`` 0 (it turns with the case). The
motor is a ``thrust_table`` engine: the lift-off (or ignition) thrust ``T0``, a straight line to
``tail T0`` at the end of the web ``t_b`` and a tail-off to zero over ``SOLID_TAILOFF t_b``; ``t_b`` gives
the total impulse ``ISP_SOLID g0 m_prop`` and the mean flow empties the grain at the table's end. The case
carries the chamber pressure :data:`CHAMBER_PA` in hoop stress (:data:`HOOP_STRESS_PA` over the drawn safety
factor) as well as the axial load; its dry structure is :data:`SOLID_STRUCTURE_FACTOR` times the wall (the
case is most of it).

Every stage's wall (aluminium 2219-T87, one section over the stage) carries the axial load with the drawn
safety factor on :data:`WALL_STRESS_PA`, no thinner than :data:`MIN_WALL_M`; the engine or nozzle weighs
its thrust over :data:`ENGINE_THRUST_TO_WEIGHT`.
"""

from __future__ import annotations

import math
from typing import Any

from .definition import G0
from .propulsion import P_SEA_LEVEL

__all__ = ["stage_file", "stage_geometry", "stage_masses"]

#: the wall's allowed axial stress before the safety factor [Pa] (2219-T87 yields at about 390 MPa; a thin
#: tube buckles first, so a preliminary sizing takes much less)
WALL_STRESS_PA = 120e6
MIN_WALL_M = 0.0015
STRUCTURE_FACTOR = 1.6
ENGINE_THRUST_TO_WEIGHT = 60.0
ISP_S, EXIT_PRESSURE_PA = 255.0, 70e3
EXIT_AREA_PER_FLOW = 0.07 / 15.6            # [m^2 per kg/s], a small pressure-fed-class engine
MIXTURE, RHO_LOX, RHO_RP1 = 2.35, 1141.0, 810.0
#: a composite solid propellant (AP/HTPB/Al) [kg/m^3] and its delivered specific impulse near sea level [s]
RHO_SOLID, ISP_SOLID = 1770.0, 245.0
#: a solid motor's chamber pressure [Pa] and the case's allowed hoop stress before the safety factor [Pa]
CHAMBER_PA, HOOP_STRESS_PA = 5e6, 300e6
SOLID_STRUCTURE_FACTOR = 1.25
#: the tail-off of a solid's thrust table, as a share of the web burn time
SOLID_TAILOFF = 0.03
THRUST_PER_FLOW = ISP_S * G0 - (P_SEA_LEVEL - EXIT_PRESSURE_PA) * EXIT_AREA_PER_FLOW     # [N per kg/s]


def stage_geometry(D: float, top: float, length: float, nose: float, h: float, fill: float,
                   solid: bool) -> dict[str, Any]:
    """The tanks of a stage of diameter ``D`` [m] from station ``top`` [m] over ``length`` [m] (``nose``
    [m]: the nose it holds, 0 below the top stage) with ``h`` [m] of tank height filled to ``fill``:
    the tanks' heights and tops [m], the inner radius [m], the engine bay below them [m] and the propellant
    [kg]."""
    r_in = 0.48 * D
    tanks_top = top - nose - 0.1 * D
    if solid:
        heights, tops = [h], [tanks_top]
        m_prop = fill * math.pi * r_in ** 2 * h * RHO_SOLID
    else:
        h_lox = h * (MIXTURE / RHO_LOX) / (MIXTURE / RHO_LOX + 1.0 / RHO_RP1)
        h_rp1 = h - h_lox
        heights, tops = [h_lox, h_rp1], [tanks_top, tanks_top - h_lox - 0.05 * D]
        m_prop = fill * math.pi * r_in ** 2 * (h_lox * RHO_LOX + h_rp1 * RHO_RP1)
    bay = length + (tops[-1] - top) - heights[-1]
    return {"top": top, "length": length, "r_in": r_in, "heights": heights, "tops": tops, "bay": bay,
            "fill": fill, "propellant": m_prop, "solid": solid}


def stage_masses(D: float, geo: dict[str, Any], load: float, thrust: float, safety: float) -> dict[str, float]:
    """The wall [m], dry structure [kg] and engine [kg] of a stage (:func:`stage_geometry`) whose wall
    carries the axial ``load`` [N] and whose engine gives ``thrust`` [N]."""
    wall = max(MIN_WALL_M, safety * load / (math.pi * D * WALL_STRESS_PA))
    factor = STRUCTURE_FACTOR
    if geo["solid"]:
        wall = max(wall, safety * CHAMBER_PA * geo["r_in"] / HOOP_STRESS_PA)
        factor = SOLID_STRUCTURE_FACTOR
    return {"wall": wall, "structure": factor * 2840.0 * math.pi * D * wall * geo["length"],
            "engine": thrust / (G0 * ENGINE_THRUST_TO_WEIGHT)}


def stage_file(name: str, D: float, geo: dict[str, Any], parts: dict[str, float], thrust: float, tail: float,
               zeta: float, upper: bool) -> tuple[dict[str, Any], float]:
    """The stage's mapping in the vehicle file and its burn time [s]: ``thrust`` [N] at sea level at
    ignition, ``tail`` the end-of-web thrust over it (solid), ``zeta`` the slosh damping (liquid), ``upper``
    whether it is the second stage (its parts' names)."""
    top, L, bay, m_engine = geo["top"], geo["length"], geo["bay"], parts["engine"]
    m_struct, wall, m_prop = parts["structure"], parts["wall"], geo["propellant"]
    bottom = top - L
    j_engine = m_engine / 60.0 * (D / 0.6) ** 2              # scaled from a 60 kg engine of a 0.6 m vehicle
    ename = "upper" if upper else "main"
    engine: dict[str, Any] = {"name": ename, "mass": round(m_engine, 3), "cg": round(bottom + 0.2 * bay, 4),
                              "inertia": [round(1.5 * j_engine, 4), round(3.0 * j_engine, 4), round(3.0 * j_engine, 4)],
                              "gimbal": round(bottom + 0.3 * bay, 4), "gimbal_limit_deg": 6.0}
    tank = {"engine": ename, "inner_radius": round(geo["r_in"], 4), "fill_ratio": round(geo["fill"], 4)}
    prefix = "upper_" if upper else ""
    if geo["solid"]:
        t_web = ISP_SOLID * G0 * m_prop / (thrust * (0.5 * (1.0 + tail) + 0.5 * SOLID_TAILOFF * tail))
        t_end = (1.0 + SOLID_TAILOFF) * t_web
        engine |= {"mass_flow": round(m_prop / t_end, 4),
                   "thrust_table": [[0.0, round(thrust, 1)], [round(t_web, 3), round(tail * thrust, 1)],
                                    [round(t_end, 3), 0.0]]}
        tanks = [{"name": prefix + "grain", "role": "propellant", "height": round(geo["heights"][0], 4),
                  "top": round(geo["tops"][0], 4), "density": RHO_SOLID, **tank, "slip_factor": 0.0, "slosh": False}]
        burn = t_end
    else:
        flow = thrust / THRUST_PER_FLOW
        engine |= {"mass_flow": round(flow, 4), "isp": ISP_S, "nozzle_exit_area": round(EXIT_AREA_PER_FLOW * flow, 6),
                   "nozzle_exit_pressure": EXIT_PRESSURE_PA, "mixture_ratio": MIXTURE}
        tank |= {"slip_factor": 0.95, "slosh_damping": round(zeta, 5)}
        tanks = [{"name": prefix + n, "role": role, "height": round(h, 4), "top": round(t, 4), "density": rho, **tank}
                 for n, role, h, t, rho in zip(("lox", "rp1"), ("oxidiser", "fuel"), geo["heights"], geo["tops"],
                                               (RHO_LOX, RHO_RP1))]
        burn = m_prop / flow
    stage = {"name": name, "top": round(top, 4), "length": round(L, 4), "outer_diameter": round(D, 4),
             "structure": {"mass": round(m_struct, 3), "cg": round(top - 0.52 * L, 4),
                           "inertia": [round(m_struct * (D / 2) ** 2, 3),
                                       *[round(m_struct * (L ** 2 / 12 + D ** 2 / 8), 3)] * 2]},
             "sections": [{"top": round(top, 4), "bottom": round(bottom, 4), "material": "al2219_t87",
                           "wall_thickness": round(wall, 6)}],
             "engines": [engine], "tanks": tanks}
    return stage, burn
