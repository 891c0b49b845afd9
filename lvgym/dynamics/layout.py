"""Flat array layouts of the non-rigid vehicle: state, parameters and loads.

The compiled kernels work on three flat ``float64`` vectors per vehicle (or arrays of shape
``(batch, n)``): the state ``x``, the parameters ``p`` (mass properties, slosh and mode data, which
the caller may change before every step) and the loads ``u`` (forces held over a step). This module
says where each named quantity lives, so that Python code never indexes by hand. A layout is fixed
by the number of slosh pendulums ``n_slosh`` (N) and of bending modes per plane ``n_modes`` (K).

Conventions (see DESIGN.md): SI units, radians; quaternions are Hamilton, scalar first;
``q_bi`` is the attitude of the body frame b relative to the inertial frame i, with
``C_ib = R(q_bi)`` (``v_i = C_ib @ v_b``). Stations are body-frame coordinates measured from the
nose tip, ``+x_b`` forward, so stations along the vehicle are zero or negative.

State ``x`` (length ``13 + 4K + 6N``):

==================  =====  ==============================================================
name                size   meaning
==================  =====  ==============================================================
``r_zw_i``          3      position of the rigid-body CG z from the inertial origin w [m]
``v_zw_i``          3      its inertial velocity [m/s]
``q_bi``            4      body attitude quaternion (scalar first)
``omega_bi_b``      3      body angular velocity, body frame [rad/s]
``eta``             2K     modal coordinates, first the K modes of the y plane, then z [sqrt(kg) m]
``eta_dot``         2K     their rates
``q_si``            4N     attitude of each pendulum frame s_j (rod along ``+x_s``; the mass
                           hangs at ``-L x_s`` from the hinge)
``omega_si_s``      2N     pendulum angular velocity, y_s and z_s components; the component
                           along the rod is zero by construction (a point mass has no spin)
==================  =====  ==============================================================

Parameters ``p`` (length ``16 + 4K + N (8 + K)``):

==================  =====  ==============================================================
``m_b``             1      mass of the rigid body B (everything except the slosh masses) [kg]
``r_cg``            3      station of the CG of B [m]
``J_b``             9      inertia of B about its CG, body axes, row major [kg m^2]
``r_gimbal``        3      station of the engine gimbal (thrust application node) [m]
``omega_modes``     K      bending natural frequencies Omega [rad/s]
``zeta_modes``      K      bending damping ratios Z [-]
``phi_gimbal``      K      mass-normalised mode shape at the gimbal node [1/sqrt(kg)]
``dphi_gimbal``     K      mode slope d(phi)/dx at the gimbal node [1/(m sqrt(kg))]
per slosh j:
``m``               1      slosh mass (0: the pendulum is inactive and its state frozen) [kg]
``length``          1      pendulum length L, hinge to mass [m]
``inertia``         1      transverse inertia of the slosh body about the mass (0: point mass)
                           [kg m^2]
``r_hinge``         3      station of the undeflected hinge [m]
``zeta``            1      slosh damping ratio [-]
``omega``           1      slosh natural frequency used by the damper, sqrt(a / L) [rad/s]
``phi``             K      mode shape at the hinge node [1/sqrt(kg)]
==================  =====  ==============================================================

Loads ``u`` (length ``12 + 2K``), held constant over one integration stage:

==================  =====  ==============================================================
``f_b_i``           3      external force on B at its CG other than gravity and thrust
                           (aerodynamics, support), inertial frame [N]
``m_b_b``           3      external moment on B about its CG, body frame [N m]
``thrust_e``        3      thrust force in the undeformed engine frame (body axes); the core
                           tilts it by the mode slope at the gimbal and applies it at the
                           deflected gimbal node (thesis eq. 2.20-2.22) [N]
``g_i``             3      gravitational acceleration on B and on every slosh mass [m/s^2]
``f_eta``           2K     further generalised forces on the modes (aeroelastic) [sqrt(kg) m/s^2]
==================  =====  ==============================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Layout"]


def _build(entries: list[tuple[str, int]]) -> tuple[dict[str, slice], int]:
    slices: dict[str, slice] = {}
    offset = 0
    for name, size in entries:
        slices[name] = slice(offset, offset + size)
        offset += size
    return slices, offset


@dataclass(frozen=True)
class Layout:
    """Index map of state, parameter and load vectors for N slosh pendulums and K modes per plane."""

    n_slosh: int
    n_modes: int
    state: dict[str, slice] = field(init=False, repr=False)
    params: dict[str, slice] = field(init=False, repr=False)
    loads: dict[str, slice] = field(init=False, repr=False)
    n_x: int = field(init=False)
    n_p: int = field(init=False)
    n_u: int = field(init=False)

    SLOSH_FIELDS = ("m", "length", "inertia", "r_hinge", "zeta", "omega", "phi")

    def __post_init__(self) -> None:
        for key in ("n_slosh", "n_modes"):
            value = getattr(self, key)
            if not isinstance(value, (int, np.integer)) or value < 0:
                raise ValueError(f"Layout.{key} = {value!r}: must be an integer >= 0")
        n, k = int(self.n_slosh), int(self.n_modes)
        state, n_x = _build(
            [("r_zw_i", 3), ("v_zw_i", 3), ("q_bi", 4), ("omega_bi_b", 3), ("eta", 2 * k),
             ("eta_dot", 2 * k), ("q_si", 4 * n), ("omega_si_s", 2 * n)]
        )
        params, n_p = _build(
            [("m_b", 1), ("r_cg", 3), ("J_b", 9), ("r_gimbal", 3), ("omega_modes", k),
             ("zeta_modes", k), ("phi_gimbal", k), ("dphi_gimbal", k), ("slosh", n * (8 + k))]
        )
        loads, n_u = _build([("f_b_i", 3), ("m_b_b", 3), ("thrust_e", 3), ("g_i", 3), ("f_eta", 2 * k)])
        for name, value in (("state", state), ("params", params), ("loads", loads), ("n_x", n_x),
                            ("n_p", n_p), ("n_u", n_u)):
            object.__setattr__(self, name, value)

    # ------------------------------------------------------------------ slosh parameter blocks
    @property
    def slosh_block(self) -> int:
        """Number of parameters per slosh pendulum."""
        return 8 + self.n_modes

    def slosh_param(self, j: int, name: str) -> slice:
        """Slice of parameter ``name`` (one of ``SLOSH_FIELDS``) of pendulum ``j`` in ``p``."""
        if not 0 <= j < self.n_slosh:
            raise IndexError(f"slosh index {j} outside 0..{self.n_slosh - 1}")
        sizes = {"m": 1, "length": 1, "inertia": 1, "r_hinge": 3, "zeta": 1, "omega": 1,
                 "phi": self.n_modes}
        if name not in sizes:
            raise KeyError(f"slosh parameter {name!r}: allowed {self.SLOSH_FIELDS}")
        offset = self.params["slosh"].start + j * self.slosh_block
        for key in self.SLOSH_FIELDS:
            if key == name:
                return slice(offset, offset + sizes[key])
            offset += sizes[key]
        raise AssertionError("unreachable")

    # ------------------------------------------------------------------ allocation helpers
    def zeros_state(self, batch: int | None = None) -> np.ndarray:
        """A state at rest: identity attitudes, everything else zero."""
        x = np.zeros(self.n_x if batch is None else (batch, self.n_x))
        x[..., self.state["q_bi"].start] = 1.0
        q_si = self.state["q_si"]
        x[..., q_si.start:q_si.stop:4] = 1.0
        return x

    def zeros_params(self, batch: int | None = None) -> np.ndarray:
        return np.zeros(self.n_p if batch is None else (batch, self.n_p))

    def zeros_loads(self, batch: int | None = None) -> np.ndarray:
        return np.zeros(self.n_u if batch is None else (batch, self.n_u))

    def view(self, array: np.ndarray, kind: str, name: str) -> np.ndarray:
        """A writable view of one named quantity of ``array`` (``kind`` is state/params/loads).

        Multi-entry quantities keep their natural shape: ``q_si`` is ``(..., N, 4)``,
        ``omega_si_s`` ``(..., N, 2)``, ``J_b`` ``(..., 3, 3)``, ``eta`` ``(..., 2, K)`` (plane, mode).
        """
        table = {"state": self.state, "params": self.params, "loads": self.loads}.get(kind)
        if table is None:
            raise KeyError(f"kind {kind!r}: allowed 'state', 'params', 'loads'")
        if name not in table:
            raise KeyError(f"{kind} has no {name!r}: allowed {sorted(table)}")
        part = array[..., table[name]]
        shapes = {"q_si": (self.n_slosh, 4), "omega_si_s": (self.n_slosh, 2), "J_b": (3, 3),
                  "eta": (2, self.n_modes), "eta_dot": (2, self.n_modes), "f_eta": (2, self.n_modes)}
        if name in shapes:
            part = part.reshape(part.shape[:-1] + shapes[name])
        return part
