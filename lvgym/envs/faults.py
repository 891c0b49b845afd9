"""In-flight faults of the ascent task: what each kind does, how a row's fault is drawn, and when it strikes.

A task whose ``randomize`` holds ``fault`` draws one fault per episode at every reset, from the env's
generator, through the ``fault`` rows of the dispersion table (:data:`.dispersions.DISPERSIONS`, layout
:data:`FAULT_DRAW`: the kind, the onset and the severity, each uniform, the axis and the sign, 0 or 1). The
kind is one of the task's ``fault_kinds``, the onset is uniform over ``fault_onset_s`` (the window, in flight
time), the severity places the fault's size in its kind's range (:data:`FAULT_KINDS`), the axis is pitch or
yaw. The fault strikes at the first control step that starts at or after its onset and stays for the rest of
the flight. Nothing in the observation or the step's info announces it: the info names it
(``info["fault"]``) only at the step that ends the episode.

The kinds, as they act on the flight (the actuator faults act in the simulator's servo,
:mod:`lvgym.simulator.servo`):

- ``effectiveness``: loss of actuator effectiveness on one axis: the servo drives the gimbal towards ``(1 -
  size)`` times the command (an actuator that moves less than commanded, a weakened hydraulic supply);
- ``bandwidth``: loss of actuator bandwidth on one axis: the servo's natural frequency times ``(1 - size)``;
- ``stuck``: an actuator jammed at its current angle on one axis;
- ``thrust``: loss of thrust, the thrust times ``(1 - size)`` from the onset (the mass flow is the
  timeline's: a combustion or nozzle fault);
- ``gyro_bias``: a step in the rate gyro's bias on one axis, ``size`` [rad/s] of either sign: the rate the
  policy sees is off by it, and the attitude the flight computer integrates from it drifts;
- ``misalignment``: a step in the thrust's direction on one axis, ``size`` [rad] of either sign, added to the
  row's thrust misalignment (a nozzle damaged in flight: its thrust turns off the gimbal's axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lvgym.packing import Field, Packed
from lvgym.simulator.layouts import ACTUATOR

from .layouts import FAULT_INFO

__all__ = ["FAULT", "FAULT_DRAW", "FAULT_KINDS", "FAULT_NAMES", "FaultKind", "apply_faults", "decode", "fault_info",
           "fault_names"]


@dataclass(frozen=True)
class FaultKind:
    """One kind of fault: its ``name``, what it does (``what``), its size range ``low``..``high`` in ``unit``
    (a fraction, or deg/s: converted to rad/s), whether it acts on one axis, and where the range comes from."""

    name: str
    what: str
    low: float
    high: float
    unit: str
    one_axis: bool
    source: str

    def size(self, severity: float) -> float:
        """The fault's size in SI (a fraction, or rad/s) at ``severity`` in [0, 1] of the range."""
        x = self.low + severity * (self.high - self.low)
        return math.radians(x) if self.unit in ("deg", "deg/s") else x


#: the kinds of fault, in code order (code = index + 1; 0 is no fault)
FAULT_KINDS = (
    FaultKind("effectiveness", "loss of actuator effectiveness on one axis", 0.3, 0.7, "-", True,
              "30-70 %: the range protocol v2 sets; adaptive augmenting control is built to recover lost control "
              "effectiveness (docs/adaptive-control.md: gs-pid scaled by 0.4)"),
    FaultKind("bandwidth", "loss of actuator bandwidth on one axis", 0.5, 0.8, "-", True,
              "a servo at half to a fifth of its natural frequency: a hydraulic supply or a motor that lost "
              "pressure or power (reasoned: no flight statistics found)"),
    FaultKind("stuck", "an actuator stuck at its current angle on one axis", 0.0, 0.0, "-", True,
              "a jammed actuator holds its position"),
    FaultKind("thrust", "loss of thrust", 0.1, 0.3, "-", False,
              "10-30 %: the range protocol v2 sets; a partial loss of a first stage's thrust"),
    FaultKind("gyro_bias", "a rate-gyro bias step on one axis", 0.05, 0.25, "deg/s", True,
              "58 to 290 times the flight gyro's bias sigma (1.5e-5 rad/s); 0.5 deg/s failed every shipped policy "
              "(experiments/protocol_v2_design); to be tuned on validation seeds with the suite"),
    FaultKind("misalignment", "a thrust-direction step on one axis (a damaged nozzle)", 0.5, 1.5, "deg", True,
              "Ariane 5 flight 157 (11 December 2002): a leak in the Vulcain 2 nozzle's cooling circuit overheated "
              "the nozzle, and its deterioration caused a major thrust imbalance and the loss of control (Arianespace "
              "inquiry board, January 2003); sized here at 3 to 10 times the 0.15 deg alignment tolerance, within a "
              "third of SMILE's 5 deg gimbal range, so that a design can hold it"),
)
FAULT_NAMES = tuple(k.name for k in FAULT_KINDS)
_SIGNED = ("gyro_bias", "misalignment")            # kinds of either sign (the draw's ``sign``)
#: what the dispersion table draws for a row's fault (:data:`.dispersions.DISPERSIONS`, in this order)
FAULT_DRAW = Packed("fault draw", [
    Field("kind", 1, "-", "uniform [0, 1): picks one of the task's fault_kinds"),
    Field("onset", 1, "-", "uniform [0, 1]: the onset's place in the fault_onset_s window"),
    Field("severity", 1, "-", "uniform [0, 1]: the size's place in the kind's range"),
    Field("axis", 1, "-", "0 or 1: pitch or yaw"),
    Field("sign", 1, "-", "0 or 1: the gyro bias step or the misalignment step negative or positive"),
], interface=True)
#: a row's fault in the task's rows (``TaskData.fault``)
FAULT = Packed("fault", [
    Field("kind", 1, "-", "code of the kind: 0 none, else the index in FAULT_KINDS plus 1"),
    Field("onset_s", 1, "s", "flight time from which it acts"),
    Field("size", 1, "-, rad/s or rad", "its size (a fraction, the gyro bias step or the misalignment step)"),
    Field("axis", 1, "-", "0 pitch, 1 yaw (unused by a kind on no axis)"),
    Field("active", 1, "-", "1 once it has struck"),
], interface=True)
_F = FAULT.at


def decode(draw: np.ndarray, kinds: tuple[str, ...], window: tuple[float, float]) -> np.ndarray:
    """A row's fault (layout :data:`FAULT`) from its draw (layout :data:`FAULT_DRAW`), among ``kinds`` (names
    of :data:`FAULT_KINDS`) and with its onset in ``window`` [s]; no kinds: no fault."""
    out = FAULT.zeros()
    if not kinds:
        return out
    d = FAULT_DRAW.at
    name = kinds[min(int(draw[d.kind] * len(kinds)), len(kinds) - 1)]
    kind = FAULT_KINDS[FAULT_NAMES.index(name)]
    out[_F.kind] = FAULT_NAMES.index(name) + 1
    out[_F.onset_s] = window[0] + float(draw[d.onset]) * (window[1] - window[0])
    size = kind.size(float(draw[d.severity]))
    out[_F.size] = -size if kind.name in _SIGNED and draw[d.sign] == 0.0 else size
    out[_F.axis] = float(draw[d.axis])
    return out


def fault_names(fault: np.ndarray) -> np.ndarray:
    """The name of each row's fault (B,), ``""`` for none: ``kind`` plus the axis of a one-axis kind, e.g.
    ``"stuck pitch"``."""
    out = np.full(fault.shape[0], "", dtype=object)
    for b in np.flatnonzero(fault[:, _F.kind] > 0):
        kind = FAULT_KINDS[int(fault[b, _F.kind]) - 1]
        out[b] = kind.name + ((" yaw" if fault[b, _F.axis] else " pitch") if kind.one_axis else "")
    return out


#: the :data:`~.layouts.FAULT_INFO` entries of each one-axis kind, pitch then yaw, and the scale of its size
_INFO_ENTRIES = {"effectiveness": (("fault_effectiveness_loss_pitch", "fault_effectiveness_loss_yaw"), 1.0),
                 "bandwidth": (("fault_bandwidth_loss_pitch", "fault_bandwidth_loss_yaw"), 1.0),
                 "gyro_bias": (("fault_gyro_bias_pitch", "fault_gyro_bias_yaw"), math.degrees(1.0)),
                 "misalignment": (("fault_misalignment_pitch", "fault_misalignment_yaw"), math.degrees(1.0)),
                 "stuck": (("fault_stuck_pitch", "fault_stuck_yaw"), 1.0)}


def fault_info(fault: np.ndarray) -> np.ndarray:
    """The privileged observation block of each row's fault (B, :data:`~.layouts.FAULT_INFO` size), float32:
    zeros until it strikes (``active``), then its size on its kind's entry (deg and deg/s for the angle and
    the gyro bias; 1 for a stuck actuator)."""
    out = FAULT_INFO.zeros(fault.shape[0], np.float32)
    at = FAULT_INFO.at
    for b in np.flatnonzero((fault[:, _F.kind] > 0) & (fault[:, _F.active] > 0.0)):
        name = FAULT_NAMES[int(fault[b, _F.kind]) - 1]
        out[b, at.fault_active] = 1.0
        if name == "thrust":
            out[b, at.fault_thrust_loss] = fault[b, _F.size]
        else:
            entries, scale = _INFO_ENTRIES[name]
            size = 1.0 if name == "stuck" else fault[b, _F.size] * scale
            out[b, getattr(at, entries[int(fault[b, _F.axis])])] = size
    return out


def apply_faults(sim: Any, data: Any, fault: np.ndarray, gyro_bias: np.ndarray) -> np.ndarray:
    """Let strike, in place, the faults of the rows whose onset has come (``data.t`` at or after it) and that
    have not struck yet: the actuator's fault fields (``data.actuator``), the thrust scale of the row's loads
    (``sim.load_dispersion``), the row's thrust misalignment (``sim.misalignment``) or the gyro bias
    (``gyro_bias`` (B, 3) [rad/s], roll, pitch, yaw); marks them active. Returns the rows that struck."""
    kind = fault[:, _F.kind]
    rows = np.flatnonzero((kind > 0) & (fault[:, _F.active] == 0.0) & (data.t >= fault[:, _F.onset_s] - 1e-9))
    if rows.size == 0:
        return rows
    for b in rows:
        name = FAULT_NAMES[int(kind[b]) - 1]
        size, axis = float(fault[b, _F.size]), int(fault[b, _F.axis])
        if name == "effectiveness":
            ACTUATOR.view(data.actuator, "effectiveness_loss")[b, axis] = size
        elif name == "bandwidth":
            ACTUATOR.view(data.actuator, "bandwidth_loss")[b, axis] = size
        elif name == "stuck":
            ACTUATOR.view(data.actuator, "stuck")[b, axis] = 1.0
        elif name == "thrust":
            sim.load_dispersion(data, "thrust_scale")[b] *= 1.0 - size
        elif name == "misalignment":
            sim.misalignment(data)[b, axis] += size
        else:                                                    # gyro_bias: body y (pitch) or z (yaw)
            gyro_bias[b, 1 + axis] += size
    fault[rows, _F.active] = 1.0
    return rows
