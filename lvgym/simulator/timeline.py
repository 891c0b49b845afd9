"""The mission timeline: the mass model and the bending modes tabulated over the flight, once per vehicle.

Propellant depletion and staging do not depend on the vehicle's motion (the engines run at full
throttle), so the dynamics parameters, the thrust and the mass properties are functions of time
alone. :func:`~.tabulate.build_timeline` evaluates :class:`~lvgym.vehicle.MassModel` and
:class:`~lvgym.vehicle.structure.ModeSchedule` on a grid (every ``dt`` seconds, every breakpoint of a
thrust table and both sides of every event), array-wise, one batch of rows per stretch between events
(:meth:`~lvgym.vehicle.MassModel.history`; the same numbers, to the last bit, as evaluating the rows one at
a time), and :class:`Timeline` interpolates it linearly, so a step
costs a table look-up instead of a mass-model evaluation and a batch of vehicles at different times
looks up its rows in one call. Event times are stored twice (the row before and the row after), and the
simulator lands its steps on them, so nothing is interpolated across a separation.

Mode data are held piecewise constant between the times the modes are recomputed (separations, and every
``mode_interval`` seconds when set). ``mode_basis`` says what becomes of the modal state at such a change:
``held`` (v0) keeps the numbers ``eta``, ``eta_dot`` as they are in the new basis; ``projected`` keeps the
deflection field: the timeline stores one transfer matrix per change (:func:`lvgym.vehicle.structure.mode_transfer`,
rows of modes above the cut-off zeroed, several changes at one time multiplied into one), the simulator
cuts its steps at the change times and applies the matrix there (:mod:`.piece`).

A vehicle file's ``tables`` (:mod:`lvgym.vehicle.timetables`) replace the stack's mass, CG and inertia and
the tabled modes' frequencies and damping in the rows (:mod:`.tabled`).

``model`` picks which parameters the dynamics core flies (thesis section 4.4):

=============  ===============================================================================
``rigid``      the rigid-equivalent stack (slosh masses frozen at rest): same mass, CG and inertia
``slosh``      the rigid body B and one pendulum per slosh tank
``flex``       the rigid-equivalent stack on its bending modes (slosh masses on the beam as rigid)
``nonrigid``   B, the pendulums and the modes, coupled (the thesis's full model)
=============  ===============================================================================
"""

from __future__ import annotations

import functools
from collections import namedtuple
from dataclasses import dataclass

import numba as nb
import numpy as np

from lvgym.dynamics import NonRigidModel

MODELS = ("rigid", "slosh", "flex", "nonrigid")
MODE_BASES = ("held", "projected")


@dataclass(frozen=True)
class Timeline:
    """Tabulated flight of one vehicle. Rows ``t`` (n,) [s], non-decreasing, event times twice.

    ``params`` (n, n_p): dynamics parameters (:class:`~lvgym.dynamics.NonRigidModel` layout of
    ``model``); ``hold`` (n_p,) columns that are piecewise constant (mode data); ``thrust0`` (n,) [N]
    and ``exit_area`` (n,) [m^2]: thrust ``max(T_0 - A_e p_amb, 0)``; ``vectored_share`` (n,) the share of
    it the gimbal turns (:meth:`~lvgym.vehicle.MassModel.vectored_share`); ``mass`` (n,) [kg], ``cg`` (n, 3)
    [m], ``inertia`` (n, 3, 3) [kg m^2] of the whole stack; ``slosh_mass`` (n, N) [kg];
    ``burning`` (n,) any engine burning; ``stage`` (n,) index of the lowest attached stage;
    ``phi_sensor`` (n, S, K) mode shapes and ``dphi_sensor`` (n, S, K) slopes at the sensor stations
    ``sensor_stations`` (S,) [m]; ``strip_stations`` (n_stages, n) [m] the aeroelastic strips of each
    stage (n = 0: none) with ``phi_strip`` (n, K, n_strip) mode shapes and ``dphi_strip`` slopes at the
    strips of the row's lowest attached stage (linear between the beam's nodes);
    ``events`` ((time, description), ...); ``mode_change_t`` (C,) [s] the changes of the mode basis
    (``mode_basis="projected"``; none when ``held``) and ``mode_transfer`` (C, K, K) their matrices
    (``eta_new = T eta_old``); ``mode_interval`` [s] (None: at separations only) and ``mode_basis`` the
    options it was built with."""

    model: str
    dynamics: NonRigidModel
    t: np.ndarray
    params: np.ndarray
    hold: np.ndarray
    thrust0: np.ndarray
    exit_area: np.ndarray
    vectored_share: np.ndarray
    mass: np.ndarray
    cg: np.ndarray
    inertia: np.ndarray
    slosh_mass: np.ndarray
    burning: np.ndarray
    stage: np.ndarray
    stage_names: tuple[str, ...]
    slosh_names: tuple[str, ...]
    sensor_stations: np.ndarray
    phi_sensor: np.ndarray
    dphi_sensor: np.ndarray
    strip_stations: np.ndarray
    phi_strip: np.ndarray
    dphi_strip: np.ndarray
    events: tuple[tuple[float, str], ...]
    mode_change_t: np.ndarray
    mode_transfer: np.ndarray
    mode_interval: float | None = None
    mode_basis: str = "held"

    @property
    def t_end(self) -> float:
        return float(self.t[-1])

    @property
    def event_times(self) -> np.ndarray:
        return np.array(sorted({t for t, _ in self.events}))

    def locate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Row index ``i`` and weight ``w`` of the times ``t`` (B,): value = (1-w) row i + w row i+1.
        A time equal to an event time takes the row after the event (:func:`locate_k`)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        i, w = np.empty(t.size, dtype=np.int64), np.empty(t.size)
        locate_rows(self.t, t, i, w)
        return i, w

    def interp(self, name: str, t) -> np.ndarray:
        """Linear interpolation of the row quantity ``name`` at the times ``t`` (B,): shape (B, ...)
        (:func:`interp_k`)."""
        a = getattr(self, name)
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((t.size, int(np.prod(a.shape[1:], dtype=int))))
        interp_rows(self.t, np.ascontiguousarray(a, dtype=float).reshape(a.shape[0], -1), t, out)
        return out.reshape((t.size,) + a.shape[1:])

    def left(self, name: str, t) -> np.ndarray:
        """The row quantity ``name`` in force at the times ``t`` (no interpolation; the row after an
        event at an event time, :func:`held_k`)."""
        i, w = self.locate(t)
        return getattr(self, name)[np.where(w >= 1.0, i + 1, i)]

    def params_at(self, t, scale: np.ndarray | None = None, offset: np.ndarray | None = None) -> np.ndarray:
        """Dynamics parameters (B, n_p) at the times ``t`` (B,): interpolated, mode data held, then
        ``* scale + offset`` (B, n_p) when given (:func:`params_k`, as the simulator's step)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        n_p = self.params.shape[1]
        scale = np.ones((t.size, n_p)) if scale is None else np.ascontiguousarray(scale, dtype=float)
        offset = np.zeros((t.size, n_p)) if offset is None else np.ascontiguousarray(offset, dtype=float)
        out = np.empty((t.size, n_p))
        params_rows(self.t, self.params, self.hold, scale, offset, t, out)
        return out

    @functools.cached_property
    def tables(self) -> Tables:
        """The columns the compiled step and the task signals read (:class:`Tables`)."""
        return Tables(t=np.ascontiguousarray(self.t, dtype=float), params=np.ascontiguousarray(self.params),
                      hold=np.ascontiguousarray(self.hold), thrust0=np.ascontiguousarray(self.thrust0, dtype=float),
                      exit_area=np.ascontiguousarray(self.exit_area, dtype=float),
                      vectored_share=np.ascontiguousarray(self.vectored_share, dtype=float),
                      stage=np.ascontiguousarray(self.stage, dtype=float),
                      burning=np.ascontiguousarray(self.burning, dtype=float),
                      mass=np.ascontiguousarray(self.mass, dtype=float),
                      phi_sensor=np.ascontiguousarray(self.phi_sensor, dtype=float),
                      dphi_sensor=np.ascontiguousarray(self.dphi_sensor, dtype=float),
                      phi_strip=np.ascontiguousarray(self.phi_strip, dtype=float),
                      dphi_strip=np.ascontiguousarray(self.dphi_strip, dtype=float),
                      event_times=np.ascontiguousarray(self.event_times, dtype=float),
                      mode_change_t=np.ascontiguousarray(self.mode_change_t, dtype=float),
                      mode_transfer=np.ascontiguousarray(self.mode_transfer, dtype=float))


#: the timeline's columns as compiled code reads them: ``t`` (n,) [s] rows; ``params`` (n, n_p);
#: ``hold`` (n_p,) bool; ``thrust0`` (n,) [N]; ``exit_area`` (n,) [m^2]; ``vectored_share`` (n,) [-] the
#: share of the thrust the gimbal turns; ``stage`` (n,) lowest attached
#: stage; ``burning`` (n,) 1 while an engine burns; ``mass`` (n,) [kg]; ``phi_sensor`` (n, S, K)
#: [1/sqrt(kg)] and ``dphi_sensor`` (n, S, K) [1/(m sqrt(kg))] mode shapes and slopes at the sensor stations;
#: ``phi_strip``, ``dphi_strip`` (n, K, n_strip) at the aeroelastic strips;
#: ``event_times`` (E,) [s], each once; ``mode_change_t`` (C,) [s] and ``mode_transfer``
#: (C, K, K) the changes of the mode basis the step projects the modal state across (none: held)
Tables = namedtuple("Tables", ["t", "params", "hold", "thrust0", "exit_area", "vectored_share", "stage", "burning", "mass",
                               "phi_sensor", "dphi_sensor", "phi_strip", "dphi_strip", "event_times", "mode_change_t",
                               "mode_transfer"])


# ---------------------------------------------------------------------------- compiled look-ups (the only ones)
_FORWARD = 8              # rows locate_from_k walks forward before it bisects


@nb.njit(cache=True, nogil=True, inline="always")
def locate_k(tl_t, t):
    """Row ``i`` and weight ``w`` of time ``t`` in the timeline rows ``tl_t``: value = (1-w) row i + w
    row i+1; a time equal to an event time (stored twice) takes the row after the event."""
    n = tl_t.size
    i = np.searchsorted(tl_t, t, side="right") - 1
    return _weight_k(tl_t, min(max(i, 0), n - 2), t)


@nb.njit(cache=True, nogil=True, inline="always")
def _weight_k(tl_t, i, t):
    """``(i, w)`` of :func:`locate_k` for its row ``i``."""
    span = tl_t[i + 1] - tl_t[i]
    w = (t - tl_t[i]) / span if span > 0.0 else 0.0
    return i, min(max(w, 0.0), 1.0)


@nb.njit(cache=True, nogil=True, inline="always")
def locate_from_k(tl_t, t, hint):
    """:func:`locate_k` (the same row and weight) searched forward from the row ``hint`` (the row of an
    earlier, not later, time of the same flight: a step's pieces and sensors go forward a row or two at a
    time); a bisection when ``hint`` is not at or before ``t`` (e.g. -1) or ``t`` lies more than a few rows
    ahead."""
    n = tl_t.size
    i = hint
    if i < 0 or i > n - 2 or not tl_t[i] <= t:
        return locate_k(tl_t, t)
    for _ in range(_FORWARD):
        if i >= n - 2 or not tl_t[i + 1] <= t:         # the last row at or before t (at most n - 2)
            return _weight_k(tl_t, i, t)
        i += 1
    return locate_k(tl_t, t)


@nb.njit(cache=True, nogil=True, inline="always")
def params_k(tl_t, tl_p, hold, scale, offset, t, out):
    """Dynamics parameters at time ``t`` into ``out``: interpolated, held columns from the row in
    force, then ``* scale + offset``."""
    i, w = locate_k(tl_t, t)
    params_at_k(tl_p, hold, scale, offset, i, w, out)


@nb.njit(cache=True, nogil=True, inline="always")
def params_at_k(tl_p, hold, scale, offset, i, w, out):
    """:func:`params_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    j = i + 1 if w >= 1.0 else i
    for k in range(out.size):
        v = tl_p[j, k] if hold[k] else (1.0 - w) * tl_p[i, k] + w * tl_p[i + 1, k]
        out[k] = v * scale[k] + offset[k]


@nb.njit(cache=True, nogil=True, inline="always")
def interp_k(tl_t, values, t):
    """Linear interpolation of a timeline column ``values`` at time ``t``."""
    i, w = locate_k(tl_t, t)
    return interp_at_k(values, i, w)


@nb.njit(cache=True, nogil=True, inline="always")
def interp_at_k(values, i, w):
    """:func:`interp_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    return (1.0 - w) * values[i] + w * values[i + 1]


@nb.njit(cache=True, nogil=True, inline="always")
def held_k(tl_t, values, t):
    """The value of a piecewise-constant timeline column ``values`` in force at time ``t`` (the row
    after an event at an event time)."""
    i, w = locate_k(tl_t, t)
    return held_at_k(values, i, w)


@nb.njit(cache=True, nogil=True, inline="always")
def held_at_k(values, i, w):
    """:func:`held_k` at the row ``i`` and weight ``w`` of :func:`locate_k`."""
    return values[i + 1] if w >= 1.0 else values[i]


@nb.njit(cache=True, nogil=True, inline="always")
def row_in_force_k(i, w):
    """The row in force (the row after an event at an event time) at the row ``i`` and weight ``w`` of
    :func:`locate_k`."""
    return i + 1 if w >= 1.0 else i


@nb.njit(cache=True)
def locate_rows(tl_t, t, i_out, w_out):
    """:func:`locate_k` of every time ``t`` (B,)."""
    for b in range(t.size):
        i_out[b], w_out[b] = locate_k(tl_t, t[b])


@nb.njit(cache=True)
def interp_rows(tl_t, values, t, out):
    """:func:`interp_k` of every column of ``values`` (n, m) at every time ``t`` (B,) into ``out`` (B, m)."""
    for b in range(t.size):
        for k in range(values.shape[1]):
            out[b, k] = interp_k(tl_t, values[:, k], t[b])


@nb.njit(cache=True)
def params_rows(tl_t, tl_p, hold, scale, offset, t, out):
    """:func:`params_k` at every time ``t`` (B,) with the rows' ``scale``, ``offset`` (B, n_p)."""
    for b in range(t.size):
        params_k(tl_t, tl_p, hold, scale[b], offset[b], t[b], out[b])
