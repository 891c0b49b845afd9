"""A vehicle's design parameters at lift-off, as a flight computer could be loaded with them: what the
``informed`` track of the launcher family's suite lets a policy see (the env option ``vehicle_info``).

They are the vehicle file's nominal numbers, computed by lvgym's own mass model and beam at lift-off
(time 0, every stage attached, the first stage burning at sea level), not the dispersed truth of an
episode: a flight computer knows its vehicle's design, not the draw of the day. A vehicle file's ``tables``
(:mod:`.timetables`) give the lift-off mass, CG and inertia and the first mode's frequency in their place,
as they do in flight.

======================  ========  =============================================================================
entry                   unit      meaning
======================  ========  =============================================================================
``mass_t``              t         lift-off mass
``pitch_inertia``       kg m^2    lift-off pitch inertia about the CG, as log10
``slenderness``         -         length over the largest outer diameter, over 10
``thrust_to_weight``    -         lift-off thrust at sea level (the largest in the first second) over the
                                  lift-off weight
``control_power``       1/s^2     pitch control power T_v (x_cg - x_gimbal) / J_yy over 10 (T_v: the
                                  vectored thrust; the moment of 1 rad of gimbal per unit inertia)
``bending_hz``          Hz        the first free-free bending frequency at lift-off, over 10
``slosh_mass_share``    -         the slosh pendulums' mass over the lift-off mass
``slosh_hz``            Hz        the largest slosh pendulum's frequency at the lift-off thrust acceleration
                                  (sqrt(a / l) / 2 pi, a = thrust / mass; 0 without slosh)
======================  ========  =============================================================================

The scaling keeps every entry near 0.1-10 for the family's vehicles (a network's input).
"""

from __future__ import annotations

import math

import numpy as np

from .config import load_vehicle
from .definition import G0, Vehicle
from .massmodel import MassModel
from .propulsion import P_SEA_LEVEL
from .structure import vehicle_modes
from .timetables import stack_at

__all__ = ["DESIGN_ENTRIES", "design_parameters", "design_vector"]

#: the window [s] after ignition in which the lift-off thrust is the largest thrust
THRUST_WINDOW_S = 1.0
#: the entries of :func:`design_vector`, in order, with their units (module docstring)
DESIGN_ENTRIES = (("mass_t", "t"), ("pitch_inertia", "log10 kg m^2"), ("slenderness", "1/10"),
                  ("thrust_to_weight", "-"), ("control_power", "10/s^2"), ("bending_hz", "10 Hz"),
                  ("slosh_mass_share", "-"), ("slosh_hz", "Hz"))


def design_parameters(vehicle: Vehicle) -> dict[str, float]:
    """The design parameters of ``vehicle`` at lift-off, in SI (module docstring): ``mass_kg``,
    ``pitch_inertia_kgm2``, ``slenderness``, ``thrust_to_weight``, ``control_power_per_s2``,
    ``bending_hz`` (0 without bending modes), ``slosh_mass_share``, ``slosh_hz``."""
    mm = MassModel(vehicle)
    state = mm.initial_state()
    props = mm.properties(state)
    mass, cg, j_yy = float(props.mass), float(props.cg[0]), float(props.inertia[1, 1])
    tables = vehicle.tables
    if tables is not None and tables.mass_properties is not None:
        m, c, J = stack_at(tables.mass_properties, [0.0])
        mass, cg, j_yy = float(m[0]), float(c[0, 0]), float(J[0, 1, 1])
    thrust, vectored = _lift_off_thrust(mm, state)
    arm = cg - float(props.gimbal[0])                          # CG ahead of the gimbal: > 0 [m]
    diameter = max(s.outer_diameter for s in vehicle.stages)
    bending = 0.0
    if vehicle.structure.n_modes > 0 and tables is not None and tables.modes:
        bending = float(tables.modes[0].column("hz", [0.0])[0])
    elif vehicle.structure.n_modes > 0:
        modes = vehicle_modes(vehicle, state, props, n_modes=1)
        bending = float(modes.omega[0]) / (2.0 * math.pi) if modes.omega.size else 0.0
    slosh = np.asarray(props.slosh_mass, float)
    slosh_hz = 0.0
    if slosh.size and slosh.max() > 0.0:
        k = int(np.argmax(slosh))
        slosh_hz = math.sqrt(thrust / mass / float(props.pendulum_length[k])) / (2.0 * math.pi)
    return {"mass_kg": mass, "pitch_inertia_kgm2": j_yy, "slenderness": vehicle.length / diameter,
            "thrust_to_weight": thrust / (mass * G0), "control_power_per_s2": vectored * arm / j_yy,
            "bending_hz": bending, "slosh_mass_share": float(slosh.sum()) / mass, "slosh_hz": slosh_hz}


def _lift_off_thrust(mm: MassModel, state) -> tuple[float, float]:
    """The largest sea-level thrust [N] in the first :data:`THRUST_WINDOW_S` of the flight (a motor whose
    thrust table starts at zero reaches its lift-off thrust in a fraction of a second), and its vectored
    part [N] at that time."""
    best, best_state = float(mm.thrust(state, 1.0, P_SEA_LEVEL)), state
    for t in np.linspace(0.05, THRUST_WINDOW_S, 20):
        s, _ = mm.advance(state, float(t))
        f = float(mm.thrust(s, 1.0, P_SEA_LEVEL))
        if f > best:
            best, best_state = f, s
    return best, best * float(mm.vectored_share(best_state))


def design_vector(vehicle: str | Vehicle) -> np.ndarray:
    """:func:`design_parameters` of a vehicle (a shipped name, a YAML path or a :class:`Vehicle`) scaled
    as :data:`DESIGN_ENTRIES` (the ``vehicle_info`` observation's block), float32, read-only."""
    return _scaled(design_parameters(vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)))


def _scaled(p: dict[str, float]) -> np.ndarray:
    """The parameters of :func:`design_parameters` scaled as :data:`DESIGN_ENTRIES`, float32, read-only."""
    v = np.array([p["mass_kg"] / 1e3, math.log10(p["pitch_inertia_kgm2"]), p["slenderness"] / 10.0,
                  p["thrust_to_weight"], p["control_power_per_s2"] / 10.0, p["bending_hz"] / 10.0,
                  p["slosh_mass_share"], p["slosh_hz"]], np.float32)
    v.setflags(write=False)
    return v
