"""Aerodynamic tables from geometry, so that every vehicle has aerodynamics without outside data.

:class:`BarrowmanAero` (registered as aerodynamics model ``barrowman``) builds an
:class:`~lvgym.environment.aerodynamics.AxisymmetricAero` (tables ``CA, CN, Cm, Cmq, Clp`` over Mach
and total angle of attack 0-180 deg) from a nose (cone, tangent ogive, von Karman), a cylindrical
body, an optional conical boat-tail and trapezoidal fin sets. Reference area ``pi d^2 / 4`` and
reference length ``d`` (body diameter). Sources of each term (details in docs/aerodynamics.md):

* Normal-force slopes and centres of pressure: Barrowman & Barrowman, "The theoretical prediction
  of the center of pressure", NARAM-8, 1966 (nose ``2 (A_b/S)``, nose CP from slender-body theory
  ``L - V/A_b``; conical transition ``2 (A_aft - A_fore)/S`` and its CP; fin CP). Fin slope:
  Diederich's planform correlation with Prandtl-Glauert ``beta = sqrt(1 - M^2)`` (as OpenRocket,
  Niskanen 2009, and RocketPy), fin-body interference ``1 + R/(s + R)``, fin-count factors of
  Niskanen 2009 (table 3.3). Supersonic fins: linear (Ackeret) theory of a rectangular wing
  ``4/beta (1 - 1/(2 beta AR))``, bounded by the slender-wing value ``pi AR / 2`` (R.T. Jones 1946),
  which Diederich's formula also reaches at M = 1, so the slope is continuous through M = 1.
* Large angles: ``CN = CNa sin(a) cos(a)`` (fins ``sin(a) |cos(a)|``) plus the crossflow term
  ``K (A_plan/S) sin^2(a)`` of the body planform at its centroid (Galejs 1999, K = 1.1) and of the
  fins (projected area (n/2) A_fin at its centroid); ``CA = CA0 cos(a)``.
* Axial force at zero angle: turbulent skin friction ``max(0.455/log10(Re)^2.58, 0.032 (eps/L)^0.2)``
  (Schlichting; roughness limit as Niskanen 2009) times ``(1 + 0.15 M^2)^-0.58`` with form factors
  ``1 + 1/(2 L/d)`` (body) and ``1 + 2 t/c`` (fins); base drag ``0.12 + 0.13 M^2`` (M < 1),
  ``0.25/M`` (Niskanen 2009, after Fleeman) on the base and the fins' trailing edges; nose wave drag:
  cone ``2.1 sin^2(phi) + 0.5 sin(phi)/sqrt(M^2 - 1)`` (Niskanen 2009), ogive and von Karman from
  slender-body theory ``D/q = (pi/4) sum n A_n^2`` (von Karman 1936; Ashley & Landahl 1965,
  ch. 9); fin wave drag ``4 (t/c)^2 / beta`` per fin area (Ackeret, double wedge). Wave terms rise
  smoothly (smoothstep) from 0 at M = 0.8 to their M = 1.2 value.
* Damping: ``Cmq`` from strip theory over the normal-force distribution about ``x_ref``,
  ``-2/L^2 int c(x) (x - x_ref)^2 dx``; ``Clp`` from fin strips over the span,
  ``-2 n CNa_1 int c(r) r^2 dr / (A_fin L^2)`` (Barrowman 1967, without interference factor).

Stations are x_b positions from the nose tip [m] (<= 0), lengths in m.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.errors import MISSING, ConfigError

from .aerodynamics import AxisymmetricAero
from .registry import register

NOSE_SHAPES = ("cone", "ogive", "von_karman")
FIN_COUNT_FACTOR = {5: 2.37, 6: 2.74, 7: 2.99, 8: 3.24}       # Niskanen 2009, else n / 2
MACH_GRID = (0.0, 0.2, 0.4, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.3, 1.5,
             1.75, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 8.0, 10.0)
# fine near 0 so the linear interpolation of the quadratic body-lift term adds little to the slope
# (0.4 % of CN_alpha at 0.05 deg for Stratos III; 1.9 % with a first step of 0.25 deg)
ALPHA_GRID_DEG = (0, 0.05, 0.1, 0.25, 0.5, 1, 1.5, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 70,
                  80, 90, 100, 110, 120, 130, 140, 150, 160, 170, 175, 180)
M_WAVE_START, M_WAVE_FULL = 0.8, 1.2


def _number(section: str, spec: Mapping[str, Any], key: str, lo: float = 0.0, *, positive: bool = True,
            hi: float = math.inf, default: Any = MISSING, allowed: str = "") -> float:
    value = spec.get(key, default)
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    ok = math.isfinite(x) and (x > lo if positive else x >= lo) and x <= hi
    if not ok:
        rel = ">" if positive else ">="
        upper = f" and <= {hi:g}" if hi < math.inf else ""
        raise ConfigError(f"{section}.{key}", value, allowed or f"a number [m] {rel} {lo:g}{upper}")
    return x


def _mapping(section: str, spec: Any, keys: tuple[str, ...]) -> Mapping[str, Any]:
    if not isinstance(spec, Mapping):
        raise ConfigError(section, spec, f"a mapping with keys {list(keys)}")
    for key in spec:
        if key not in keys:
            raise ConfigError(f"{section}.{key}", spec[key], f"unknown key; allowed {list(keys)}")
    return spec


@dataclass(frozen=True)
class FinSet:
    """Trapezoidal fins: ``count`` (3-8), chords, span, leading-edge sweep length (root to tip
    leading edge along the axis, aft positive), root leading-edge ``station`` and ``thickness`` [m]."""

    count: int
    root_chord: float
    tip_chord: float
    span: float
    sweep: float
    station: float
    thickness: float

    @property
    def area(self) -> float:
        """Planform area of one fin [m^2]."""
        return 0.5 * (self.root_chord + self.tip_chord) * self.span

    @property
    def mac(self) -> float:
        """Mean aerodynamic chord [m]."""
        cr, ct = self.root_chord, self.tip_chord
        return 2.0 / 3.0 * (cr + ct - cr * ct / (cr + ct))

    @property
    def x_cp(self) -> float:
        """Barrowman centre of pressure station [m]."""
        cr, ct, sw = self.root_chord, self.tip_chord, self.sweep
        return self.station - (sw / 3.0 * (cr + 2 * ct) / (cr + ct)
                               + (cr + ct - cr * ct / (cr + ct)) / 6.0)

    @property
    def x_centroid(self) -> float:
        """Station of the planform centroid [m]."""
        cr, ct, sw = self.root_chord, self.tip_chord, self.sweep
        return self.station - (sw * (cr + 2 * ct) + cr * cr + cr * ct + ct * ct) / (3.0 * (cr + ct))


def fin_normal_slope(fins: FinSet, radius: float, s_ref: float, mach: float) -> tuple[float, float]:
    """``(CNa of the set, CNa_1 of one fin alone)`` [1/rad] referred to ``s_ref`` [m^2], on a body
    of ``radius`` [m] at Mach ``mach``; the set includes interference and the fin-count factor."""
    s, area = fins.span, fins.area
    ar = 2.0 * s * s / area
    gamma_c = math.atan((fins.sweep + 0.5 * fins.tip_chord - 0.5 * fins.root_chord) / s)
    if mach < 1.0:
        fd = math.sqrt(1.0 - mach * mach) * ar / math.cos(gamma_c)
        slope = 2.0 * math.pi * ar / (2.0 + math.sqrt(4.0 + fd * fd))
    else:
        beta = math.sqrt(mach * mach - 1.0)
        slope = 0.5 * math.pi * ar
        if beta * ar >= 1.0:
            slope = min(slope, 4.0 / beta * (1.0 - 0.5 / (beta * ar)))
    single = slope * area / s_ref
    factor = FIN_COUNT_FACTOR.get(fins.count, 0.5 * fins.count)
    return factor * (1.0 + radius / (s + radius)) * single, single


def base_drag(mach: float) -> float:
    """Base drag coefficient referred to the base area [-] (Niskanen 2009, after Fleeman)."""
    return 0.12 + 0.13 * mach * mach if mach < 1.0 else 0.25 / mach


def wave_ramp(mach: float, supersonic) -> float:
    """0 below M 0.8, ``supersonic(M)`` above M 1.2, a smoothstep towards ``supersonic(1.2)`` between."""
    if mach <= M_WAVE_START:
        return 0.0
    if mach >= M_WAVE_FULL:
        return supersonic(mach)
    t = (mach - M_WAVE_START) / (M_WAVE_FULL - M_WAVE_START)
    return t * t * (3.0 - 2.0 * t) * supersonic(M_WAVE_FULL)


@functools.lru_cache(maxsize=4)
def _sine_table(n_terms: int, n_points: int = 4000) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Midpoints ``t`` (n_points,) of ``[0, pi]``, ``sin(n t)`` (n_terms, n_points) for n = 1..n_terms,
    ``cos t`` and ``sin t`` (n_points,): constants of :func:`slender_body_wave_drag` (3-4 ms to compute, so
    computed once), read-only."""
    t = (np.arange(n_points) + 0.5) * math.pi / n_points
    n = np.arange(1, n_terms + 1)
    table = np.sin(n[:, None] * t[None, :])
    cos_t, sin_t = np.cos(t), np.sin(t)
    for a in (t, table, cos_t, sin_t):
        a.flags.writeable = False
    return t, table, cos_t, sin_t


_SCRATCH = threading.local()


def _wave_scratch(shape: tuple[int, ...]) -> np.ndarray:
    """A scratch array of ``shape`` kept per thread (the products of :func:`slender_body_wave_drag`)."""
    buf = getattr(_SCRATCH, "wave", None)
    if buf is None or buf.shape != shape:
        buf = _SCRATCH.wave = np.empty(shape)
    return buf


def slender_body_wave_drag(shape: str, length: float, radius: float, n_terms: int = 80) -> float:
    """Wave drag coefficient (per base area) of a pointed nose on a cylinder, slender-body theory:
    ``S'(x) = sum A_n sin(n t)``, ``x = L (1 - cos t) / 2``, ``D/q = pi/4 sum n A_n^2``
    (von Karman 1936). The von Karman nose gives ``4 (R/L)^2``. Not for the cone (slope jump)."""
    t, table, cos_t, sin_t = _sine_table(n_terms)
    x = 0.5 * length * (1.0 - cos_t)
    r = nose_radius(shape, x, length, radius)
    ds_dt = np.gradient(math.pi * r * r, t)
    ds_dx = ds_dt / (0.5 * length * sin_t)
    n = np.arange(1, n_terms + 1)
    # the products into the process's scratch block (no new 2.6 MB temporary), each row summed alone
    a_n = np.multiply(table, ds_dx[None, :], out=_wave_scratch(table.shape)).sum(axis=1)
    a_n = 2.0 / 4000 * a_n
    return float(0.25 * math.pi * np.sum(n * a_n * a_n) / (math.pi * radius * radius))


def nose_radius(shape: str, xi: np.ndarray, length: float, radius: float) -> np.ndarray:
    """Radius [m] of the nose at distance ``xi`` [m] behind its tip (0..length)."""
    xi = np.clip(np.asarray(xi, dtype=float), 0.0, length)
    if shape == "cone":
        return radius * xi / length
    if shape == "ogive":                                   # tangent ogive
        rho = (radius * radius + length * length) / (2.0 * radius)
        return np.sqrt(np.maximum(rho * rho - (length - xi) ** 2, 0.0)) + radius - rho
    theta = np.arccos(1.0 - 2.0 * xi / length)             # von Karman (LD-Haack)
    return radius * np.sqrt(np.maximum(theta - 0.5 * np.sin(2.0 * theta), 0.0) / math.pi)


def nose_volume(shape: str, length: float, radius: float) -> float:
    """Volume of the nose [m^3] (closed forms)."""
    if shape == "cone":
        return math.pi * radius * radius * length / 3.0
    if shape == "ogive":
        rho = (radius * radius + length * length) / (2.0 * radius)
        return math.pi * (length * rho * rho - length ** 3 / 3.0
                          - (rho - radius) * rho * rho * math.asin(length / rho))
    return 0.5 * math.pi * radius * radius * length


@register("aerodynamics", "barrowman")
class BarrowmanAero(AxisymmetricAero):
    """Axisymmetric aerodynamic tables generated from the vehicle's outer geometry.

    Parameters
    ----------
    nose:
        ``{"shape": "cone" | "ogive" | "von_karman", "length": m}``.
    body:
        ``{"diameter": m, "length": m}``: the cylinder behind the nose (reference diameter).
    fins:
        One mapping or a list of them: ``{"count", "root_chord", "tip_chord", "span", "sweep"
        (leading-edge sweep length; default root - tip chord: unswept trailing edge), "station"
        (root leading edge, <= 0), "thickness"}`` [m]; the fins sit on the cylinder's radius.
    boat_tail:
        Optional ``{"length": m, "aft_diameter": m}`` behind the cylinder.
    x_ref:
        Moment reference station [m] of Cm and Cmq (default: half the length; give the mean CG).
    roughness, reynolds_per_m:
        Surface roughness [m] and the Reynolds number per metre [1/m] for skin friction.
    crossflow_k:
        Crossflow normal-force coefficient of the planform terms (Galejs: 1.1).
    mach, alpha_deg:
        Table grids (defaults ``MACH_GRID`` and ``ALPHA_GRID_DEG``, alpha from 0 to 180 deg).
    """

    def __init__(self, nose: Mapping[str, Any], body: Mapping[str, Any],
                 fins: Mapping[str, Any] | Sequence[Mapping[str, Any]] | None = None,
                 boat_tail: Mapping[str, Any] | None = None, x_ref: float | None = None,
                 roughness: float = 20e-6, reynolds_per_m: float = 7.0e6, crossflow_k: float = 1.1,
                 mach: Sequence[float] | None = None, alpha_deg: Sequence[float] | None = None) -> None:
        nose = _mapping("nose", nose, ("shape", "length"))
        if nose.get("shape") not in NOSE_SHAPES:
            raise ConfigError("nose.shape", nose.get("shape", MISSING), f"one of {list(NOSE_SHAPES)}")
        self.nose_shape = str(nose["shape"])
        self.nose_length = _number("nose", nose, "length")
        body = _mapping("body", body, ("diameter", "length"))
        self.diameter = _number("body", body, "diameter")
        self.body_length = _number("body", body, "length", positive=False)
        self.radius = 0.5 * self.diameter
        self.tail_length, self.aft_diameter = 0.0, self.diameter
        if boat_tail is not None:
            bt = _mapping("boat_tail", boat_tail, ("length", "aft_diameter"))
            self.tail_length = _number("boat_tail", bt, "length")
            self.aft_diameter = _number("boat_tail", bt, "aft_diameter")
            if abs(self.aft_diameter - self.diameter) < 1e-9 * self.diameter:
                raise ConfigError("boat_tail.aft_diameter", bt["aft_diameter"],
                                  "differs from body.diameter (leave boat_tail out for a cylinder)")
        self.length = self.nose_length + self.body_length + self.tail_length
        self.fins = self._fin_sets(fins)
        for key, value in (("roughness", roughness), ("reynolds_per_m", reynolds_per_m),
                           ("crossflow_k", crossflow_k)):
            _number("barrowman", {key: value}, key, positive=key != "roughness")
        self.roughness, self.reynolds_per_m = float(roughness), float(reynolds_per_m)
        self.crossflow_k = float(crossflow_k)
        self.s_ref = math.pi * self.radius ** 2
        xr = -0.5 * self.length if x_ref is None else _number(
            "barrowman", {"x_ref": x_ref}, "x_ref", -math.inf, positive=False, hi=0.0,
            allowed="a moment reference station [m] <= 0")
        self._c_sbt = (None if self.nose_shape == "cone"
                       else slender_body_wave_drag(self.nose_shape, self.nose_length, self.radius))
        grid_m = np.asarray(MACH_GRID if mach is None else mach, dtype=float)
        grid_a = np.asarray(ALPHA_GRID_DEG if alpha_deg is None else alpha_deg, dtype=float)
        # profile on a fine grid of distance behind the tip, for planform, areas and wetted surface
        self._xi = np.linspace(0.0, self.length, 4001)
        self._r = self.radius_at(self._xi)
        table = self._tables(grid_m, np.radians(grid_a), xr)
        table |= {"mach": grid_m, "alpha_deg": grid_a}
        super().__init__(table, self.s_ref, self.diameter, xr)

    # ------------------------------------------------------------------------- geometry
    def _fin_sets(self, fins: Any) -> tuple[FinSet, ...]:
        if fins is None:
            return ()
        specs = [fins] if isinstance(fins, Mapping) else list(fins)
        out = []
        for i, spec in enumerate(specs):
            sec = f"fins[{i}]"
            spec = _mapping(sec, spec, ("count", "root_chord", "tip_chord", "span", "sweep", "station",
                                        "thickness"))
            count = spec.get("count", MISSING)
            if not isinstance(count, (int, np.integer)) or isinstance(count, bool) or not 3 <= count <= 8:
                raise ConfigError(f"{sec}.count", count, "an integer from 3 to 8")
            cr = _number(sec, spec, "root_chord")
            ct = _number(sec, spec, "tip_chord", positive=False, default=0.0)
            sweep = _number(sec, spec, "sweep", -math.inf, positive=False, default=cr - ct)
            station = _number(sec, spec, "station", -self.length + cr, positive=False, hi=0.0,
                              allowed=f"the root leading-edge station [m], with the root chord on the "
                                      f"body: in [{cr - self.length:g}, 0]")
            out.append(FinSet(int(count), cr, ct, _number(sec, spec, "span"), sweep, station,
                              _number(sec, spec, "thickness", positive=False, hi=cr, default=0.0)))
        return tuple(out)

    def radius_at(self, xi: Any) -> np.ndarray:
        """Body radius [m] at distance ``xi`` [m] behind the nose tip (0 beyond the ends)."""
        xi = np.asarray(xi, dtype=float)
        ln, lb = self.nose_length, self.body_length
        slope = (0.5 * self.aft_diameter - self.radius) / max(self.tail_length, 1e-300)
        r_tail = self.radius + slope * (xi - ln - lb)
        r = np.where(xi < ln, nose_radius(self.nose_shape, xi, ln, self.radius),
                     np.where(xi <= ln + lb, self.radius, r_tail))
        return np.where((xi < 0.0) | (xi > self.length), 0.0, r)

    # ------------------------------------------------------------------------- components
    def components(self, mach: float) -> dict[str, tuple[float, float]]:
        """Linear normal-force slope [1/rad] (ref. area ``pi d^2/4``) and CP station [m] of each
        component at Mach ``mach``: ``nose``, ``boat_tail``, ``fins[i]``."""
        ln = self.nose_length
        out = {"nose": (2.0, -(ln - nose_volume(self.nose_shape, ln, self.radius) / self.s_ref))}
        if self.tail_length > 0.0:
            r = self.aft_diameter / self.diameter          # q = fore / aft diameter in Barrowman's CP
            x_top = -(ln + self.body_length)
            out["boat_tail"] = (2.0 * (r * r - 1.0),
                                x_top - self.tail_length / 3.0 * (1.0 + r / (1.0 + r)))
        for i, f in enumerate(self.fins):
            out[f"fins[{i}]"] = (fin_normal_slope(f, self.radius, self.s_ref, mach)[0], f.x_cp)
        return out

    def cn_alpha(self, mach: float) -> float:
        """Total normal-force slope at zero angle of attack [1/rad]."""
        return sum(c for c, _ in self.components(mach).values())

    def x_cp(self, mach: float) -> float:
        """Centre-of-pressure station at zero angle of attack [m]."""
        return sum(c * x for c, x in self.components(mach).values()) / self.cn_alpha(mach)

    def drag(self, mach: float) -> dict[str, float]:
        """Zero-angle axial force coefficient by term (ref. area ``pi d^2/4``); ``total`` their sum."""
        xi, r = self._xi, self._r
        wet_body = float(np.sum(math.pi * (r[1:] + r[:-1]) * np.hypot(np.diff(xi), np.diff(r))))
        re = self.reynolds_per_m * self.length
        cf = max(0.455 / math.log10(re) ** 2.58, 0.032 * (self.roughness / self.length) ** 0.2)
        cf *= (1.0 + 0.15 * mach * mach) ** -0.58
        friction = (1.0 + 0.5 * self.diameter / self.length) * wet_body
        te_area = 0.0
        fin_wave = 0.0
        for f in self.fins:
            friction += (1.0 + 2.0 * f.thickness / f.mac) * 2.0 * f.count * f.area
            te_area += f.count * f.thickness * f.span
            tc2 = (f.thickness / f.mac) ** 2
            fin_wave += wave_ramp(mach, lambda m: 4.0 * tc2 / math.sqrt(m * m - 1.0)) * f.count * f.area
        if self.nose_shape == "cone":
            phi = math.atan(self.radius / self.nose_length)
            sp = math.sin(phi)
            nose = wave_ramp(mach, lambda m: 2.1 * sp * sp + 0.5 * sp / math.sqrt(m * m - 1.0))
        else:
            nose = wave_ramp(mach, lambda m: self._c_sbt)
        terms = {"friction": cf * friction / self.s_ref,
                 "base": base_drag(mach) * (self.aft_diameter / self.diameter) ** 2,
                 "fin_base": base_drag(mach) * te_area / self.s_ref,
                 "nose_wave": nose, "fin_wave": fin_wave / self.s_ref}
        return terms | {"total": sum(terms.values())}

    # ------------------------------------------------------------------------- strips and tables
    def strips(self, mach: float = 0.0, n: int = 200) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Strip-theory distribution of the linear normal force: ``(x, width, cna)``, with ``x``
        the stations of ``n`` equal strips' centres [m], their widths [m] and each strip's share of
        CNa [1/rad] (its integral over the strip; ``cna / width`` is CNa per metre). Nose and
        boat-tail follow slender-body theory ``(2/S) dA/dx``; each fin set is spread evenly over one
        mean aerodynamic chord centred on its CP. ``cna.sum() == cn_alpha(mach)``."""
        edges = np.linspace(0.0, self.length, n + 1)           # distance behind the tip
        area = math.pi * self.radius_at(edges) ** 2
        area[-1] = math.pi * (0.5 * self.aft_diameter) ** 2
        cna = 2.0 / self.s_ref * np.diff(area)
        for i, f in enumerate(self.fins):
            c_f = self.components(mach)[f"fins[{i}]"][0]
            lo, hi = -f.x_cp - 0.5 * f.mac, -f.x_cp + 0.5 * f.mac
            overlap = np.clip(np.minimum(edges[1:], hi) - np.maximum(edges[:-1], lo), 0.0, None)
            if overlap.sum() <= 0.0:                       # CP outside the vehicle: nearest strip
                overlap[np.argmin(np.abs(edges[:-1] + f.x_cp))] = 1.0
            cna += c_f * overlap / overlap.sum()
        return -0.5 * (edges[1:] + edges[:-1]), np.diff(edges), cna

    def _tables(self, mach: np.ndarray, alpha: np.ndarray, x_ref: float) -> dict[str, np.ndarray]:
        sa, ca = np.sin(alpha), np.cos(alpha)
        r = self._r
        plan = float(np.trapezoid(2.0 * r, self._xi))
        x_plan = -float(np.trapezoid(2.0 * r * self._xi, self._xi)) / plan
        k = self.crossflow_k
        out = {key: np.zeros((len(mach), len(alpha))) for key in ("CA", "CN", "Cm", "Cmq", "Clp")}
        for i, m in enumerate(mach):
            cn = k * plan / self.s_ref * sa * sa
            cm = cn * (x_plan - x_ref)
            for name, (c, x) in self.components(m).items():
                shape = sa * (np.abs(ca) if name.startswith("fins") else ca)
                cn = cn + c * shape
                cm = cm + c * shape * (x - x_ref)
            for f in self.fins:
                plate = k * 0.5 * f.count * f.area / self.s_ref * sa * sa
                cn, cm = cn + plate, cm + plate * (f.x_centroid - x_ref)
            out["CN"][i], out["Cm"][i] = cn, cm / self.diameter
            out["CA"][i] = self.drag(m)["total"] * ca
            x, _, cna = self.strips(m, 400)
            out["Cmq"][i] = -2.0 / self.diameter ** 2 * np.sum(cna * (x - x_ref) ** 2)
            clp = 0.0
            for f in self.fins:
                cr, ct, s, rr = f.root_chord, f.tip_chord, f.span, self.radius
                i_r = ((cr + 3 * ct) * s ** 3 + 4 * (cr + 2 * ct) * rr * s * s
                       + 6 * (cr + ct) * s * rr * rr) / 12.0         # int_R^R+s c(r) r^2 dr
                single = fin_normal_slope(f, rr, self.s_ref, m)[1]
                clp -= 2.0 * f.count * single * i_r / (f.area * self.diameter ** 2)
            out["Clp"][i] = clp
        out["CN"][:, 0] = 0.0
        out["Cm"][:, 0] = 0.0
        return out
