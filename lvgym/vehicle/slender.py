"""The parametric slender vehicle of the thesis's sensitivity study (thesis 6.1-6.2, case D).

The thesis varies five factors of a Stratos-III-like single-stage sounding rocket (Table 6.3): length
8.5 / 7.5 m, diameter 0.3 / 0.26 m, slosh damping 0.8 / 0.5, mass flow 30 / 20 kg/s and tank fill
1 / 0.8, on a hollow aluminium beam with a 2 mm wall (Table 6.4). It does not describe the rest of the
vehicle, so this module builds one from those five numbers, with every other number scaled from
Stratos III (``lvgym/vehicles/stratos3.yaml``):

- one liquid propellant tank with one slosh pendulum, from ``0.2 L`` to ``0.8 L`` below the nose (the
  Stratos III oxidiser tank is "about 60 % of the rocket", public data), inner radius ``D / 2 - t``
  (the 2 mm wall is the tank wall), density 800 kg/m^3 (N2O, as Stratos III). One tank and no grain:
  the thesis's factors act on the sloshing liquid (fill, its drain rate, its damping), so the tank is
  fed by one engine at ``mass_flow`` with role ``propellant``;
- engine: the thrust equation at Isp 220 s (the effective Isp of the Stratos III thrust table), 10 kg
  with Table 5.1's inertia, CG at ``0.975 L``, gimbal at ``0.97 L``, 5 deg;
- structure: the aluminium wall over the whole length (``al_ansys``, the thesis's ANSYS aluminium:
  44.1 kg at the defaults) plus 50 kg of equipment, 25 kg at ``0.15 L`` (avionics, recovery) and 25 kg at
  ``0.92 L`` (thrust structure, fins), so the default structure weighs 94.1 kg like Table 5.1's;
- bending: one section of the same wall over the whole length (Table 6.4's beam);
- aerodynamics: a tangent ogive of ``L / 8.2`` and Stratos III's four fins, unchanged, at the base (the
  thesis holds the aerodynamic coefficients constant over the study), as a mapping for the Barrowman
  table generator (``model: barrowman``, :mod:`lvgym.environment.barrowman`).

>>> from lvgym.vehicle.slender import slender_vehicle
>>> v = slender_vehicle()
>>> round(v.length / v.stages[0].outer_diameter, 2), v.tanks[0].fill_ratio
(28.33, 1.0)
>>> slender_vehicle(fill=1.2)
Traceback (most recent call last):
...
lvgym.errors.ConfigError: slender_vehicle: fill = 1.2: must be in (0, 1]

``python -m lvgym.vehicle.slender`` prints the YAML of the defaults (``lvgym/vehicles/slender.yaml``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
import yaml

from lvgym.errors import ConfigError

from .config import parse_vehicle
from .definition import Vehicle
from .sections import MATERIALS, tube_area

__all__ = ["DEFAULTS", "TABLE_6_3", "WALL_THICKNESS", "SlenderGeometry", "slender_mapping", "slender_vehicle",
           "slender_yaml"]

#: defaults of the five study factors (Table 6.3's high levels, damping at its low level)
DEFAULTS: dict[str, float] = {"length": 8.5, "diameter": 0.3, "fill": 1.0, "mass_flow": 30.0, "slosh_damping": 0.5}
#: Table 6.3: (high, low) level of each factor; length and diameter [m], mass flow [kg/s]
TABLE_6_3: dict[str, tuple[float, float]] = {"length": (8.5, 7.5), "diameter": (0.3, 0.26),
                                             "slosh_damping": (0.8, 0.5), "mass_flow": (30.0, 20.0),
                                             "fill": (1.0, 0.8)}

SOURCE = "slender_vehicle"
#: fractions of the length from the nose tip [-]
NOSE, TANK_TOP, TANK_BOTTOM, GIMBAL, ENGINE_CG = 1.0 / 8.2, 0.2, 0.8, 0.97, 0.975
FORWARD_EQUIPMENT, AFT_EQUIPMENT = (0.15, 25.0), (0.92, 25.0)     # (fraction of L, mass [kg])
ENGINE_MASS, ENGINE_INERTIA = 10.0, [0.112, 0.088, 0.088]         # Table 5.1 [kg], [kg m^2]
#: Stratos III fins (lvgym/vehicles/stratos3.yaml) [m]; the trailing edge sits FIN_GAP above the base
FINS = {"count": 4, "root_chord": 0.50, "tip_chord": 0.20, "span": 0.25, "sweep": 0.30, "thickness": 0.006}
FIN_GAP = 0.05
#: the thesis's aluminium wall [m] (Table 6.4)
WALL_THICKNESS = 0.002


def _number(name: str, value: Any, lo: float, hi: float, lo_open: bool, allowed: str | None = None) -> float:
    """``value`` as a finite float in the interval, else a :class:`ConfigError` naming ``name``."""
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    x = float(value) if ok else math.nan
    if not (math.isfinite(x) and (x > lo if lo_open else x >= lo) and x <= hi):
        left = "(" if lo_open else "["
        raise ConfigError(name, value, allowed or f"must be in {left}{lo:g}, {hi:g}]", SOURCE)
    return x


def _geometry(length: Any, diameter: Any, wall_thickness: Any) -> tuple[float, float, float]:
    """Length, diameter and wall [m] as floats, each in its range (else a :class:`ConfigError` naming it)."""
    L = _number("length", length, 3.0, 30.0, False)
    t = _number("wall_thickness", wall_thickness, 0.0, 0.05, True)
    D = _number("diameter", diameter, 2.0 * t + 0.02, L / 5.0, True,
                f"must be in ({2.0 * t + 0.02:g}, {L / 5.0:g}] m: more than twice the wall plus 2 cm and at "
                f"most length / 5")
    return L, D, t


def _aero_mach(aero_mach: Any) -> float:
    return _number("aero_mach", aero_mach, 0.0, 25.0, False)


def _r(x: float) -> float:
    """Rounded to a micrometre / milligram so the YAML and the mapping agree exactly."""
    return round(float(x), 6)


def slender_mapping(length: float = 8.5, diameter: float = 0.3, fill: float = 1.0, mass_flow: float = 30.0,
                    slosh_damping: float = 0.5, *, wall_thickness: float = WALL_THICKNESS, material: str = "al_ansys",
                    density: float = 800.0, isp: float = 220.0, name: str = "slender",
                    aero_mach: float | None = None) -> dict[str, Any]:
    """The vehicle-file mapping of the slender vehicle (see the module docstring).

    Parameters
    ----------
    length : overall length L [m], in [3, 30].
    diameter : outer diameter D [m], in (2 wall + 0.02, L / 5].
    fill : tank fill ratio at lift-off [-], in (0, 1].
    mass_flow : propellant mass flow [kg/s], in (0, 1000].
    slosh_damping : damping ratio of the slosh pendulum [-], in [0, 2].
    wall_thickness : aluminium wall [m], in (0, 0.05].
    material : key of :data:`lvgym.vehicle.sections.MATERIALS` for the wall.
    density : propellant density [kg/m^3], in (0, 3000].
    isp : momentum specific impulse of the thrust equation [s], in (0, 1000].
    name : vehicle name.
    aero_mach : if given, the Barrowman tables are frozen at this Mach number [-], in [0, 25] (the
        thesis's constant coefficients; ``SlenderAscent-v0`` uses 2.0); None: the full Mach tables.
    """
    L, D, t = _geometry(length, diameter, wall_thickness)
    F = _number("fill", fill, 0.0, 1.0, True)
    mdot = _number("mass_flow", mass_flow, 0.0, 1000.0, True)
    zeta = _number("slosh_damping", slosh_damping, 0.0, 2.0, False)
    rho = _number("density", density, 0.0, 3000.0, True)
    isp_s = _number("isp", isp, 0.0, 1000.0, True)
    if material not in MATERIALS:
        raise ConfigError("material", material, f"one of {sorted(MATERIALS)}", SOURCE)
    frozen = {} if aero_mach is None else {"mach": [_aero_mach(aero_mach)]}
    if not isinstance(name, str) or not name:
        raise ConfigError("name", name, "must be a non-empty string", SOURCE)

    # structure: the wall as a thin shell over [0, -L] plus two equipment masses
    m_wall = MATERIALS[material].density * tube_area(D, t) * L
    r_mid = 0.5 * (D - t)
    parts = [(m_wall, -0.5 * L, np.diag([m_wall * r_mid**2, *[m_wall * (r_mid**2 / 2 + L**2 / 12)] * 2]))]
    parts += [(m, -f * L, np.zeros((3, 3))) for f, m in (FORWARD_EQUIPMENT, AFT_EQUIPMENT)]
    m_s = sum(p[0] for p in parts)
    x_s = sum(p[0] * p[1] for p in parts) / m_s
    J_s = sum(p[2] + p[0] * (p[1] - x_s) ** 2 * np.diag([0.0, 1.0, 1.0]) for p in parts)
    chord = FINS["root_chord"]
    return {
        "name": name,
        "description": (f"Parametric slender vehicle of thesis 6.1-6.2: L {L:g} m, D {D:g} m, fill {F:g}, "
                        f"mass flow {mdot:g} kg/s, slosh damping {zeta:g}"),
        "stages": [{
            "name": "stage1", "top": 0.0, "length": _r(L), "outer_diameter": _r(D),
            "structure": {"mass": _r(m_s), "cg": _r(x_s), "inertia": [_r(J_s[i, i]) for i in range(3)]},
            "sections": [{"top": 0.0, "bottom": _r(-L), "material": material, "wall_thickness": _r(t)}],
            "engines": [{"name": "engine", "mass": ENGINE_MASS, "cg": _r(-ENGINE_CG * L),
                         "inertia": list(ENGINE_INERTIA), "gimbal": _r(-GIMBAL * L), "gimbal_limit_deg": 5.0,
                         "mass_flow": _r(mdot), "isp": _r(isp_s)}],
            "tanks": [{"name": "propellant", "engine": "engine", "role": "propellant",
                       "inner_radius": _r(0.5 * D - t), "height": _r((TANK_BOTTOM - TANK_TOP) * L),
                       "top": _r(-TANK_TOP * L), "density": _r(rho), "fill_ratio": _r(F), "slip_factor": 0.95,
                       "slosh_damping": _r(zeta)}],
        }],
        "staging": [{"stage": "stage1"}],
        "structure": {"n_modes": 2, "damping": 0.01, "aeroelastic": True},
        "aerodynamics": {"model": "barrowman", "nose": {"shape": "ogive", "length": _r(NOSE * L)},
                         "body": {"diameter": _r(D), "length": _r(L - NOSE * L)},
                         "fins": {**FINS, "station": _r(-(L - FIN_GAP - chord))}, **frozen},
    }


def slender_vehicle(length: float = 8.5, diameter: float = 0.3, fill: float = 1.0, mass_flow: float = 30.0,
                    slosh_damping: float = 0.5, **options: Any) -> Vehicle:
    """The slender vehicle as a checked :class:`~lvgym.vehicle.definition.Vehicle`.

    ``length`` [m], ``diameter`` [m], ``fill`` [-], ``mass_flow`` [kg/s], ``slosh_damping`` [-] are
    the factors of Table 6.3; ``options`` are the keyword options of :func:`slender_mapping`
    (``wall_thickness``, ``material``, ``density``, ``isp``, ``name``, ``aero_mach``). A parameter out of
    range raises :class:`~lvgym.errors.ConfigError` naming it."""
    unknown = sorted(set(options) - {"wall_thickness", "material", "density", "isp", "name", "aero_mach"})
    if unknown:
        raise ConfigError(unknown[0], options[unknown[0]],
                          "unknown option; allowed: wall_thickness, material, density, isp, name, aero_mach", SOURCE)
    mapping = slender_mapping(length, diameter, fill, mass_flow, slosh_damping, **options)
    return parse_vehicle(mapping, source=SOURCE)


@dataclass(frozen=True)
class SlenderGeometry:
    """The geometry of one slender vehicle, as a value: what an env flies (``TaskSpec.vehicle``), the key
    of its cached vehicle and timeline, and of a controller's schedule (``lvgym.baselines.pid.FLEX_SCHEDULES``).
    Frozen and hashable; equal geometries are the same vehicle. The other factors of Table 6.3 keep
    :func:`slender_mapping`'s defaults. A value out of range raises :class:`~lvgym.errors.ConfigError`
    naming it.

    >>> SlenderGeometry(8.5, 0.2833, aero_mach=2.0, wall_thickness=0.0045).vehicle().length
    8.5
    """

    length: float
    """overall length L [m], in [3, 30]"""
    diameter: float
    """outer diameter D [m], in (2 wall + 0.02, L / 5]"""
    aero_mach: float | None = None
    """the Mach number [-] the Barrowman tables are frozen at, in [0, 25] (the thesis's constant
    coefficients); None: the full Mach-dependent tables"""
    wall_thickness: float = WALL_THICKNESS
    """the aluminium tube's wall [m], in (0, 0.05] (default the thesis's 2 mm)"""

    def __post_init__(self) -> None:
        L, D, t = _geometry(self.length, self.diameter, self.wall_thickness)
        mach = None if self.aero_mach is None else _aero_mach(self.aero_mach)
        for key, value in (("length", L), ("diameter", D), ("aero_mach", mach), ("wall_thickness", t)):
            object.__setattr__(self, key, value)

    def vehicle(self) -> Vehicle:
        """The checked vehicle of this geometry (:func:`slender_vehicle`)."""
        return slender_vehicle(length=self.length, diameter=self.diameter, aero_mach=self.aero_mach,
                               wall_thickness=self.wall_thickness)

    def with_diameter(self, diameter: float) -> SlenderGeometry:
        """The same vehicle with another outer diameter [m]."""
        return replace(self, diameter=diameter)

    @classmethod
    def from_key(cls, key: Any) -> SlenderGeometry:
        """The geometry of a positional key ``("slender", length, diameter[, aero_mach[, wall_thickness]])``
        (the form before this value; a missing ``aero_mach`` is None, a missing wall the thesis's 2 mm)."""
        if not (isinstance(key, (tuple, list)) and 3 <= len(key) <= 5 and key[0] == "slender"):
            raise ConfigError("vehicle", key, "a SlenderGeometry or ('slender', length, diameter[, aero_mach"
                              "[, wall_thickness]])", SOURCE)
        return cls(*key[1:])


HEADER = """\
# The parametric slender vehicle of the thesis's sensitivity study (thesis 6.1-6.2, Tables 6.3-6.4;
# reference case D, docs/studies.md) at the default parameters of
# lvgym.vehicle.slender.slender_vehicle: length 8.5 m, diameter 0.3 m, fill 1.0, mass flow 30 kg/s,
# slosh damping 0.5. GENERATED by `python -m lvgym.vehicle.slender`; tests/test_vehicles.py checks that
# this file equals the function's defaults. Build other corners of Table 6.3 with slender_vehicle(...).
#
# Assumptions (the thesis names only the five factors and the 2 mm aluminium beam), all scaled from
# Stratos III (stratos3.yaml) with L the length and D the diameter:
# - one liquid tank with one slosh pendulum from 0.2 L to 0.8 L (Stratos III's oxidiser tank is about
#   60 % of the rocket), inner radius D/2 - 2 mm, density 800 kg/m^3 (N2O), role 'propellant': one
#   engine drains it at the mass flow (no grain: the factors act on the sloshing liquid);
# - thrust equation at Isp 220 s (the effective Isp of the Stratos III table); engine 10 kg with
#   Table 5.1's inertia at 0.975 L, gimbal at 0.97 L;
# - structure: the 2 mm wall of aluminium (al_ansys, 2770 kg/m^3, the thesis's ANSYS material) over the
#   length, plus 25 kg at 0.15 L and 25 kg at 0.92 L: 94.1 kg here, like Table 5.1's 94 kg;
# - slosh damping is used as the pendulum's damping ratio; the thesis's "damping" was a scalar
#   coefficient on the slosh velocity (thesis 6.2), not a ratio;
# - one bending section: the 2 mm aluminium tube over the whole length (Table 6.4's beam);
# - aerodynamics: tangent ogive of L / 8.2 and Stratos III's four fins at the base (the thesis keeps
#   the Stratos III aerodynamic coefficients for the whole study), in the keys of the Barrowman table
#   generator (lvgym/environment/barrowman.py): make("aerodynamics", vehicle.aerodynamics) builds it.
# Propellant 280.7 kg: the tank runs dry at 9.4 s at 30 kg/s, before the thesis's 12 s runs end.
"""


def slender_yaml(**parameters: Any) -> str:
    """The YAML text (with its comment header) of :func:`slender_mapping` ``(**parameters)``."""
    body = yaml.safe_dump(slender_mapping(**parameters), sort_keys=False, default_flow_style=None, width=110)
    return HEADER + body


@dataclass
class Args:
    """Command-line arguments (``lvgym vehicle slender --help``): the thesis's five factors."""

    length: float = 8.5
    """overall length L [m], in [3, 30]"""
    diameter: float = 0.3
    """outer diameter D [m], in (2 wall + 0.02, L / 5]"""
    fill: float = 1.0
    """tank fill ratio at lift-off [-], in (0, 1]"""
    mass_flow: float = 30.0
    """propellant mass flow [kg/s], in (0, 1000]"""
    slosh_damping: float = 0.5
    """damping ratio of the slosh pendulum [-], in [0, 2]"""


def main(argv: list[str] | None = None) -> None:
    """``lvgym vehicle slender`` (``python -m lvgym.vehicle.slender``): print the vehicle file of the factors
    (the defaults: ``lvgym/vehicles/slender.yaml``)."""
    from lvgym.commandline import command_name, fail, parse

    prog = "python -m lvgym.vehicle.slender"
    args = parse(Args, argv, prog, "Print the YAML vehicle file of the parametric slender vehicle (thesis 6.1-6.2).")
    try:
        text = slender_yaml(**asdict(args))
    except ConfigError as exc:                        # named as the option
        fail(command_name(prog), ConfigError("--" + exc.key.replace("_", "-"), exc.value, exc.allowed))
    print(text, end="")


if __name__ == "__main__":
    main()
