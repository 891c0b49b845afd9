"""The vehicle file's ``tables`` (:mod:`lvgym.vehicle.timetables`) applied to the timeline's columns.

:func:`apply_mass` puts the ``mass_properties`` table's stack in place of the mass model's rigid-equivalent
stack at every row (the row before an event takes the table's row before a jump there); the rigid body B
the dynamics flies is that stack for the rigid and flex models, and the stack minus the slosh pendulums at
rest for the slosh and non-rigid models, so B and the pendulums together are the table's.
:func:`apply_modes` puts each ``modes`` table's frequency and damping in place of the beam's for its mode
and, with a ``slope_gimbal`` column, scales the beam's shape of that mode as a whole so that its slope at the
gimbal is the table's, and with a ``slope_imu`` column scales what the sensors read of it (the shapes at the
sensor stations) so that its slope at the table's ``imu_station`` is the table's; then decouples the modes
above the cut-off by their final frequencies (shapes zero). Both move a table's jumps onto the separation they stand for first
(:func:`~lvgym.vehicle.timetables.snap_jumps`).
"""

from __future__ import annotations

import numpy as np

from lvgym.errors import ConfigError
from lvgym.vehicle.massmodel import body_minus_pendulums
from lvgym.vehicle.timetables import VehicleTables, before_rows, snap_jumps, stack_at

__all__ = ["apply_mass", "apply_modes"]

#: the mode columns scaled with the shape: (key, axis of the mode, read by the sensors) in the timeline's mode
#: arrays
_SHAPES = (("phi_gimbal", 1, False), ("dphi_gimbal", 1, False), ("phi_hinge", 2, False), ("phi_sensor", 2, True),
           ("dphi_sensor", 2, True), ("phi_strip", 1, False), ("dphi_strip", 1, False))


def _separations(events) -> list[float]:
    return sorted({float(t) for t, e in events if e.endswith("separation") or e == "fairing jettison"})


def apply_mass(tables: VehicleTables | None, c: dict[str, np.ndarray], events, with_slosh: bool, N: int,
               source: str | None) -> None:
    """Replace, in place, the stack columns ``m`` (n,) [kg], ``cg`` (n, 3) [m], ``J`` (n, 3, 3) [kg m^2] and
    B's ``m_b``, ``r_cg``, ``J_b`` of the timeline's columns ``c`` by the ``mass_properties`` table (none:
    nothing changes); B without the ``N`` pendulums (``ms`` (n, N) [kg] at rest at ``rest`` (n, N, 3) [m])
    when the model flies them (``with_slosh``)."""
    if tables is None or tables.mass_properties is None:
        return
    table = snap_jumps(tables.mass_properties, _separations(events))
    t = c["t"]
    m, cg, J = stack_at(table, t, before_rows(t))
    c["m"], c["cg"], c["J"] = m, cg, J
    if with_slosh:
        c["m_b"], c["r_cg"], c["J_b"] = body_minus_pendulums(t, m, cg, J, c["ms"][:, :N], c["rest"][:, :N],
                                                             table.key, source)
    else:
        c["m_b"], c["r_cg"], c["J_b"] = m, cg, J


def apply_modes(tables: VehicleTables | None, md: dict, t: np.ndarray, K: int, cutoff_hz: float, events,
                source: str | None, modes_rows: list) -> None:
    """Replace, in place, the frequency and damping of each tabled mode (of the first ``K``) in the mode
    columns ``md`` of the rows ``t`` (n,) [s] (:func:`~lvgym.simulator.tabulate._mode_rows`, built without
    the cut-off; ``modes_rows`` each row's :class:`~lvgym.vehicle.structure.VehicleModes`), scale its shapes
    to the table's gimbal slope and its sensor shapes to the IMU slope when it gives them, carry the scale
    through the changes of basis (``eta' = eta / c``: ``T' = diag(1 / c_after) T diag(c_before)``), and decouple every
    mode above ``cutoff_hz`` [Hz] at its rows (shapes zero, its rows of a change's matrix zero)."""
    if tables is None or not tables.modes or K == 0:
        return
    before = before_rows(t)
    n = t.size
    scale = np.ones((n, K))
    sensed = {}                                                     # mode: the sensors' scale (n,)
    events = _separations(events)
    for k, table in enumerate(tables.modes[:K]):
        table = snap_jumps(table, events)
        rows = table.at(t, before)
        md["omega"][:, k] = 2.0 * np.pi * rows[:, 0]
        md["zeta"][:, k] = rows[:, 1]
        if rows.shape[1] >= 3:
            beam = md["dphi_gimbal"][:, k]
            _turns(beam, rows[:, 2], t, table.key, source, "the gimbal")
            scale[:, k] = rows[:, 2] / beam
        if rows.shape[1] == 4:
            beam = _beam_slopes(modes_rows, table.imu_station)[:, k]
            _turns(beam, rows[:, 3], t, table.key, source, "the IMU station")
            sensed[k] = rows[:, 3] / beam
    kept = md["omega"] <= 2.0 * np.pi * cutoff_hz                   # (n, K)
    factor = scale * kept
    read = factor.copy()
    for k, c in sensed.items():
        read[:, k] = c * kept[:, k]
    for key, axis, sensor in _SHAPES:
        a = md[key]
        shape = [n] + [1] * (a.ndim - 1)
        shape[axis] = K
        md[key] = a * (read if sensor else factor).reshape(shape)
    changes = []
    for tc, T in md["changes"]:
        after = int(np.searchsorted(t, tc, side="right")) - 1           # the row after the change
        prior = after - 1
        changes.append((tc, (kept[after] / scale[after])[:, None] * T * scale[prior][None, :]))
    md["changes"] = changes


def _turns(beam: np.ndarray, slope: np.ndarray, t: np.ndarray, key: str, source: str | None, where: str) -> None:
    """A :class:`ConfigError` naming ``key`` when the beam's slope ``beam`` (n,) at ``where`` is too small to be
    scaled to the table's ``slope`` (n,) at the rows ``t`` (n,) [s]."""
    tiny = np.abs(beam) <= 1e-9 * np.abs(slope)
    if tiny.any():
        i = int(np.argmax(tiny))
        raise ConfigError(key, f"t = {t[i]:g} s: slope {slope[i]:g} at {where}", f"a mode whose beam shape turns at "
                          f"{where} (the beam's slope there is {beam[i]:g}), so that it can be scaled to the table's",
                          source)


def _beam_slopes(modes_rows: list, station: float) -> np.ndarray:
    """The beam's slopes (n, K) [1/(m sqrt(kg))] at ``station`` [m] (clipped to the stack) of each row's modes."""
    seen: dict[int, np.ndarray] = {}
    for modes in modes_rows:
        if id(modes) not in seen:
            x = modes.beam.node_stations
            seen[id(modes)] = modes.beam.shape_at(np.clip([station], x.min(), x.max()))[1][0]
    return np.array([seen[id(modes)] for modes in modes_rows])
