"""Aeroelastic strip theory: normal force over stations with the local angle of attack of the bent,
rotating, vibrating body, and the generalised forces it puts on the bending modes (thesis eq.
2.14-2.19, recommended there and never built). Off by default: a simulator adds these loads only
when a vehicle asks for them.

The body is cut into strips at stations ``x_j`` (x_b from the nose tip, <= 0). Strip j carries the
share ``c_j`` [1/rad] of the normal-force slope (CN-alpha per metre times the strip width, referred to
the reference area ``S``; the strips sum to the vehicle's CN-alpha, e.g. from
:meth:`~lvgym.environment.barrowman.BarrowmanAero.strips`). With ``v_air_b = (u, v, w)``, the body
rate ``omega_bi_b`` and K mass-normalised modes per plane (shapes ``phi_k(x_j)``, slopes
``phi_k'(x_j)``; ``eta`` and ``eta_dot`` ordered y plane then z plane, as ``lvgym/dynamics/layout.py``),
the crossflow velocity normal to the local, deflected axis at strip j is, to first order,

    v_j = v + omega_z (x_j - x_cg) + sum_k phi_k(x_j) eta_dot_y,k - u sum_k phi_k'(x_j) eta_y,k
    w_j = w - omega_y (x_j - x_cg) + sum_k phi_k(x_j) eta_dot_z,k - u sum_k phi_k'(x_j) eta_z,k

(rigid crossflow + body rotation + deflection rate - axial flow over the local slope; thesis
alpha + alpha_1 + alpha_2 of eq. 2.16 with this package's signs: a slope towards +z turns the local
axis into a wind from +z and lowers the local alpha). The local angles are ``v_j / V`` and
``w_j / V``, and the strip force (eq. 2.18) is ``dF_j = -qbar S c_j (0, v_j, w_j) / V
= -rho V S c_j (0, v_j, w_j) / 2``: linear in the angles (small-angle strip theory) and zero at zero
airspeed. The loads are the sums ``f_b = sum dF_j``, ``m_b = sum (x_j - x_cg) e_x x dF_j`` about the
CG, and the generalised forces by virtual work, ``f_eta_y,k = sum_j phi_k(x_j) dF_y,j`` and
``f_eta_z,k = sum_j phi_k(x_j) dF_z,j`` [sqrt(kg) m/s^2], the core's ``f_eta`` load.

With ``include_rigid=False`` the body force and moment hold only the elastic part (slope and
deflection-rate terms), to be added to a table model's rigid loads; ``f_eta`` always holds the
whole distribution, since the rigid angle of attack bends the vehicle too.

Compiled callers use :func:`strip_loads_k` with ``model.kernel_args()`` (a :data:`StripTable`), the modes
at the strips and the modal state (a :data:`StripModes`) and the output arrays (a :data:`StripLoads`).
"""

from __future__ import annotations

import math
from collections import namedtuple
from typing import Any

import numba as nb
import numpy as np

from lvgym.errors import ConfigError

#: a strip model's arrays (``kernel_args()``): ``x_strip`` (n) stations [m]; ``mach_grid`` (n_m) and
#: ``cna_table`` (n_m, n) the strips' CN-alpha shares [1/rad] against Mach (linear, clamped); ``s_ref``
#: [m^2]; ``include_rigid``: whether ``f_b``, ``m_b`` include the rigid-body crossflow terms
StripTable = namedtuple("StripTable", ["x_strip", "mach_grid", "cna_table", "s_ref", "include_rigid"])
#: the bending of one vehicle at the strips: ``phi``, ``dphi`` (K, n) mode shapes [1/sqrt(kg)] and slopes
#: [1/(m sqrt(kg))] at the strips; ``eta``, ``eta_dot`` (2K) the modal coordinates and rates (y plane, then z)
StripModes = namedtuple("StripModes", ["phi", "dphi", "eta", "eta_dot"])
#: what :func:`strip_loads_k` writes: ``f_b`` (3) [N], ``m_b`` (3) [N m], ``f_eta`` (2K), ``df_strip`` (n, 2) [N]
StripLoads = namedtuple("StripLoads", ["f_b", "m_b", "f_eta", "df_strip"])


@nb.njit(cache=True)
def strip_loads_k(v_air_b, omega_bi_b, rho, sound, x_cg, strips, modes, loads):
    """Strip-theory normal force ``loads.f_b`` [N], moment about the CG ``loads.m_b`` [N m] (body frame,
    written into 3-vectors) and generalised modal forces ``loads.f_eta`` (2K) of one vehicle;
    ``loads.df_strip`` (n, 2) receives each strip's force (y, z) [N] (a :data:`StripLoads`).

    ``v_air_b`` (3) [m/s], ``omega_bi_b`` (3) [rad/s], ``rho`` [kg/m^3], ``sound`` [m/s], ``x_cg`` CG
    station [m]; ``strips`` the model's :data:`StripTable`; ``modes`` the :data:`StripModes` (shapes and
    slopes at the strips, modal coordinates and rates).
    """
    x_strip, mach_grid, cna_table, s_ref, include_rigid = strips
    phi, dphi, eta, eta_dot = modes
    f_b, m_b, f_eta, df_strip = loads
    n_k = phi.shape[0]
    u, v, w = v_air_b[0], v_air_b[1], v_air_b[2]
    speed = math.sqrt(u * u + v * v + w * w)
    mach = speed / sound if sound > 0.0 else 0.0
    n_m = mach_grid.shape[0]
    i0, t = 0, 0.0
    if n_m > 1:
        if mach >= mach_grid[n_m - 1]:
            i0, t = n_m - 2, 1.0
        elif mach > mach_grid[0]:
            i0 = np.searchsorted(mach_grid, mach, side="right") - 1
            t = (mach - mach_grid[i0]) / (mach_grid[i0 + 1] - mach_grid[i0])
    i1 = i0 + 1 if n_m > 1 else 0
    half = 0.5 * rho * speed * s_ref
    for i in range(3):
        f_b[i] = 0.0
        m_b[i] = 0.0
    for k in range(2 * n_k):
        f_eta[k] = 0.0
    for j in range(x_strip.shape[0]):
        c = (1.0 - t) * cna_table[i0, j] + t * cna_table[i1, j]
        d = x_strip[j] - x_cg
        ey = 0.0
        ez = 0.0
        for k in range(n_k):
            ey += phi[k, j] * eta_dot[k] - u * dphi[k, j] * eta[k]
            ez += phi[k, j] * eta_dot[n_k + k] - u * dphi[k, j] * eta[n_k + k]
        ry = v + omega_bi_b[2] * d
        rz = w - omega_bi_b[1] * d
        fy = -half * c * (ry + ey)
        fz = -half * c * (rz + ez)
        df_strip[j, 0] = fy
        df_strip[j, 1] = fz
        for k in range(n_k):
            f_eta[k] += phi[k, j] * fy
            f_eta[n_k + k] += phi[k, j] * fz
        if not include_rigid:
            fy = -half * c * ey
            fz = -half * c * ez
        f_b[1] += fy
        f_b[2] += fz
        m_b[1] -= d * fz
        m_b[2] += d * fy


@nb.njit(cache=True)
def strip_loads_batch(v_air_b, omega_bi_b, rho, sound, x_cg, strips, modes, loads):
    """:func:`strip_loads_k` over a leading batch axis (``strips`` shared; every array of ``modes`` and
    ``loads`` per vehicle: ``phi``, ``dphi`` (B, K, n))."""
    for b in range(v_air_b.shape[0]):
        strip_loads_k(v_air_b[b], omega_bi_b[b], rho[b], sound[b], x_cg[b], strips,
                      StripModes(modes.phi[b], modes.dphi[b], modes.eta[b], modes.eta_dot[b]),
                      StripLoads(loads.f_b[b], loads.m_b[b], loads.f_eta[b], loads.df_strip[b]))


def resample_modes(x_strip: Any, x_nodes: Any, phi_nodes: Any, dphi_nodes: Any
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Mode shapes and slopes (K, n) at the strip stations, linearly interpolated from the beam
    nodes ``x_nodes`` (n_nodes) [m] and ``phi_nodes``, ``dphi_nodes`` (K, n_nodes)."""
    x_nodes = np.asarray(x_nodes, float)
    order = np.argsort(x_nodes)
    xs = np.asarray(x_strip, float)
    pick = [np.atleast_2d(np.asarray(a, float))[:, order] for a in (phi_nodes, dphi_nodes)]
    return tuple(np.array([np.interp(xs, x_nodes[order], row) for row in a]) for a in pick)


class StripAeroelastic:
    """Aeroelastic strip-theory loads of one vehicle geometry (see the module docstring).

    Parameters
    ----------
    x_strip:
        Stations of the strip centres [m] (<= 0), shape (n,).
    width:
        Strip widths [m], (n,).
    cna_per_m:
        Local normal-force slope per unit length [1/(rad m)] referred to ``ref_area``, (n,) or
        (n_mach, n) with ``mach`` given.
    ref_area:
        Reference area of the slopes [m^2].
    phi, dphi:
        Mode shapes [1/sqrt(kg)] and slopes [1/(m sqrt(kg))] at the strips, (K, n); None: no modes.
    mach:
        Mach grid (n_mach,) of a 2-D ``cna_per_m``.
    include_rigid:
        Whether the body force and moment include the rigid-body terms (True) or only the elastic
        increment (False); ``f_eta`` always uses the whole distribution.

    Compiled callers: :func:`strip_loads_k` with :meth:`kernel_args` (a :data:`StripTable`) and the
    modes at the strips (:attr:`phi`, :attr:`dphi`, or the vehicle's of the moment).
    """

    def __init__(self, x_strip: Any, width: Any, cna_per_m: Any, ref_area: float, phi: Any = None,
                 dphi: Any = None, mach: Any = None, include_rigid: bool = True) -> None:
        x = np.asarray(x_strip, dtype=np.float64)
        if x.ndim != 1 or not np.all(np.isfinite(x)) or np.any(x > 0.0):
            raise ConfigError("x_strip", x_strip, "a vector of finite stations [m] <= 0")
        wid = np.broadcast_to(np.asarray(width, dtype=np.float64), x.shape)
        if not np.all(wid > 0.0):
            raise ConfigError("width", width, f"strip widths [m] > 0, one per station ({len(x)})")
        c = np.atleast_2d(np.asarray(cna_per_m, dtype=np.float64))
        grid = np.zeros(1) if mach is None else np.asarray(mach, dtype=np.float64).ravel()
        if c.shape != (len(grid), len(x)) or not np.all(np.isfinite(c)):
            raise ConfigError("cna_per_m", np.shape(cna_per_m),
                              f"finite values of shape ({len(x)},) or (len(mach), {len(x)})")
        if np.any(np.diff(grid) <= 0.0) or grid[0] < 0.0:
            raise ConfigError("mach", mach, "increasing Mach numbers >= 0")
        if not (math.isfinite(ref_area) and ref_area > 0.0):
            raise ConfigError("ref_area", ref_area, "a reference area [m^2] > 0")
        self.x_strip, self.width, self.mach_grid = x, np.array(wid), grid
        self.cna_table = np.ascontiguousarray(c * wid)
        self.ref_area = float(ref_area)
        self.include_rigid = bool(include_rigid)
        self.phi, self.dphi = self._modes(phi, dphi)
        self.n_modes = self.phi.shape[0]

    def _modes(self, phi: Any, dphi: Any) -> tuple[np.ndarray, np.ndarray]:
        n = len(self.x_strip)
        if phi is None and dphi is None:
            return np.zeros((0, n)), np.zeros((0, n))
        arrays = []
        for key, a in (("phi", phi), ("dphi", dphi)):
            a = np.atleast_2d(np.asarray(a, dtype=np.float64))
            if a.shape[-1] != n or not np.all(np.isfinite(a)):
                raise ConfigError(key, np.shape(a), f"finite values of shape (K, {n})")
            arrays.append(np.ascontiguousarray(a))
        if arrays[0].shape != arrays[1].shape:
            raise ConfigError("dphi", arrays[1].shape, f"the shape of phi, {arrays[0].shape}")
        return arrays[0], arrays[1]

    def kernel_args(self) -> StripTable:
        """The :data:`StripTable` ``(x_strip, mach_grid, cna_table, s_ref, include_rigid)`` for the kernel."""
        return StripTable(self.x_strip, self.mach_grid, self.cna_table, self.ref_area, self.include_rigid)

    def cn_alpha(self, mach: float = 0.0) -> float:
        """Sum of the strips' normal-force slopes [1/rad] at Mach ``mach``."""
        return float(np.sum([np.interp(mach, self.mach_grid, col) for col in self.cna_table.T]))

    def loads(self, v_air_b: Any, omega_bi_b: Any, rho: Any, speed_of_sound: Any, x_cg: Any,
              eta: Any = None, eta_dot: Any = None, phi: Any = None, dphi: Any = None,
              strips: bool = False) -> tuple[np.ndarray, ...]:
        """``(f_b [N], m_b [N m], f_eta)``, and the strip forces (…, n, 2) [N] if ``strips``.

        ``v_air_b`` [m/s], ``omega_bi_b`` [rad/s]: (3,) or (B, 3); ``rho`` [kg/m^3],
        ``speed_of_sound`` [m/s], ``x_cg`` [m]: scalars or (B,); ``eta``, ``eta_dot``: (2K,) or
        (B, 2K) (default zero); ``phi``, ``dphi``: (K, n) or (B, K, n) to replace the stored shapes
        (modes change as the vehicle's mass does).
        """
        v = np.asarray(v_air_b, dtype=np.float64)
        b = 1 if v.ndim == 1 else v.shape[0]
        ph = self.phi if phi is None else np.asarray(phi, dtype=np.float64)
        dph = self.dphi if dphi is None else np.asarray(dphi, dtype=np.float64)
        k, n = ph.shape[-2], len(self.x_strip)

        def rows(a: Any, shape: tuple[int, ...]) -> np.ndarray:
            a = np.zeros(shape[1:]) if a is None else np.asarray(a, dtype=np.float64)
            try:
                return np.ascontiguousarray(np.broadcast_to(a, shape))
            except ValueError:
                raise ConfigError("loads argument", a.shape, f"broadcastable to {shape}") from None

        f, m, fe, df = np.zeros((b, 3)), np.zeros((b, 3)), np.zeros((b, 2 * k)), np.zeros((b, n, 2))
        modes = StripModes(rows(ph, (b, k, n)), rows(dph, (b, k, n)), rows(eta, (b, 2 * k)), rows(eta_dot, (b, 2 * k)))
        strip_loads_batch(rows(v, (b, 3)), rows(omega_bi_b, (b, 3)), rows(rho, (b,)),
                          rows(speed_of_sound, (b,)), rows(x_cg, (b,)), self.kernel_args(), modes,
                          StripLoads(f, m, fe, df))
        out = (f, m, fe, df) if strips else (f, m, fe)
        return tuple(a[0] for a in out) if v.ndim == 1 else out
