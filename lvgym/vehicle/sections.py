"""The structure of a launch-vehicle stack as beam input: materials, tube sections, the stack mesh.

The beam model (:mod:`lvgym.vehicle.beam`) takes node stations, a bending stiffness ``EI`` [N m^2]
and a mass per length [kg/m] per element, and point masses. This module describes the stack and
produces them: :func:`tube` gives ``EI`` and the structural mass per length of a circular tube from
a material, an outer diameter and a wall thickness; :func:`mesh_stack` meshes a list of
:class:`Section` (station ranges with ``EI`` and structural mass), :class:`DistributedMass` (a liquid
column) and :class:`PointMass` (engine, payload, fixed liquid mass) into a :class:`BeamMesh`.

>>> from lvgym.vehicle.sections import MATERIALS, tube
>>> EI, m_per_l = tube(MATERIALS["al7075_t6"], d_outer=0.3, t_wall=0.002)
>>> round(EI / 1e6, 4), round(m_per_l, 4)     # N m^2 / 1e6, kg/m
(1.4903, 5.2614)

Materials (isotropic, room temperature; a laminate is given by its effective axial modulus):

===================  ========  =========  ==============================================================
key                  E [GPa]   rho        source
                               [kg/m^3]
===================  ========  =========  ==============================================================
``al7075_t6``        71.7      2810       ASM Aerospace Specification Metals, Aluminum 7075-T6 data sheet
``al2219_t87``       73.1      2840       ASM Aerospace Specification Metals, Aluminum 2219-T87 data sheet
``al_ansys``         71.0      2770       ANSYS Workbench Engineering Data, General Materials,
                                          "Aluminum Alloy" (the thesis's ANSYS default aluminium)
``steel_4130``       205.0     7850       ASM Aerospace Specification Metals, AISI 4130 steel data sheet
``ti6al4v``          113.8     4430       ASM Aerospace Specification Metals, Ti-6Al-4V (Grade 5)
``cfrp_qi``          69.7      1600       quasi-isotropic laminate of T300/5208 carbon/epoxy
                                          (V_f = 0.7): lamina E1 181 GPa, E2 10.3 GPa, G12 7.17 GPa,
                                          nu12 0.28, 1600 kg/m^3 (Tsai & Hahn, Introduction to
                                          Composite Materials, 1980, Table 1.2), modulus from
                                          :func:`quasi_isotropic_modulus`
===================  ========  =========  ==============================================================

A real CFRP tube with mostly axial plies is stiffer and one with lower fibre volume softer; pass
your own :class:`Material` then.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lvgym.errors import ConfigError

from .beamkernels import subdivide_k

__all__ = ["Material", "MATERIALS", "quasi_isotropic_modulus", "tube_area", "tube_second_moment",
           "tube_second_moment_thin", "tube", "PointMass", "Section", "DistributedMass", "BeamMesh",
           "mesh_stack"]


@dataclass(frozen=True)
class Material:
    """An isotropic structural material.

    Attributes
    ----------
    name : str
        What it is, in words.
    youngs_modulus : float
        Young's modulus E [Pa] (for a laminate: the effective axial modulus).
    density : float
        Density rho [kg/m^3].
    source : str
        Where the numbers come from.
    """

    name: str
    youngs_modulus: float
    density: float
    source: str


def quasi_isotropic_modulus(E1: float, E2: float, G12: float, nu12: float) -> float:
    """In-plane modulus of a quasi-isotropic laminate from its lamina properties [Pa].

    Classical laminate theory with the Tsai-Pagano invariants of the reduced stiffness ``Q``:
    ``U1 = (3 Q11 + 3 Q22 + 2 Q12 + 4 Q66) / 8``, ``U4 = (Q11 + Q22 + 6 Q12 - 4 Q66) / 8`` and
    ``E_qi = (U1^2 - U4^2) / U1`` (Tsai & Hahn 1980, ch. 7; Jones, Mechanics of Composite Materials).

    Parameters
    ----------
    E1, E2 : float
        Lamina moduli along and across the fibres [Pa].
    G12 : float
        In-plane shear modulus [Pa].
    nu12 : float
        Major Poisson ratio [-].
    """
    for key, value in (("E1", E1), ("E2", E2), ("G12", G12)):
        if not (math.isfinite(value) and value > 0.0):
            raise ConfigError(key, value, "must be a finite modulus > 0 Pa")
    nu21 = nu12 * E2 / E1
    if not (math.isfinite(nu12) and nu12 >= 0.0 and nu12 * nu21 < 1.0):
        raise ConfigError("nu12", nu12, "must be >= 0 with nu12 * nu21 < 1")
    d = 1.0 - nu12 * nu21
    Q11, Q22, Q12, Q66 = E1 / d, E2 / d, nu12 * E2 / d, G12
    U1 = (3.0 * Q11 + 3.0 * Q22 + 2.0 * Q12 + 4.0 * Q66) / 8.0
    U4 = (Q11 + Q22 + 6.0 * Q12 - 4.0 * Q66) / 8.0
    return (U1 * U1 - U4 * U4) / U1


_ASM = "ASM Aerospace Specification Metals data sheet (asm.matweb.com)"

#: materials by key; see the module docstring for the sources
MATERIALS: dict[str, Material] = {
    "al7075_t6": Material("aluminium 7075-T6", 71.7e9, 2810.0, _ASM),
    "al2219_t87": Material("aluminium 2219-T87", 73.1e9, 2840.0, _ASM),
    "al_ansys": Material("aluminium alloy, ANSYS default", 71.0e9, 2770.0,
                         "ANSYS Workbench Engineering Data, General Materials, 'Aluminum Alloy'"),
    "steel_4130": Material("steel AISI 4130", 205.0e9, 7850.0, _ASM),
    "ti6al4v": Material("titanium Ti-6Al-4V (grade 5)", 113.8e9, 4430.0, _ASM),
    "cfrp_qi": Material("CFRP T300/5208, quasi-isotropic", quasi_isotropic_modulus(181e9, 10.3e9, 7.17e9, 0.28),
                        1600.0, "Tsai & Hahn 1980, Table 1.2 lamina data; quasi_isotropic_modulus"),
}


def _check_tube(d_outer: float, t_wall: float) -> None:
    if not (math.isfinite(d_outer) and d_outer > 0.0):
        raise ConfigError("d_outer", d_outer, "must be a finite outer diameter > 0 m")
    if not (math.isfinite(t_wall) and 0.0 < t_wall <= 0.5 * d_outer):
        raise ConfigError("t_wall", t_wall, f"must be in (0, d_outer / 2] = (0, {0.5 * d_outer}] m")


def tube_area(d_outer: float, t_wall: float) -> float:
    """Cross-section area of a circular tube, ``pi / 4 (D^2 - d^2)`` with ``d = D - 2 t`` [m^2].

    ``d_outer`` is the outer diameter D [m], ``t_wall`` the wall thickness t [m] (``t = D / 2``: solid).
    """
    _check_tube(d_outer, t_wall)
    d_inner = d_outer - 2.0 * t_wall
    return 0.25 * math.pi * (d_outer**2 - d_inner**2)


def tube_second_moment(d_outer: float, t_wall: float) -> float:
    """Exact area moment of a circular tube about a diameter, ``pi / 64 (D^4 - d^4)`` [m^4].

    Valid for any wall, thin or thick (``t_wall = d_outer / 2`` is the solid rod, ``pi D^4 / 64``).
    """
    _check_tube(d_outer, t_wall)
    d_inner = d_outer - 2.0 * t_wall
    return math.pi / 64.0 * (d_outer**4 - d_inner**4)


def tube_second_moment_thin(d_outer: float, t_wall: float) -> float:
    """Thin-wall approximation ``pi r^3 t`` with the mid-wall radius ``r = (D - t) / 2`` [m^4].

    Its relative error is ``-(t / D_mid)^2`` to leading order (``D_mid = D - t``): 4.5e-5 for a 2 mm
    wall on a 0.3 m tube. Prefer :func:`tube_second_moment`; this one is here for hand checks.
    """
    _check_tube(d_outer, t_wall)
    r = 0.5 * (d_outer - t_wall)
    return math.pi * r**3 * t_wall


def tube(material: Material, d_outer: float, t_wall: float) -> tuple[float, float]:
    """Bending stiffness and structural mass per length of a circular tube.

    Parameters
    ----------
    material : Material
        E [Pa] and rho [kg/m^3], e.g. ``MATERIALS["al7075_t6"]``.
    d_outer : float
        Outer diameter [m].
    t_wall : float
        Wall thickness [m], ``0 < t_wall <= d_outer / 2``.

    Returns
    -------
    EI : float
        Bending stiffness ``E I`` [N m^2] (exact thick-wall second moment).
    mass_per_length : float
        ``rho A`` [kg/m].
    """
    if not isinstance(material, Material):
        raise ConfigError("material", material, f"a Material, e.g. one of {sorted(MATERIALS)}")
    return (material.youngs_modulus * tube_second_moment(d_outer, t_wall),
            material.density * tube_area(d_outer, t_wall))


# ------------------------------------------------------------------------------ stack description
#: number of elements over the stack when no element length is given
DEFAULT_ELEMENTS = 80
#: mesh breakpoints closer than this fraction of the element length are merged (no sliver elements)
MERGE_FRACTION = 0.25


@dataclass(frozen=True)
class PointMass:
    """A lumped mass on the beam axis: engine, payload, fixed liquid mass, a slosh mass.

    ``station`` [m] (x_b from the nose tip), ``mass`` [kg], ``rotary_inertia`` [kg m^2] about the
    lateral axis through the point (pitch/yaw inertia of the body about its own CG).
    """

    station: float
    mass: float
    rotary_inertia: float = 0.0


@dataclass(frozen=True)
class Section:
    """A structural segment from station ``top`` down to ``bottom`` [m] (``top > bottom``) with
    bending stiffness ``EI`` [N m^2] and structural mass per length [kg/m]."""

    top: float
    bottom: float
    EI: float
    mass_per_length: float


@dataclass(frozen=True)
class DistributedMass:
    """Non-structural mass [kg] spread uniformly from station ``top`` down to ``bottom`` [m], e.g. a
    liquid column; it adds mass but no stiffness."""

    top: float
    bottom: float
    mass: float


def per_element(value, n_el: int, key: str, allow_zero: bool = False) -> np.ndarray:
    """``value`` (a number or ``n_el`` numbers) as an array, each finite and > 0 (>= 0)."""
    a = np.broadcast_to(np.asarray(value, dtype=float), (n_el,)) if np.ndim(value) == 0 else \
        np.asarray(value, dtype=float)
    if a.shape != (n_el,):
        raise ConfigError(key, value, f"a number or one value per element ({n_el})")
    if a.size and (a.min() >= 0.0 if allow_zero else a.min() > 0.0) and a.max() < math.inf:
        return a                                     # all finite and positive (NaN fails the min test)
    bad = ~np.isfinite(a) | ((a < 0.0) if allow_zero else (a <= 0.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(f"{key}[{i}]", float(a[i]), "must be finite and " + (">= 0" if allow_zero else "> 0"))
    return a


def stations_on(s, lo: float, hi: float, key: str) -> np.ndarray:
    """Stations ``s`` [m] as a 1-D array, each in [lo, hi] (within rounding)."""
    a = np.atleast_1d(np.asarray(s, dtype=float))
    if a.ndim != 1:
        raise ConfigError(key, s, "a sequence of stations [m]")
    tol = 1e-9 * max(1.0, hi - lo)
    if a.size and not (a.min() >= lo - tol and a.max() <= hi + tol):     # NaN fails the test too
        bad = ~np.isfinite(a) | (a < lo - tol) | (a > hi + tol)
        i = int(np.argmax(bad))
        raise ConfigError(f"{key}[{i}]", float(a[i]), f"must lie on the beam, in [{lo}, {hi}] m")
    return np.clip(a, lo, hi)


def point_mass_array(point_masses, lo: float, hi: float) -> np.ndarray:
    """(P, 3) array of station [m], mass [kg], rotary inertia [kg m^2]."""
    if not isinstance(point_masses, (list, tuple)):
        point_masses = list(point_masses)
    if all(type(pm) is PointMass for pm in point_masses):    # checked as floats; the loop names a bad one
        try:
            rows = [(float(pm.station), float(pm.mass), float(pm.rotary_inertia)) for pm in point_masses]
        except (TypeError, ValueError):
            rows = [(math.nan, math.nan, math.nan)]
        tol = 1e-9 * max(1.0, hi - lo)
        if all(lo - tol <= st <= hi + tol and 0.0 <= m < math.inf and 0.0 <= j < math.inf for st, m, j in rows):
            return np.array([(min(max(st, lo), hi), m, j) for st, m, j in rows], dtype=float).reshape(-1, 3)
    rows = []
    for i, pm in enumerate(point_masses):
        try:
            fields = (pm.station, pm.mass, pm.rotary_inertia) if isinstance(pm, PointMass) else tuple(pm)
            if len(fields) not in (2, 3):
                raise ValueError(fields)
            station, mass, inertia = (float(v) for v in (*fields, 0.0)[:3])
        except (TypeError, ValueError):
            raise ConfigError(f"point_masses[{i}]", pm, "a PointMass or (station, mass[, rotary_inertia])") from None
        for name, v in (("mass", mass), ("rotary_inertia", inertia)):
            if not (math.isfinite(v) and v >= 0.0):
                raise ConfigError(f"point_masses[{i}].{name}", v, "must be finite and >= 0")
        tol = 1e-9 * max(1.0, hi - lo)
        if not (math.isfinite(station) and lo - tol <= station <= hi + tol):
            raise ConfigError(f"point_masses[{i}].station", station, f"must lie on the beam, in [{lo}, {hi}] m")
        rows.append((min(max(station, lo), hi), mass, inertia))
    return np.array(rows, dtype=float).reshape(-1, 3)


def frozen_array(a: np.ndarray) -> np.ndarray:
    """A read-only float copy of ``a``."""
    a = np.ascontiguousarray(a, dtype=float)
    a.flags.writeable = False
    return a


# ---------------------------------------------------------------------------------------- stack meshing
@dataclass(frozen=True, eq=False)
class BeamMesh:
    """A meshed stack: node ``stations`` [m] nose first, per-element ``EI`` [N m^2] and
    ``mass_per_length`` [kg/m], and the point masses; the arguments of :func:`lvgym.vehicle.beam.modes`."""

    stations: np.ndarray
    EI: np.ndarray
    mass_per_length: np.ndarray
    point_masses: tuple[PointMass, ...]


def _span(obj, i: int, key: str, lo: float, hi: float) -> tuple[float, float]:
    top, bottom = float(obj.top), float(obj.bottom)
    if not (math.isfinite(top) and math.isfinite(bottom) and top > bottom):
        raise ConfigError(f"{key}[{i}].top", top, f"must be finite and above bottom = {bottom} m")
    tol = 1e-9 * max(1.0, hi - lo)
    for name, v in (("top", top), ("bottom", bottom)):
        if not lo - tol <= v <= hi + tol:
            raise ConfigError(f"{key}[{i}].{name}", v, f"must lie in [{lo}, {hi}] m")
    return min(top, hi), max(bottom, lo)


def _cumulative(s: np.ndarray, pieces: list[tuple[float, float, float]]) -> np.ndarray:
    """Integral from the tail to each station ``s`` of a piecewise-constant density [.. * m]."""
    if not pieces:
        return np.zeros_like(s)
    top, bottom, rate = (np.array(c)[None, :] for c in zip(*pieces))
    return (rate * np.clip(s[:, None] - bottom, 0.0, top - bottom)).sum(axis=1)


def _subdivide(kept: np.ndarray, h: float) -> np.ndarray:
    """Nodes [m] from the descending breakpoints ``kept``: each span cut into the fewest equal elements no
    longer than ``h`` [m], as ``np.linspace`` places them (``a + i (b - a) / n``, the span's end exact)."""
    return subdivide_k(np.ascontiguousarray(kept, dtype=float), float(h))


def mesh_stack(sections: Sequence[Section], point_masses: Sequence = (),
               distributed_masses: Sequence[DistributedMass] = (), *, query_stations=(),
               element_length: float | None = None) -> BeamMesh:
    """Mesh a stack of sections with point and distributed masses.

    Sections must tile the stack without gaps or overlaps (``top`` of one = ``bottom`` of the one
    above, within 1 micrometre). The mesh has nodes at every section and distributed-mass boundary,
    point mass and query station, and elements no longer than ``element_length`` [m] (default:
    stack length / ``DEFAULT_ELEMENTS``). Breakpoints closer than ``MERGE_FRACTION`` element lengths
    are merged (section boundaries first, then distributed-mass ends, then point masses, then query
    stations), so no sliver element spoils the conditioning; an element over a merged boundary takes
    the exact mass of its length and the series stiffness ``h / integral(1/EI)``. Point masses and
    queries off a node are placed and read with the element shape functions.
    """
    secs = list(sections)
    if not secs or not all(isinstance(s, Section) for s in secs):
        raise ConfigError("sections", sections, "a non-empty sequence of Section")
    hi = max(float(s.top) for s in secs)
    lo = min(float(s.bottom) for s in secs)
    if not (math.isfinite(hi) and hi <= 1e-9):
        raise ConfigError("sections[].top", hi, "stations are measured from the nose tip: <= 0 m")
    order = sorted(range(len(secs)), key=lambda i: -float(secs[i].top))
    bounds, stiff, mass = [hi], [], []
    for i in order:
        top, bottom = _span(secs[i], i, "sections", lo, hi)
        if abs(top - bounds[-1]) > 1e-6:
            raise ConfigError(f"sections[{i}].top", top, f"must equal the bottom of the section above, "
                              f"{bounds[-1]} m (sections tile the stack without gaps or overlaps)")
        for name in ("EI", "mass_per_length"):
            v = getattr(secs[i], name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ConfigError(f"sections[{i}].{name}", v, "must be a finite number > 0")
        top = bounds[-1]
        stiff.append((top, bottom, 1.0 / secs[i].EI))
        mass.append((top, bottom, secs[i].mass_per_length))
        bounds.append(bottom)
    length = hi - lo
    for i, dm in enumerate(distributed_masses):
        if not isinstance(dm, DistributedMass):
            raise ConfigError(f"distributed_masses[{i}]", dm, "a DistributedMass")
        top, bottom = _span(dm, i, "distributed_masses", lo, hi)
        if not (math.isfinite(dm.mass) and dm.mass >= 0.0):
            raise ConfigError(f"distributed_masses[{i}].mass", dm.mass, "must be finite and >= 0 kg")
        mass.append((top, bottom, dm.mass / (top - bottom)))
        bounds += [top, bottom]
    pm = point_mass_array(point_masses, lo, hi)
    query = stations_on(query_stations, lo, hi, "query_stations")
    try:
        h = length / DEFAULT_ELEMENTS if element_length is None else float(element_length)
    except (TypeError, ValueError):
        h = math.nan
    if not (math.isfinite(h) and h > 0.0):
        raise ConfigError("element_length", element_length, "a finite element length > 0 m, or None")
    gap = MERGE_FRACTION * min(h, length)
    kept = [lo, hi]                              # ascending; a breakpoint is kept if no kept one is within gap
    for b in [*map(float, bounds), *pm[:, 0].tolist(), *query.tolist()]:
        i = bisect.bisect_left(kept, b)          # the nearest kept ones are kept[i - 1] and kept[i]
        if (i == len(kept) or kept[i] - b >= gap) and (i == 0 or b - kept[i - 1] >= gap):
            kept.insert(i, b)
    kept = np.array(kept[::-1])
    x = _subdivide(kept, h)
    h_el = -np.diff(x)
    mpl = -np.diff(_cumulative(x, mass)) / h_el
    ei = h_el / -np.diff(_cumulative(x, stiff))
    return BeamMesh(stations=frozen_array(x), EI=frozen_array(ei), mass_per_length=frozen_array(mpl),
                    point_masses=tuple(PointMass(*row) for row in pm))

