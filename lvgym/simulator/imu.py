"""The inertial measurement unit: gyro and accelerometer dynamics at the IMU station, advanced at every physics step.

A strapdown IMU at station ``x_imu`` on the body axis. Its sensors see the structure where it is:

- the **rate gyros** see the body rate of B plus the rate of the bending slope at the station
  (docs/physics-notes.md, note 6): ``u_x = omega_x``, ``u_y = omega_y - sum_k phi'_k(x_imu) eta_dot_z,k``,
  ``u_z = omega_z + sum_k phi'_k(x_imu) eta_dot_y,k``;
- the **accelerometers** see the specific force at the station: that of the CG of B
  (``C_bi (a_zw_i - g_i)``), the lever-arm terms ``omega_dot x r + omega x (omega x r)`` with ``r`` the
  station from the CG of B, and the modal acceleration ``sum_k phi_k(x_imu) eta_ddot_k`` of each plane
  (the y-plane modes along ``y_b``, the z-plane ones along ``z_b``). The Coriolis and centripetal terms
  of the deflection itself (``2 omega x phi eta_dot``; ``phi eta`` is millimetres) are left out.

Per physics step of ``h`` seconds the simulator (:func:`.advance.advance_range`) gives each sensor the
**mean of its input over the step**, held over the step: for the gyro the mean of the start and end
rates; for the accelerometer the velocity change over the step divided by ``h`` (the acceleration of
the CG of B on the rail too, whose reaction is part of the motion; the CG's travel within the structure,
a change of reference point, is taken out), the body-rate and modal-rate changes over ``h`` for
``omega_dot`` and ``eta_ddot``, the attitude as the mean of the start and end ones, gravity at the end.
This is what an integrating (delta-angle, delta-velocity) sensor delivers per step.

Each input then goes through continuous linear filters, the same for every axis:

- gyro: the sensor's bandwidth, ``w_g^2 / (s^2 + 2 z_g w_g s + w_g^2)`` (``w_g = 2 pi gyro_bandwidth_hz``,
  ``z_g = gyro_damping``), then the anti-aliasing low-pass before sampling, a second-order Butterworth
  ``w_a^2 / (s^2 + sqrt(2) w_a s + w_a^2)`` (``w_a = 2 pi antialias_hz``);
- accelerometer: the same anti-aliasing low-pass.

Both are discretised exactly for an input held over the step (zero-order hold, by
a matrix exponential once in Python: :meth:`Imu.params`), so the discrete filters are stable
and exact at any step, whatever ``w h``. Their parameters are the block :data:`.layouts.IMU` of the
simulator's step set-up; each row's filter states the field ``imu`` of its :class:`~.data.SimData`
(layout :data:`.layouts.IMU_STATE`), started at rest on the pad (:meth:`Imu.rest_state`). Noise, bias
and sampling belong to the flight computer that reads the filters' outputs (:mod:`lvgym.envs.flightcomputer`).

Dispersed station. A row's IMU may sit ``station_shift`` [m] from the nominal station (the ``imu_station``
dispersion; block :data:`.layouts.IMU_STATION` of the row's IMU state, written by :meth:`Imu.placement`).
The timeline then tabulates the mode shapes and slopes also at a few stations around the nominal one
(``probes``, read off the solved beam, not meshed); the row takes them linearly in station between the two
tabulated stations around its own (``(1 - weight) lo + weight hi``; weight 0 copies ``lo``'s exactly), and
its accelerometers' lever arm from its own station. A shift of zero reproduces the flight of an
undispersed IMU bit for bit.
"""

from __future__ import annotations

import functools
import math
from collections import namedtuple
from dataclasses import dataclass

import numba as nb
import numpy as np

from lvgym.borrow import unowned_matrix
from lvgym.dynamics.layout import PARAMS, STATE, X
from lvgym.packing import at
from lvgym.rotations import quat_to_dcm

from .layouts import ACCEL_ORDER, CTX, D, GYRO_ORDER, IM, IMU, IMU_STATE, IMU_STATION, IS

__all__ = ["IMU_OFF", "Imu", "ImuWork", "imu_begin_k", "imu_end_k", "imu_output_k", "imu_shift_k", "lti_step_k",
           "make_imu_work", "specific_force_k", "station_modes_k"]

XF, PF = STATE.fixed, PARAMS.fixed
#: no IMU: the filters are not advanced (the simulator of protocol v0)
IMU_OFF = IMU.zeros()
_GO, _AO = GYRO_ORDER, ACCEL_ORDER
_N_GA, _N_AA = IMU.field("gyro_a").size, IMU.field("accel_a").size
_N_G, _N_A = IMU_STATE.field("gyro").size, IMU_STATE.field("accel").size
# the filters' matrices and the axes' states, row-major over their fields (unowned_matrix)
assert _N_GA == _GO * _GO and _N_AA == _AO * _AO and _N_G == 3 * _GO and _N_A == 2 * _AO


def _second_order(wn: float, zeta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``wn^2 / (s^2 + 2 zeta wn s + wn^2)`` with the states (output, its rate)."""
    return (np.array([[0.0, 1.0], [-wn * wn, -2.0 * zeta * wn]]), np.array([[0.0], [wn * wn]]),
            np.array([[1.0, 0.0]]))


def _cascade(first: tuple, second: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """State space of ``second(first(u))`` (neither has a direct feed-through)."""
    a1, b1, c1 = first
    a2, b2, c2 = second
    n1, n2 = a1.shape[0], a2.shape[0]
    a = np.zeros((n1 + n2, n1 + n2))
    a[:n1, :n1], a[n1:, :n1], a[n1:, n1:] = a1, b2 @ c1, a2
    return a, np.vstack([b1, np.zeros((n2, 1))]), np.hstack([np.zeros((1, n1)), c2])


@functools.lru_cache(maxsize=32)
def _discrete(gyro_bandwidth_hz: float, gyro_damping: float, antialias_hz: float, h: float
              ) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """:meth:`Imu.discrete` of the filters with these constants [Hz, -, Hz] for steps of ``h`` [s],
    computed once per process and constants (read-only arrays; the station does not enter)."""
    from scipy.linalg import expm
    out = {}
    for name, (a, b, c) in Imu(0.0, 0, gyro_bandwidth_hz, gyro_damping, antialias_hz).continuous().items():
        n = a.shape[0]
        em = np.zeros((n + 1, n + 1))
        em[:n, :n], em[:n, n:] = a, b
        ms = expm(float(h) * em)[:n, :]
        out[name] = (ms[:, :n], ms[:, n], np.asarray(c, dtype=float)[0])
        for arr in out[name]:
            arr.flags.writeable = False
    return out


@dataclass(frozen=True)
class Imu:
    """An IMU at station ``station_m`` [m] (``sensor``: its index among the timeline's sensor stations,
    where the mode shapes and slopes are tabulated; ``probes``: the indices of further sensor stations
    around it between which a dispersed station interpolates, see :meth:`placement`) with the gyro's
    bandwidth ``gyro_bandwidth_hz`` [Hz] and damping ``gyro_damping`` [-] and an anti-aliasing
    Butterworth low-pass at ``antialias_hz`` [Hz] before sampling (see the module docstring)."""

    station_m: float
    sensor: int = 0
    gyro_bandwidth_hz: float = 80.0
    gyro_damping: float = 0.7
    antialias_hz: float = 20.0
    probes: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        for key in ("gyro_bandwidth_hz", "gyro_damping", "antialias_hz"):
            v = getattr(self, key)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"imu.{key} = {v!r}: a finite number > 0")
        if not (isinstance(self.sensor, int) and self.sensor >= 0):
            raise ValueError(f"imu.sensor = {self.sensor!r}: an index >= 0")
        if not all(isinstance(i, int) and i >= 0 and i != self.sensor for i in self.probes):
            raise ValueError(f"imu.probes = {self.probes!r}: sensor indices >= 0 other than sensor")

    def placement(self, shift: np.ndarray, sensor_stations: np.ndarray) -> np.ndarray:
        """The rows' station blocks (R, IMU_STATION.size) for station shifts ``shift`` (R,) [m] along +x_b:
        the two tabulated stations (``sensor`` and ``probes`` of ``sensor_stations`` [m]) around each
        row's station and the linear weight of the forward one. A shift of 0 gives ``lo = hi = sensor``
        and weight 0; a station on a tabulated one, that one with weight 0. A station outside the
        tabulated ones by more than round-off (1e-9 m; a draw clipped at the range's end) raises
        ``ValueError``."""
        shift = np.atleast_1d(np.asarray(shift, dtype=float))
        idx = np.array([self.sensor, *self.probes], dtype=int)
        xs = np.asarray(sensor_stations, dtype=float)[idx]
        order = np.argsort(xs, kind="stable")
        idx, xs = idx[order], xs[order]
        out = IMU_STATION.zeros(shift.size)
        v = lambda name: IMU_STATION.view(out, name)[:, 0]          # noqa: E731
        v("station_shift")[:] = shift
        v("station_lo")[:] = v("station_hi")[:] = self.sensor
        for r, d in enumerate(shift):
            if d == 0.0:
                continue
            x = self.station_m + d
            if not xs[0] - 1e-9 <= x <= xs[-1] + 1e-9:
                raise ValueError(f"IMU station shift {d!r} m: the station {x!r} m lies outside the tabulated "
                                 f"[{xs[0]!r}, {xs[-1]!r}] m")
            x = min(max(x, xs[0]), xs[-1])
            i = int(np.searchsorted(xs, x, side="right")) - 1
            if xs[i] == x or i == xs.size - 1:
                v("station_lo")[r] = v("station_hi")[r] = idx[i]
                continue
            v("station_lo")[r], v("station_hi")[r] = idx[i], idx[i + 1]
            v("station_weight")[r] = (x - xs[i]) / (xs[i + 1] - xs[i])
        return out

    def continuous(self) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """The continuous filters ``(A, B, C)`` of the gyro (sensor bandwidth, then anti-aliasing) and
        the accelerometer (anti-aliasing)."""
        antialias = _second_order(2.0 * math.pi * self.antialias_hz, 1.0 / math.sqrt(2.0))
        sensor = _second_order(2.0 * math.pi * self.gyro_bandwidth_hz, self.gyro_damping)
        return {"gyro": _cascade(sensor, antialias), "accel": antialias}

    def discrete(self, h: float) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """The filters discretised exactly for an input held over steps of ``h`` [s] (zero-order hold):
        ``expm(h [[A, B], [0, 0]]) = [[Ad, Bd], [0, 1]]``, the matrix exponential ``scipy.signal.cont2discrete``
        takes for ``method="zoh"`` (the same numbers; ``scipy.signal`` itself is not imported, which costs
        1-2.5 s on the first v1 env of a process)."""
        held = _discrete(self.gyro_bandwidth_hz, self.gyro_damping, self.antialias_hz, float(h))
        return {name: tuple(a.copy() for a in abc) for name, abc in held.items()}

    def params(self, h: float) -> np.ndarray:
        """The parameter block (layout :data:`.layouts.IMU`) for physics steps of ``h`` [s]."""
        d = self.discrete(h)
        return IMU.pack({"on": 1.0, "station": self.station_m, "sensor": float(self.sensor), "h": float(h),
                         "gyro_a": d["gyro"][0].ravel(), "gyro_b": d["gyro"][1], "gyro_c": d["gyro"][2],
                         "accel_a": d["accel"][0].ravel(), "accel_b": d["accel"][1], "accel_c": d["accel"][2]})

    @staticmethod
    def rest_state(rate_b: np.ndarray, force_yz_b: np.ndarray) -> np.ndarray:
        """Filter states (R, IMU_STATE.size) at rest with the constant inputs ``rate_b`` (R, 3) [rad/s]
        and ``force_yz_b`` (R, 2) [m/s^2]: every second-order stage's output at its input (unit DC
        gain), its rate zero."""
        rate_b, force_yz_b = np.atleast_2d(rate_b), np.atleast_2d(force_yz_b)
        out = IMU_STATE.zeros(rate_b.shape[0])
        g, a = IMU_STATE.view(out, "gyro"), IMU_STATE.view(out, "accel")
        g[..., 0::2] = rate_b[..., None]                   # the states are (output, rate) per stage
        a[..., 0::2] = force_yz_b[..., None]
        return out


#: scratch of one row's IMU step: ``omega0`` (3) [rad/s], ``v0`` (3) [m/s] (less the CG's travel),
#: ``C0`` (3, 3) ``C_ib`` at the start of the step, ``C1`` at its end, ``eta_dot0`` (2K) modal rates at
#: the start, ``omega1`` (3), ``a_i`` (3) [m/s^2] the CG's mean acceleration, ``g_i`` (3) gravity, ``r`` (3) [m]
#: the IMU from the CG of B, ``u`` (3) the gyro inputs, ``f`` (3) [m/s^2] the specific force, ``tmp`` (4) scratch,
#: ``phi`` (K) and ``dphi`` (K) the mode shapes and slopes at the row's station
ImuWork = namedtuple("ImuWork", ["omega0", "omega1", "v0", "a_i", "g_i", "r", "C0", "C1", "eta_dot0", "u", "f",
                                 "tmp", "phi", "dphi"])


@nb.njit(cache=True, nogil=True)
def make_imu_work(n_modes):
    """The scratch of :func:`imu_begin_k` / :func:`imu_end_k` for ``n_modes`` modes per plane."""
    return ImuWork(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros((3, 3)),
                   np.zeros((3, 3)), np.zeros(2 * n_modes), np.zeros(3), np.zeros(3), np.zeros(_GO), np.zeros(n_modes),
                   np.zeros(n_modes))


@nb.njit(cache=True, nogil=True, inline="always")
def lti_step_k(a, b, x, u, tmp):
    """One step of a discrete filter: ``x <- a x + b u`` (``a`` (n, n), ``b`` (n,), ``x`` (n,) in
    place; ``tmp`` at least n entries of scratch)."""
    n = x.size
    for i in range(n):
        s = b[i] * u
        for j in range(n):
            s += a[i, j] * x[j]
        tmp[i] = s
    for i in range(n):
        x[i] = tmp[i]


@nb.njit(cache=True, nogil=True)
def specific_force_k(a_i, g_i, C0, C1, om0, om1, h, r, out):
    """Mean specific force [m/s^2] over a step of ``h`` [s] at the point ``r`` (3,) [m] of the rigid
    body (from its CG, body frame) into ``out`` (3,), body frame:
    ``1/2 (C0 + C1)^T (a_i - g_i) + omega_dot x r + omega x (omega x r)``, with ``a_i`` (3,) the CG's
    mean inertial acceleration, ``g_i`` (3,) gravity, ``C0``/``C1`` ``C_ib`` at the start and end,
    ``omega_dot = (om1 - om0) / h`` and ``omega = (om0 + om1) / 2`` from the body rates [rad/s] at the
    start and end."""
    f0, f1, f2 = a_i[0] - g_i[0], a_i[1] - g_i[1], a_i[2] - g_i[2]
    wd0, wd1, wd2 = (om1[0] - om0[0]) / h, (om1[1] - om0[1]) / h, (om1[2] - om0[2]) / h
    w0, w1, w2 = 0.5 * (om0[0] + om1[0]), 0.5 * (om0[1] + om1[1]), 0.5 * (om0[2] + om1[2])
    r0, r1, r2 = r[0], r[1], r[2]
    c0, c1, c2 = w1 * r2 - w2 * r1, w2 * r0 - w0 * r2, w0 * r1 - w1 * r0          # omega x r
    for i in range(3):
        out[i] = 0.5 * ((C0[0, i] + C1[0, i]) * f0 + (C0[1, i] + C1[1, i]) * f1 + (C0[2, i] + C1[2, i]) * f2)
    out[0] += wd1 * r2 - wd2 * r1 + w1 * c2 - w2 * c1
    out[1] += wd2 * r0 - wd0 * r2 + w2 * c0 - w0 * c2
    out[2] += wd0 * r1 - wd1 * r0 + w0 * c1 - w1 * c0


@nb.njit(cache=True, nogil=True, inline="always")
def imu_begin_k(x, n_slosh, n_modes, w):
    """Keep the start of a physics step of the state ``x`` in the scratch ``w`` (:data:`ImuWork`)."""
    ow, ov, oq = XF.omega_bi_b, XF.v_zw_i, XF.q_bi
    for i in range(3):
        w.omega0[i] = x[ow + i]
        w.v0[i] = x[ov + i]
    quat_to_dcm(x[oq], x[oq + 1], x[oq + 2], x[oq + 3], w.C0)
    o_etad = at(X.eta_dot, n_modes, n_slosh)
    for k in range(w.eta_dot0.size):
        w.eta_dot0[k] = x[o_etad + k]


@nb.njit(cache=True, nogil=True, inline="always")
def imu_shift_k(x, w, sign):
    """Account for a change of the velocity's reference point (the CG's travel, :func:`.advance.shift_cg_k`):
    called with ``sign = -1`` before it and ``+1`` after it, so that it adds to the start velocity."""
    ov = XF.v_zw_i
    for i in range(3):
        w.v0[i] += sign * x[ov + i]


@nb.njit(cache=True, nogil=True, inline="always")
def station_modes_k(st, tables, j, phi, dphi):
    """Mode shapes ``phi`` and slopes ``dphi`` (K,) at a row's IMU station (its block IMU_STATION in the
    row's IMU state ``st``) in the timeline's row ``j``: linear between the tabulated stations ``lo`` and
    ``hi``; a weight of 0 copies ``lo``'s (exactly)."""
    lo, hi, wt = int(st[IS.station_lo]), int(st[IS.station_hi]), st[IS.station_weight]
    p0, d0 = tables.phi_sensor[j, lo], tables.dphi_sensor[j, lo]
    if wt == 0.0:
        for k in range(phi.size):
            phi[k], dphi[k] = p0[k], d0[k]
        return
    p1, d1 = tables.phi_sensor[j, hi], tables.dphi_sensor[j, hi]
    for k in range(phi.size):
        phi[k] = (1.0 - wt) * p0[k] + wt * p1[k]
        dphi[k] = (1.0 - wt) * d0[k] + wt * d1[k]


@nb.njit(cache=True, nogil=True)
def imu_end_k(prm, st, x, p, ctx, tables, j, h, w, n_slosh, n_modes):
    """Advance a row's IMU filters ``st`` (layout IMU_STATE) over the physics step of ``h`` [s] that
    ended with the state ``x`` and parameters ``p`` (its start kept in ``w`` by :func:`imu_begin_k`);
    ``prm`` the IMU block (layout IMU), ``ctx`` the row's context (gravity of the latest RK4 stage),
    ``tables`` the timeline's (mode shapes and slopes at the sensor stations, taken at the row's station
    by :func:`station_modes_k` in the timeline's row ``j``, the one in force at the step's end:
    :func:`~.timeline.row_in_force_k`)."""
    ow, ov, oq, oc = XF.omega_bi_b, XF.v_zw_i, XF.q_bi, PF.r_cg
    K = n_modes
    phi, dphi = w.phi, w.dphi
    station_modes_k(st, tables, j, phi, dphi)
    o_etad = at(X.eta_dot, n_modes, n_slosh)
    u = w.u
    for a in range(3):                               # gyro: mean body rate + mean slope rate at the IMU
        u[a] = 0.5 * (w.omega0[a] + x[ow + a])
    for k in range(K):
        u[1] -= dphi[k] * 0.5 * (w.eta_dot0[K + k] + x[o_etad + K + k])
        u[2] += dphi[k] * 0.5 * (w.eta_dot0[k] + x[o_etad + k])
    ga = unowned_matrix(prm, IM.gyro_a, _GO, _GO)
    gb = prm[IM.gyro_b:IM.gyro_b + _GO]
    gs = unowned_matrix(st, IS.gyro, 3, _GO)
    for a in range(3):
        lti_step_k(ga, gb, gs[a], u[a], w.tmp)
    # accelerometers: the CG's mean acceleration and the lever arm, then the modal acceleration
    quat_to_dcm(x[oq], x[oq + 1], x[oq + 2], x[oq + 3], w.C1)
    og = CTX.scratch + D.g_i
    for a in range(3):
        w.a_i[a] = (x[ov + a] - w.v0[a]) / h
        w.g_i[a] = ctx[og + a]
        w.omega1[a] = x[ow + a]
    w.r[0] = (prm[IM.station] + st[IS.station_shift]) - p[oc]
    w.r[1], w.r[2] = -p[oc + 1], -p[oc + 2]
    specific_force_k(w.a_i, w.g_i, w.C0, w.C1, w.omega0, w.omega1, h, w.r, w.f)
    for k in range(K):
        w.f[1] += phi[k] * (x[o_etad + k] - w.eta_dot0[k]) / h
        w.f[2] += phi[k] * (x[o_etad + K + k] - w.eta_dot0[K + k]) / h
    aa = unowned_matrix(prm, IM.accel_a, _AO, _AO)
    ab = prm[IM.accel_b:IM.accel_b + _AO]
    acs = unowned_matrix(st, IS.accel, 2, _AO)
    for a in range(2):
        lti_step_k(aa, ab, acs[a], w.f[a + 1], w.tmp)


@nb.njit(cache=True, nogil=True, inline="always")
def imu_output_k(prm, st, rate_b, force_yz_b):
    """The filters' outputs: the sampled rates ``rate_b`` (3,) [rad/s] (body x, y, z) and lateral
    specific forces ``force_yz_b`` (2,) [m/s^2] (body y, z) of the row's IMU states ``st``."""
    gc, ac = prm[IM.gyro_c:IM.gyro_c + _GO], prm[IM.accel_c:IM.accel_c + _AO]
    gs = unowned_matrix(st, IS.gyro, 3, _GO)
    acs = unowned_matrix(st, IS.accel, 2, _AO)
    for a in range(3):
        s = 0.0
        for k in range(_GO):
            s += gc[k] * gs[a, k]
        rate_b[a] = s
    for a in range(2):
        s = 0.0
        for k in range(_AO):
            s += ac[k] * acs[a, k]
        force_yz_b[a] = s
