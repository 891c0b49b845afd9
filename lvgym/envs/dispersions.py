"""The Monte Carlo dispersions of the ascent task as data: one row of :data:`DISPERSIONS` per drawn quantity.

A row names the ``randomize`` switch that draws it, the parameters it moves (:class:`Move`), its law
(``normal``: a deviation N(0, sigma) clipped at ``clip``; ``log_uniform``: a factor whose logarithm is
uniform over ``[low, high]``; ``integers``: a whole number uniform over ``low..high``; ``uniform``: a number
uniform over ``[low, high)``), whether the value
multiplies the parameters (``factor``: ``1 + d`` for a normal deviation) or is added to them (``offset``),
its unit, and where its range comes from (``source``, the column "why this range" of docs/benchmark.md,
which is generated from this table). A row whose unit is a dimension of the vehicle (``calibre``: the
first stage's outer diameter; ``length``: the vehicle's length) scales its sigma by it, and its clip stays
the same multiple of its sigma.

Each reset draws, for every row whose switch is in ``randomize``, in the table's order, from the row's
generator (:meth:`DispersionPlan.draw`). The order is part of the frozen protocols: a new row goes at the
end (an earlier place moves every later draw of a seed, and so every v0 / v1 episode). ``wind`` and
``sensor_noise`` are randomisations too (:data:`OTHER_RANDOMIZATIONS`), drawn after these by the wind
model and the sensors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.packing import Field, Packed
from lvgym.simulator.layouts import DISPERSION

from .faults import FAULT_DRAW

__all__ = ["DISPERSIONS", "IMU_STATION_INTERVALS", "IMU_STATION_SIGMA", "OTHER_RANDOMIZATIONS", "RANDOMIZE",
           "RANDOMIZE_V0", "SERVO_DISPERSION", "Dispersion", "DispersionPlan", "Move"]

#: the ``imu_station`` dispersion's sigma as a fraction of the vehicle's length (clipped at 3 sigma); the
#: timeline tabulates the mode shapes at ``IMU_STATION_INTERVALS`` + 1 evenly spaced stations over the
#: +-3 sigma range (the nominal one among them) and a row interpolates linearly between them
IMU_STATION_SIGMA = 0.005
IMU_STATION_INTERVALS = 24
#: a row's servo dispersion (``Simulator.reset_rows(servo_dispersion=...)``)
SERVO_DISPERSION = Packed("servo dispersion", [
    Field("frequency_scale", 1, "-", "factor on the servo's natural frequency"),
    Field("delay_steps", 1, "physics steps", "transport delay of the servo"),
], interface=True)
LAWS = ("normal", "log_uniform", "integers", "uniform")
EFFECTS = ("factor", "offset")
#: the units a row's sigma may be given in that are a dimension of the vehicle
VEHICLE_UNITS = ("calibre", "length")
#: conditions under which a row is drawn or a move applies, on the task's options
CONDITIONS = {"flight_observation": lambda spec: spec.observation == "flight",
              "tabulated_slosh_frequency": lambda spec: spec.slosh_frequency == "vacuum_thrust"}


@dataclass(frozen=True)
class Move:
    """A parameter a dispersion moves: ``target`` is ``block.name`` with block ``params`` (the dynamics
    parameters, layout ``PARAMS``; ``name[i]`` its entry i), ``slosh`` (that parameter of every pendulum),
    ``loads`` (layout :data:`~lvgym.simulator.layouts.DISPERSION`), ``servo`` (:data:`SERVO_DISPERSION`),
    ``thrust.misalignment`` (pitch, yaw), ``imu.station`` or ``fault`` (the row's fault draw, layout
    :data:`~.faults.FAULT_DRAW`); ``power``: a factor acts as its ``power``-th
    power (-2: the parameter is divided by its square); ``only``: a key of :data:`CONDITIONS`, or None."""

    target: str
    power: int = 1
    only: str | None = None


@dataclass(frozen=True)
class Dispersion:
    """One drawn quantity (see the module docstring)."""

    name: str
    """the ``randomize`` switch that draws it"""
    what: str
    """what is drawn, in words"""
    moves: tuple[Move, ...]
    """the parameters the one draw moves"""
    law: str
    """``normal``, ``log_uniform``, ``integers`` or ``uniform``"""
    effect: str
    """``factor`` (the parameters are multiplied by it, ``1 + d`` for a normal deviation) or ``offset``"""
    sigma: float = 0.0
    """``normal``: the standard deviation, in ``unit``"""
    clip: float = 0.0
    """``normal``: the largest deviation drawn, in ``unit`` (3 sigma throughout)"""
    low: float = 0.0
    """``log_uniform``, ``integers``, ``uniform``: the range's low end"""
    high: float = 0.0
    """``log_uniform``, ``integers``: the range's high end (drawn too); ``uniform``: its open end"""
    unit: str = "-"
    """of sigma and clip: ``-`` (a fraction), a unit (``m``, ``deg``: converted to rad), ``physics step``
    or a dimension of the vehicle (:data:`VEHICLE_UNITS`)"""
    size: int = 1
    """values drawn in one call (2: one per axis)"""
    only: str | None = None
    """drawn only under this key of :data:`CONDITIONS`"""
    source: str = ""
    """why this range"""

    def __post_init__(self) -> None:
        if self.law not in LAWS or self.effect not in EFFECTS:
            raise ValueError(f"dispersion {self.name!r}: law {self.law!r} of {LAWS}, effect {self.effect!r} of "
                             f"{EFFECTS}")
        if self.law == "normal" and not 0.0 < self.sigma <= self.clip:
            raise ValueError(f"dispersion {self.name!r}: sigma {self.sigma} > 0 and clip {self.clip} >= sigma")

    def sample(self, rng: np.random.Generator, scale: float = 1.0) -> Any:
        """One draw from ``rng`` (a float, or an array of ``size``), as the parameters take it: a factor
        (``1 + d`` for a normal deviation) or an offset in SI units. ``scale``: the vehicle dimension of a
        row given in one (:data:`VEHICLE_UNITS`; [m])."""
        n = None if self.size == 1 else self.size
        if self.law == "normal":
            if self.unit in VEHICLE_UNITS:
                sigma = self.sigma * scale
                limit = (self.clip / self.sigma) * sigma
            else:
                sigma, limit = self.sigma, self.clip
            d = np.clip(rng.normal(0.0, sigma, n), -limit, limit)
            if self.unit == "deg":
                d = np.radians(d)
            return 1.0 + d if self.effect == "factor" else d
        if self.law == "log_uniform":
            return math.exp(rng.uniform(math.log(self.low), math.log(self.high)))
        if self.law == "uniform":
            return float(rng.uniform(self.low, self.high))
        return float(rng.integers(int(self.low), int(self.high) + 1))

    def _amount(self, x: float) -> str:
        """``x`` in the row's unit, for the docs (a fraction in per cent)."""
        if self.unit in ("-", "length"):
            return f"{x * 100:g} %" + (" of the length" if self.unit == "length" else "")
        return f"{x:g} {self.unit}"

    def law_text(self) -> str:
        """The law and its spread in words (the docs table's column)."""
        if self.law == "normal":
            sigma = self._amount(self.sigma)
            return f"x N(1, {sigma})" if self.effect == "factor" else f"+ N(0, {sigma})"
        if self.law == "log_uniform":
            return f"x log-uniform [{self.low:g}, {self.high:g}]"
        if self.law == "uniform":
            return f"uniform [{self.low:g}, {self.high:g})"
        unit = "" if self.unit == "-" else f" {self.unit}"
        return f"+ {' or '.join(str(k) for k in range(int(self.low), int(self.high) + 1))}{unit}"

    def clip_text(self) -> str:
        """The clip in words (the docs table's column; a range's ends for the other laws)."""
        return f"+-{self._amount(self.clip)}" if self.law == "normal" else "its range"


def _normal(name: str, what: str, moves: tuple, sigma: float, clip: float, source: str, **kw: Any) -> Dispersion:
    """A row of the normal law (a factor unless ``effect="offset"``)."""
    return Dispersion(name, what, moves, "normal", kw.pop("effect", "factor"), sigma=sigma, clip=clip, source=source,
                      **kw)


_TWO = "the damping of a baffled tank is known to a factor of two at best"
_FAULTS = "the kinds and their ranges: `lvgym.envs.faults.FAULT_KINDS` (below, \"In-flight faults\")"
_SLOSH = "the equivalent-mechanical-model masses against tests"
#: the dispersions, in the order a reset draws them (v0's first, then v1's)
DISPERSIONS: tuple[Dispersion, ...] = (
    _normal("mass", "body mass", (Move("params.m_b"),), 0.01, 0.03,
            "mass properties of a built vehicle are weighed"),
    _normal("mass", "CG station", (Move("params.r_cg[0]"),), 0.02, 0.06,
            "mass properties of a built vehicle are weighed (its CG station too)", effect="offset", unit="m"),
    _normal("mass", "inertia", (Move("params.J_b"),), 0.03, 0.09, "inertias are computed and less sure"),
    Dispersion("slosh_damping", "slosh damping ratios", (Move("slosh.zeta"),), "log_uniform", "factor", low=0.5,
               high=2.0, source=_TWO),
    _normal("bending_frequency", "bending frequencies", (Move("params.omega_modes"),), 0.05, 0.15,
            "finite-element frequencies against modal tests differ by a few per cent"),
    _normal("thrust_misalignment", "fixed thrust misalignment per axis (pitch, yaw)", (Move("thrust.misalignment"),),
            0.05, 0.15, "engine alignment tolerance of the order of 0.1 deg (3 sigma 0.15 deg)", effect="offset",
            unit="deg", size=2),
    _normal("aerodynamics", "normal force and moment", (Move("loads.normal_scale"),), 0.05, 0.15,
            "the semi-empirical (Barrowman-class) tables are good to several per cent in force; reasoned, not "
            "from a published database. Where the aeroelastic strip loads are on (slender), the factor scales "
            "them too (force, moment and modal forces)"),
    _normal("aerodynamics", "axial force", (Move("loads.axial_scale"),), 0.05, 0.15,
            "the same tables' drag, to several per cent"),
    _normal("aerodynamics", "centre of pressure", (Move("loads.cp_shift"),), 0.25, 0.75,
            "a fraction of a calibre in centre of pressure; it moves only the table's rigid normal force",
            effect="offset", unit="calibre"),
    _normal("thrust_level", "thrust (mass flow kept: an Isp dispersion)", (Move("loads.thrust_scale"),), 0.01, 0.03,
            "engine-to-engine thrust spread of acceptance tests, of the order of 1 %"),
    _normal("slosh_mass", "pendulum masses", (Move("slosh.m"),), 0.05, 0.15, _SLOSH),
    _normal("slosh_frequency", "pendulum frequencies (lengths / f^2; the tabulated damper frequency x f)",
            (Move("slosh.length", power=-2), Move("slosh.omega", only="tabulated_slosh_frequency")), 0.05, 0.15,
            "the same for frequencies; with `slosh_frequency=\"specific_force\"` the damper's frequency follows "
            "from the dispersed length"),
    Dispersion("bending_damping", "modal damping ratios", (Move("params.zeta_modes"),), "log_uniform", "factor",
               low=0.5, high=2.0,
               source="structural damping is seldom known better than a factor of two before flight"),
    _normal("servo_bandwidth", "the servo's natural frequency", (Move("servo.frequency_scale"),), 0.1, 0.3,
            "a hydraulic or electromechanical actuator's bandwidth moves with load, supply pressure and "
            "temperature by some ten per cent"),
    Dispersion("servo_delay", "a transport delay in the servo", (Move("servo.delay_steps"),), "integers", "offset",
               low=0, high=1, unit="physics step", source="actuator electronics and data-bus latency of a few ms; "
               "quantised at the physics step (0 or 10 ms at the default step)"),
    _normal("imu_station", "the IMU station along x_b (gyro slope term, accelerometer shape and lever arm); "
            "`observation=\"flight\"` only", (Move("imu.station"),), IMU_STATION_SIGMA, 0.015,
            "mounting tolerance (millimetres) plus the mode-shape uncertainty expressed as an equivalent "
            "station shift: SMILE 8.25 cm (3 sigma 0.25 m), Stratos III 4.1 cm, slender 4.25 cm; reasoned, see "
            "below", effect="offset", unit="length", only="flight_observation"),
    # protocol v2's in-flight fault (lvgym.envs.faults): one per episode, what and when drawn here
    Dispersion("fault", "the fault's kind, one of `fault_kinds` (an equal share each)", (Move("fault.kind"),),
               "uniform", "offset", low=0.0, high=1.0, source=_FAULTS),
    Dispersion("fault", "the fault's onset, its place in the `fault_onset_s` window", (Move("fault.onset"),),
               "uniform", "offset", low=0.0, high=1.0, source="unannounced: any time in the window"),
    Dispersion("fault", "the fault's size, its place in the kind's range", (Move("fault.severity"),), "uniform",
               "offset", low=0.0, high=1.0, source=_FAULTS),
    Dispersion("fault", "the fault's axis: pitch (0) or yaw (1)", (Move("fault.axis"),), "integers", "offset",
               low=0, high=1, source="the vehicle is axisymmetric: either axis alike"),
    Dispersion("fault", "the sign of a gyro bias or misalignment step: negative (0) or positive (1)",
               (Move("fault.sign"),), "integers", "offset", low=0, high=1, source="either sign alike"),
)
#: the randomisations drawn elsewhere: what they draw, and where it is documented
OTHER_RANDOMIZATIONS = {
    "wind": "the wind model's draws (the tier's): [atmosphere and wind](atmosphere-and-wind.md)",
    "sensor_noise": "the sensors' bias, drift and noise: [sensors](sensors.md)",
}
#: protocol v0's randomisations (what ``randomize=True`` means)
RANDOMIZE_V0 = ("wind", "thrust_misalignment", "mass", "slosh_damping", "bending_frequency", "sensor_noise")
#: every randomisation by name: v0's, then the rows' others in the table's order
RANDOMIZE = RANDOMIZE_V0 + tuple(dict.fromkeys(d.name for d in DISPERSIONS if d.name not in RANDOMIZE_V0))


class DispersionPlan:
    """The rows of :data:`DISPERSIONS` a task draws, with their targets resolved to entries of the arrays
    a reset hands the simulator. ``spec``: the task's options; ``layout``: the dynamics layout (its
    ``params`` and ``slosh_param``); ``n_slosh``: pendulums; ``vehicle``: its dimensions."""

    def __init__(self, spec: Any, layout: Any, n_slosh: int, vehicle: Any) -> None:
        self.n_p = layout.n_p
        dims = {"calibre": vehicle.stages[0].outer_diameter, "length": vehicle.length}
        self.rows: list[tuple[Dispersion, float, list[tuple[str, Any, int]]]] = []
        for row in DISPERSIONS:
            if row.name not in spec.randomize or (row.only and not CONDITIONS[row.only](spec)):
                continue
            targets = [(_array(m.target, row.effect), idx, m.power) for m in row.moves
                       if m.only is None or CONDITIONS[m.only](spec) for idx in _entries(m.target, layout, n_slosh)]
            self.rows.append((row, dims.get(row.unit, 1.0), targets))

    def neutral(self) -> dict[str, np.ndarray]:
        """The arrays of an undispersed row."""
        return {"scale": np.ones(self.n_p), "offset": np.zeros(self.n_p), "misalignment": np.zeros(2),
                "loads": DISPERSION.pack({"thrust_scale": 1.0, "normal_scale": 1.0, "axial_scale": 1.0}),
                "servo": SERVO_DISPERSION.pack({"frequency_scale": 1.0}), "station": np.zeros(1),
                "fault": FAULT_DRAW.zeros()}

    def draw(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                      float, np.ndarray]:
        """One row's parameter scale and offset (n_p,), thrust misalignment (2,) [rad], load dispersions
        (layout DISPERSION), servo dispersion (layout :data:`SERVO_DISPERSION`), IMU station shift [m] and
        fault draw (layout :data:`~.faults.FAULT_DRAW`), drawn from ``rng`` row by row in the table's
        order."""
        out = self.neutral()
        for row, scale, targets in self.rows:
            value = row.sample(rng, scale)
            for array, idx, power in targets:
                a = out[array]
                if row.effect == "factor":
                    if power == 1:
                        a[idx] *= value
                    else:
                        a[idx] /= _power(value, -power)
                else:
                    a[idx] += value
        return (out["scale"], out["offset"], out["misalignment"], out["loads"], out["servo"],
                float(out["station"][0]), out["fault"])


def _power(x: Any, n: int) -> Any:
    """``x`` to the whole power ``n`` >= 1 by repeated products (``x * x`` for 2, as the hand-written law)."""
    y = x
    for _ in range(n - 1):
        y = y * x
    return y


def _array(target: str, effect: str) -> str:
    """The array a target's block lives in (a parameter's factor in ``scale``, its offset in ``offset``)."""
    block = target.split(".")[0]
    if block in ("params", "slosh"):
        return "scale" if effect == "factor" else "offset"
    return {"thrust": "misalignment", "imu": "station"}.get(block, block)


def _entries(target: str, layout: Any, n_slosh: int) -> list[Any]:
    """The index (or indices, one per pendulum) of ``target`` in its array."""
    block, _, name = target.partition(".")
    if block == "params":
        key, _, element = name.partition("[")
        sl = layout.params[key]
        return [sl.start + int(element.rstrip("]"))] if element else [sl]
    if block == "slosh":
        return [layout.slosh_param(j, name) for j in range(n_slosh)]
    if block == "loads":
        return [DISPERSION.index(name)]
    if block == "servo":
        return [SERVO_DISPERSION.index(name)]
    if block == "fault":
        return [FAULT_DRAW.index(name)]
    if target in ("thrust.misalignment", "imu.station"):
        return [slice(None)]
    raise ValueError(f"dispersion target {target!r}: params.<name>[i], slosh.<name>, loads.<name>, servo.<name>, "
                     "fault.<name>, thrust.misalignment or imu.station")
