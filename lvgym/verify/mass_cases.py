"""Reference case M: the thesis's mass-model verification (Tables 4.1-4.4), every row within 0.1 %.

The expected numbers are those of the thesis's Tables 4.1-4.4 (recomputed from the thesis's own
formulas with kappa on the radius); where the thesis's printed value differs, the note gives it.
"""

from __future__ import annotations

from lvgym.vehicle.config import load_vehicle
from lvgym.vehicle.massmodel import MassModel

from .report import Check

T_END = 241.27
TOL = 1e-3

# (quantity, unit, time, cg convention, expected, extractor, note)
_ROWS = [
    ("oxidiser mass", "kg", 0.0, "static", 175929.19, lambda p, s, mm: p.tanks[0].liquid_mass, ""),
    ("oxidiser mass", "kg", T_END, "static", 15082.5, lambda p, s, mm: p.tanks[0].liquid_mass, ""),
    ("oxidiser liquid CG", "m", 0.0, "static", -5.0, lambda p, s, mm: p.tanks[0].liquid_cg, ""),
    ("oxidiser liquid CG", "m", T_END, "static", -9.571, lambda p, s, mm: p.tanks[0].liquid_cg, ""),
    ("fuel liquid CG", "m", 0.0, "static", -14.0, lambda p, s, mm: p.tanks[1].liquid_cg, ""),
    ("fuel liquid CG (empty)", "m", T_END, "static", -18.0, lambda p, s, mm: p.tanks[1].liquid_cg, ""),
    ("oxidiser slosh mass", "kg", 0.0, "static", 15992.08, lambda p, s, mm: p.slosh_mass[0], ""),
    ("oxidiser slosh mass", "kg", T_END, "static", 10522.0, lambda p, s, mm: p.slosh_mass[0], ""),
    ("fuel slosh mass", "kg", 0.0, "static", 9138.32, lambda p, s, mm: p.slosh_mass[1], ""),
    ("oxidiser slosh mass station", "m", 0.0, "static", -2.172, lambda p, s, mm: p.slosh_rest[0, 0], ""),
    ("fuel slosh mass station", "m", 0.0, "static", -12.170, lambda p, s, mm: p.slosh_rest[1, 0], ""),
    ("oxidiser slosh mass station", "m", T_END, "static", -9.958, lambda p, s, mm: p.slosh_rest[0, 0], ""),
    ("oxidiser pendulum length", "m", 0.0, "static", 1.086, lambda p, s, mm: p.pendulum_length[0], ""),
    ("oxidiser pendulum length (Roberts, uncapped)", "m", T_END, "static", 1.651,
     lambda p, s, mm: p.tanks[0].pendulum_length_roberts,
     "the dynamics uses it capped at the liquid height (0.857 m), physics note 4"),
    ("Ixx fixed oxidiser", "kg m2", 0.0, "static", 15993.71, lambda p, s, mm: p.tanks[0].fixed_inertia[0, 0], ""),
    ("Ixx fixed oxidiser", "kg m2", T_END, "static", 456.015, lambda p, s, mm: p.tanks[0].fixed_inertia[0, 0], ""),
    ("Ixx fixed fuel", "kg m2", 0.0, "static", 7128.64, lambda p, s, mm: p.tanks[1].fixed_inertia[0, 0], ""),
    ("Iyy fixed oxidiser", "kg m2", 0.0, "static", 1492746.0, lambda p, s, mm: p.tanks[0].fixed_inertia[1, 1],
     "thesis prints 1,492,149"),
    ("Iyy fixed oxidiser", "kg m2", T_END, "static", 4839.5, lambda p, s, mm: p.tanks[0].fixed_inertia[1, 1],
     "thesis prints 4,837.5"),
    ("Iyy fixed fuel", "kg m2", 0.0, "static", 451481.0, lambda p, s, mm: p.tanks[1].fixed_inertia[1, 1],
     "thesis prints 451,300"),
    ("vehicle CG, thesis convention", "m", 0.0, "thesis", -7.592, lambda p, s, mm: p.cg[0], ""),
    ("vehicle CG, thesis convention", "m", T_END, "thesis", -9.847, lambda p, s, mm: p.cg[0], ""),
    ("vehicle CG, static CG kept", "m", 0.0, "static", -7.832, lambda p, s, mm: p.cg[0], ""),
    ("vehicle CG, static CG kept", "m", T_END, "static", -9.595, lambda p, s, mm: p.cg[0], ""),
]


def case_m() -> list[Check]:
    """Case M rows, plus the empty times (the flow stops when the fuel is empty)."""
    vehicle = load_vehicle("thesis-verification")
    models = {conv: MassModel(vehicle, conv) for conv in ("static", "thesis")}
    states = {}
    for conv, mm in models.items():
        s0 = mm.initial_state()
        states[conv, 0.0] = s0
        states[conv, T_END] = mm.advance(s0, T_END)[0]
    out = []
    for quantity, unit, t, conv, expected, get, note in _ROWS:
        mm, s = models[conv], states[conv, t]
        got = float(get(mm.properties(s), s, mm))
        out.append(Check("M", f"{quantity}, t = {t:g} s", expected, got, unit, TOL, True, note))
    mm = models["static"]
    s0 = mm.initial_state()
    _, events = mm.advance(s0, 300.0)
    burnout = next(t for t, e in events if "burnout" in e)
    out.append(Check("M", "burnout (fuel empty)", 241.27, burnout, "s", TOL, True))
    ox_rate = 1000.0 * 2.0 / 3.0
    engine = mm.engines[0][1]
    out.append(Check("M", "oxidiser empty time at full flow", 263.89,
                     engine.time_to_consume(0.0, vehicle.tanks[0].capacity * 1.5), "s", TOL, True,
                     "the engine's flow model: the oxidiser is 2/3 of it"))
    end = mm.advance(s0, 300.0)[0]
    out.append(Check("M", "oxidiser left when the flow stops", 175929.19 - 241.274 * ox_rate,
                     float(end.tank_mass[0]), "kg", TOL, True, "no flow after burnout"))
    return out
