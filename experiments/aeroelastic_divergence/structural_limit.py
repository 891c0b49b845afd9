"""A physical q-alpha limit of the slender vehicle: the dynamic pressure times angle of attack [Pa deg] at
which the tube's wall reaches its allowable stress (docs/flex-design.md, "The slender vehicle").

The loads, per unit ``q S alpha`` (``q`` [Pa], ``S`` the reference area [m^2], ``alpha`` [rad]), in the
pitch plane of the free vehicle, quasi-static (the rigid-body accelerations balance the loads: inertia
relief), on the independent model of :mod:`.divergence` (not lvgym's strip code):

- **aerodynamic normal force**: :func:`.divergence.vehicle_lift`, slender-body theory over the ogive
  nose, ``dCN_alpha / dxi = (2 / S) dA / dxi``, and the fins' CN-alpha at their centre of pressure;
- **mass**: the lumped translational mass of each node of :func:`.divergence.vehicle_beam` (the wall, the
  liquid column, the equipment and the engine);
- two ends of what a TVC loop can do: ``"free"``, the gimbal at zero (the vehicle accelerates laterally
  at ``F / m`` and in pitch at ``M_cg / J``), and ``"trimmed"``, the gimbal's side force holding the
  pitching moment (``F_g (xi_g - xi_cg) = M_cg``, no pitch acceleration); the limit takes the worse.

The bending moment at station ``xi`` [m] behind the nose is the moment of the net lateral loads (aero,
gimbal, inertia) ahead of it. The wall's stress is the bending stress ``M (D / 2) / I`` plus the axial
compression ``N / A`` of the thrust accelerating the mass ahead and the drag (:meth:`.divergence.Beam.
compression`); the allowable is the yield stress over the factor of safety. So the limit is

    q alpha_max [Pa rad] = (sigma_y / FS - N / A) / (max_xi |m(xi)| S (D / 2) / I)

with ``m(xi)`` [m] the bending moment per unit ``q S alpha``, in degrees times 180 / pi. Local buckling of
the thin wall (D / t = 63) is checked against the classical cylinder stress ``0.6 E t / R`` with NASA
SP-8007's knockdown: with the 4.5 mm wall it is well above yield, so yield governs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.commandline import arg
from lvgym.vehicle.sections import MATERIALS, tube_area, tube_second_moment

from experiments.aeroelastic_divergence.divergence import Beam, Lift, vehicle_beam, vehicle_lift

__all__ = ["YIELD_STRESS_PA", "FACTOR_OF_SAFETY_YIELD", "lumped_masses", "bending_moment_per_qsa",
           "qalpha_limit_pa_deg", "slender_v1_qalpha_limit", "buckling_stress_pa"]

#: tensile yield stress [Pa] of the slender tube's material (``lvgym.vehicle.slender``: ``al_ansys``, the
#: ANSYS Workbench General Materials "Aluminum Alloy"; 280 MPa is that library's value, close to aluminium
#: 6061-T6's 276 MPa); 7075-T6 as a stronger alloy for comparison (505 MPa, ASM)
YIELD_STRESS_PA = {"al_ansys": 280e6, "al6061_t6": 276e6, "al7075_t6": 505e6}
#: the factor of safety on yield of a metallic flight structure verified by analysis (launch-vehicle
#: practice, NASA-STD-5001's factor for untested metallic structures; a convention here)
FACTOR_OF_SAFETY_YIELD = 1.25


def lumped_masses(beam: Beam) -> np.ndarray:
    """The translational mass [kg] of each node of ``beam`` (the rows of its mass matrix summed over the
    translational DOFs: they add up to the vehicle's mass)."""
    w = np.zeros(beam.M.shape[0])
    w[0::2] = 1.0
    return (beam.M @ w)[0::2]


def bending_moment_per_qsa(beam: Beam, lift: Lift, case: str = "free") -> tuple[np.ndarray, np.ndarray]:
    """The bending moment [N m per N of ``q S alpha``, i.e. m] at the beam's nodes under a unit ``q S
    alpha`` (module docstring), for ``case`` ``"free"`` (gimbal at zero) or ``"trimmed"`` (the gimbal's
    side force holds the pitching moment). Returns (stations ``xi`` [m], moments [m])."""
    if case not in ("free", "trimmed"):
        raise ValueError(f"case = {case!r}: 'free' or 'trimmed'")
    m = lumped_masses(beam)
    cg = float(np.sum(m * beam.xi) / m.sum())         # of the lumped masses (so the loads balance exactly)
    inertia = float(np.sum(m * (beam.xi - cg) ** 2))
    xs, fs = list(lift.xi), list(lift.c)              # lateral forces per unit q S alpha [-], stations [m]
    force = float(np.sum(fs))
    moment = float(np.sum(np.asarray(fs) * (cg - np.asarray(xs))))   # about the CG, nose-up positive
    if case == "trimmed":
        f_g = -moment / (cg - beam.gimbal)
        xs.append(beam.gimbal)
        fs.append(f_g)
        force += f_g
        moment = 0.0
    accel = force / m.sum()                           # per unit q S alpha [1/kg]
    ang = moment / inertia                            # [1/(kg m)]
    inertial = -m * (accel + ang * (cg - beam.xi))    # the inertia forces at the nodes
    xs_all = np.concatenate([np.asarray(xs), beam.xi])
    fs_all = np.concatenate([np.asarray(fs), inertial])
    out = np.array([float(np.sum(fs_all[xs_all < x] * (x - xs_all[xs_all < x]))) for x in beam.xi])
    return beam.xi.copy(), out


def buckling_stress_pa(youngs_pa: float, radius_m: float, wall_m: float) -> float:
    """Axial buckling stress [Pa] of a thin cylinder, ``gamma 0.605 E t / R`` with NASA SP-8007's
    knockdown ``gamma = 1 - 0.901 (1 - exp(-sqrt(R / t) / 16))``."""
    phi = math.sqrt(radius_m / wall_m) / 16.0
    gamma = 1.0 - 0.901 * (1.0 - math.exp(-phi))
    return gamma * 0.605 * youngs_pa * wall_m / radius_m


def qalpha_limit_pa_deg(moment_per_qsa_m: float, s_ref_m2: float, diameter_m: float, wall_m: float,
                        allowable_pa: float, axial_n: float = 0.0) -> float:
    """q-alpha [Pa deg] at which the wall's stress (bending plus the compression ``axial_n`` [N]) reaches
    ``allowable_pa`` [Pa]; ``moment_per_qsa_m`` [m]: the largest bending moment per unit ``q S alpha``."""
    D, t = float(diameter_m), float(wall_m)
    inertia, area = tube_second_moment(D, t), tube_area(D, t)
    per_q_alpha = abs(moment_per_qsa_m) * s_ref_m2 * (D / 2.0) / inertia      # stress [Pa] per Pa rad
    left = allowable_pa - axial_n / area
    if left <= 0.0:
        return 0.0
    return left / per_q_alpha * 180.0 / math.pi


def slender_v1_qalpha_limit(t: float = 8.0, thrust_n: float | None = None, drag_n: float | None = None,
                            material: str = "al_ansys", fs: float = FACTOR_OF_SAFETY_YIELD, length: float = 8.5,
                            diameter: float = 0.2833, wall: float = 0.0045, mach: float = 2.0) -> dict[str, Any]:
    """The structural q-alpha limit of ``SlenderAscent-v1``'s tube at flight time ``t`` [s] (default 8 s,
    its max q): the worse of the free and the trimmed load cases, with the axial compression of
    ``thrust_n`` and ``drag_n`` [N] at the most loaded station (None: no axial load). Returns the limit
    [Pa deg], the moments per unit ``q S alpha`` [m] and their stations, the allowable and buckling stresses."""
    beam = vehicle_beam(t, length=length, diameter=diameter, wall_thickness=wall)
    lift = vehicle_lift(length=length, diameter=diameter, mach=mach)
    allowable = YIELD_STRESS_PA[material] / fs
    out: dict[str, Any] = {"allowable_pa": allowable, "s_ref_m2": lift.s_ref, "mass_kg": beam.mass}
    worst = math.inf
    for case in ("free", "trimmed"):
        xi, m = bending_moment_per_qsa(beam, lift, case)
        k = int(np.argmax(np.abs(m)))
        axial = 0.0
        if thrust_n is not None:
            accel = (thrust_n - (drag_n or 0.0)) / beam.mass
            axial = float(beam.compression(xi[k], accel, drag_n or 0.0)[0])
        lim = qalpha_limit_pa_deg(m[k], lift.s_ref, diameter, wall, allowable, axial)
        out[case] = {"moment_per_qsa_m": float(m[k]), "station_m": float(xi[k]), "axial_n": axial, "limit_pa_deg": lim}
        worst = min(worst, lim)
    out["buckling_pa"] = buckling_stress_pa(MATERIALS[material if material in MATERIALS else "al_ansys"].youngs_modulus,
                                            diameter / 2.0, wall)
    out["limit_pa_deg"] = worst
    return out


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.aeroelastic_divergence.structural_limit --help``)."""

    times: list[float] = arg(default_factory=lambda: [4.0, 6.0, 8.0], positional=True, lo=0.0, hi=100.0, metavar="T")
    """flight times [s] of SlenderAscent-v1"""


def main(argv: list[str] | None = None) -> int:
    """``python -m experiments.aeroelastic_divergence.structural_limit [times...]``: the limit at flight times [s] of
    ``SlenderAscent-v1`` (default 4, 6, 8 s), with the thrust and axial drag of its calm flight there."""
    from lvgym.baselines.design.linearize import aero_slopes, operating_point
    from lvgym.commandline import parse

    times = parse(Args, argv, "python -m experiments.aeroelastic_divergence.structural_limit", main.__doc__).times
    print("| t [s] | mass [kg] | thrust / drag [kN] | bending moment per q S alpha, free / trimmed [m] | station [m] "
          "| compression [kN] | q-alpha limit [MPa deg] |\n|---:|---:|---|---|---:|---:|---:|")
    for t in times:
        op = operating_point("slender", t, "rigid", protocol="v1")
        thrust, drag = op.condition("thrust"), float(aero_slopes(op)[3])
        r = slender_v1_qalpha_limit(t, thrust_n=thrust, drag_n=drag)
        worst = min(("free", "trimmed"), key=lambda c: r[c]["limit_pa_deg"])
        print(f"| {t:g} | {r['mass_kg']:.0f} | {thrust / 1e3:.1f} / {drag / 1e3:.1f} | {r['free']['moment_per_qsa_m']:.2f} / "
              f"{r['trimmed']['moment_per_qsa_m']:.2f} | {r[worst]['station_m']:.2f} | {r[worst]['axial_n'] / 1e3:.1f} "
              f"| {r['limit_pa_deg'] / 1e6:.2f} |")
    print(f"allowable {r['allowable_pa'] / 1e6:.0f} MPa (yield / {FACTOR_OF_SAFETY_YIELD}), local buckling "
          f"{r['buckling_pa'] / 1e9:.2f} GPa")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
