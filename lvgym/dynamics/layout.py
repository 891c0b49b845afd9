"""Flat array layouts of the non-rigid vehicle: state, parameters and loads.

The compiled kernels work on three flat ``float64`` vectors per vehicle (or arrays of shape
``(batch, n)``): the state ``x``, the parameters ``p`` (mass properties, slosh and mode data, which
the caller may change before every step) and the loads ``u`` (forces held over a step). This module
says where each named quantity lives, so that Python code never indexes by hand. A layout is fixed
by the number of slosh pendulums ``n_slosh`` (N) and of bending modes per plane ``n_modes`` (K).

Conventions (docs/conventions.md): SI units, radians; quaternions are Hamilton, scalar first;
``q_bi`` is the attitude of the body frame b relative to the inertial frame i, with
``C_ib = R(q_bi)`` (``v_i = C_ib @ v_b``). Stations are body-frame coordinates measured from the
nose tip, ``+x_b`` forward, so stations along the vehicle are zero or negative.

The tables below are generated from the descriptions in this module (:data:`STATE`, :data:`PARAMS`,
:data:`SLOSH`, :data:`LOADS`), which are the only place any offset is defined: the compiled kernels read
their offsets from them (``at(X.eta_dot, K, N)``, see :mod:`lvgym.packing`).
"""

from __future__ import annotations

import functools
from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np

from lvgym.packing import Field, Linear, LinearField, Packed

__all__ = ["ATTITUDES", "LOADS", "Layout", "P", "PARAMS", "RANK_ONE", "RK4_ROWS", "SIZES", "SLOSH", "SLOSH_BLOCK",
           "SLOSH_FIELDS", "SLOSH_WORK", "SPEEDS", "STATE", "S", "TERMS_PER_PENDULUM", "U", "V", "WORK_ROWS", "X",
           "X_PER_SLOSH"]

# ---------------------------------------------------------------------------- the one description
#: state x (K modes per plane, N pendulums)
STATE = Linear("dynamics state", [
    LinearField("r_zw_i", 3, unit="m", doc="position of the rigid-body CG z from the inertial origin w"),
    LinearField("v_zw_i", 3, unit="m/s", doc="its inertial velocity"),
    LinearField("q_bi", 4, unit="-", doc="body attitude quaternion (scalar first)"),
    LinearField("omega_bi_b", 3, unit="rad/s", doc="body angular velocity, body frame"),
    LinearField("eta", per_mode=2, unit="sqrt(kg) m", doc="modal coordinates: the K modes of the y plane, then z",
                shape=lambda K, N: (2, K)),
    LinearField("eta_dot", per_mode=2, unit="sqrt(kg) m/s", doc="their rates", shape=lambda K, N: (2, K)),
    LinearField("q_si", per_slosh=4, unit="-", doc="attitude of each pendulum frame s_j (scalar first)",
                shape=lambda K, N: (N, 4)),
    LinearField("omega_si_s", per_slosh=2, unit="rad/s", doc="pendulum angular velocity, y_s and z_s components",
                shape=lambda K, N: (N, 2)),
])
#: parameters of one pendulum j, a block of the ``slosh`` parameter (sizes in K only)
SLOSH = Linear("slosh parameters", [
    LinearField("m", 1, unit="kg", doc="slosh mass (0: the pendulum is inactive and its state frozen)"),
    LinearField("length", 1, unit="m", doc="pendulum length L, hinge to mass"),
    LinearField("inertia", 1, unit="kg m^2", doc="transverse inertia of the slosh body about the mass"),
    LinearField("r_hinge", 3, unit="m", doc="station of the undeflected hinge"),
    LinearField("zeta", 1, unit="-", doc="slosh damping ratio"),
    LinearField("omega", 1, unit="rad/s", doc="slosh natural frequency used by the damper"),
    LinearField("phi", per_mode=1, unit="1/sqrt(kg)", doc="mode shape at the hinge node"),
])
#: parameters p
PARAMS = Linear("dynamics parameters", [
    LinearField("m_b", 1, unit="kg", doc="mass of the rigid body B"),
    LinearField("r_cg", 3, unit="m", doc="station of the CG of B"),
    LinearField("J_b", 9, unit="kg m^2", doc="inertia of B about its CG, body axes, row major",
                shape=lambda K, N: (3, 3)),
    LinearField("r_gimbal", 3, unit="m", doc="station of the engine gimbal"),
    LinearField("omega_modes", per_mode=1, unit="rad/s", doc="bending natural frequencies"),
    LinearField("zeta_modes", per_mode=1, unit="-", doc="bending damping ratios"),
    LinearField("phi_gimbal", per_mode=1, unit="1/sqrt(kg)", doc="mode shape at the gimbal node"),
    LinearField("dphi_gimbal", per_mode=1, unit="1/(m sqrt(kg))", doc="mode slope at the gimbal node"),
    LinearField("slosh", per_slosh=SLOSH.size_form[0], per_both=SLOSH.size_form[1], unit="-",
                doc="per pendulum, the block SLOSH"),
])
#: loads u, held over one integration stage
LOADS = Linear("dynamics loads", [
    LinearField("f_b_i", 3, unit="N", doc="external force on B at its CG other than gravity and thrust, inertial"),
    LinearField("m_b_b", 3, unit="N m", doc="external moment on B about its CG, body frame"),
    LinearField("thrust_b", 3, unit="N", doc="thrust in the undeformed engine frame (body axes)"),
    LinearField("g_i", 3, unit="m/s^2", doc="gravitational acceleration"),
    LinearField("f_eta", per_mode=2, unit="sqrt(kg) m/s^2", doc="further generalised forces on the modes",
                shape=lambda K, N: (2, K)),
])
#: independent speeds of B and the modes, the unknowns of the reduced system ``A_r u_dot = b``
SPEEDS = Linear("rigid and elastic speeds", [
    LinearField("v_zw_i", 3, unit="m/s", doc="inertial velocity of the CG of B"),
    LinearField("omega_bi_b", 3, unit="rad/s", doc="body rate"),
    LinearField("eta_dot", per_mode=2, unit="sqrt(kg) m/s", doc="modal rates, y plane then z"),
], pad=False)

#: offset forms for compiled code: ``at(X.eta_dot, K, N)``, ``at(P.slosh, K, N) + j * at(SLOSH_BLOCK, K, N)
#: + at(S.phi, K, N)``; the fields that depend on neither K nor N are also plain integers in ``*.fixed``
X, P, U, S, V = STATE.at, PARAMS.at, LOADS.at, SLOSH.at, SPEEDS.at
#: size forms of the vectors, for compiled code: ``at(SIZES.state, K, N)`` is the length of ``x``,
#: ``at(SIZES.speeds, K, N)`` the order of the reduced system
SIZES = namedtuple("DynamicsSizes", ["state", "params", "loads", "slosh", "speeds"])(
    STATE.size_form, PARAMS.size_form, LOADS.size_form, SLOSH.size_form, SPEEDS.size_form)
#: size form of one pendulum's parameter block
SLOSH_BLOCK = SLOSH.size_form
#: entries per pendulum of the state fields, for compiled code: pendulum j's quaternion starts at
#: ``at(X.q_si, K, N) + j * X_PER_SLOSH.q_si``
X_PER_SLOSH = STATE.per_slosh
#: names of one pendulum's parameters, in order
SLOSH_FIELDS = SLOSH.names

# ---------------------------------------------------------------------------- work arrays of the kernels
# (internal: the scratch of vehicle_deriv and rk4_vehicle, described here like the vectors above)
#: per-pendulum row of the work array ``slosh``: what the elimination keeps for the back-substitution
SLOSH_WORK = Packed("slosh work", [
    Field("y_s", 3, "-", "pendulum axis y_s, inertial components"),
    Field("z_s", 3, "-", "pendulum axis z_s, inertial components"),
    Field("rho_b", 3, "m", "deflected hinge from the CG of B, body frame"),
    Field("g_beta", 3, "m/s^2", "gravity less the bias acceleration of the slosh mass, inertial"),
    Field("tau", 2, "m^2/s^2", "damper torque per unit slosh mass, s frame (y_s, z_s)"),
    Field("m", 1, "kg", "slosh mass (<= 0: the pendulum is inactive)"),
    Field("length", 1, "m", "pendulum length L"),
    Field("k2", 1, "m^2", "transverse inertia per unit slosh mass J/m"),
])
#: one rank-one term ``c h h^T`` of the reduced matrix: two rows of the ``work`` matrix
RANK_ONE = Packed("rank-one term", [
    Field("ch", 1, "-", "c h, a row of speeds"),
    Field("h", 1, "-", "h, a row of speeds"),
])
#: rank-one terms per pendulum at most: the rod, and the three axes when the slosh body has inertia
TERMS_PER_PENDULUM = 4
#: rows of the ``work`` matrix (``max(n_r, 3)`` columns)
WORK_ROWS = Linear("work rows", [
    LinearField("scratch", 1, unit="m/s^2", doc="z, the pendulum's projected acceleration (3 columns)"),
    LinearField("terms", per_slosh=TERMS_PER_PENDULUM * RANK_ONE.size, doc="the rank-one terms, in order"),
])
#: the attitude matrices (3 x 3 each) in the array ``C`` of the kernels' ``DerivWork``
ATTITUDES = Packed("attitude matrices", [
    Field("C_ib", 1, "-", "C_ib = R(q_bi), body to inertial"),
    Field("C_is", 1, "-", "C_is = R(q_si) of the pendulum being eliminated, pendulum to inertial"),
])

#: rows of the RK4 buffer ``buf`` of :func:`lvgym.dynamics.stepper.rk4_vehicle`, each a state vector
RK4_ROWS = Packed("rk4 rows", [
    Field("k1", 1, "-", "stage derivative 1"),
    Field("k2", 1, "-", "stage derivative 2"),
    Field("k3", 1, "-", "stage derivative 3"),
    Field("k4", 1, "-", "stage derivative 4"),
    Field("x_stage", 1, "-", "state of the current stage"),
    Field("x_prop", 1, "-", "state at the start of the step, propagated over h/2"),
])


@functools.lru_cache(maxsize=None)
def _resolved(n: int, k: int) -> tuple[dict[str, Packed], dict[str, dict[str, slice]]]:
    """The :class:`~lvgym.packing.Packed` layouts (state, params, loads, slosh) for ``n`` pendulums and ``k``
    modes per plane and the state, params and loads slices by name: resolved once per process (a resolve
    makes four offset namedtuple classes, about 0.25 ms), shared by every :class:`Layout` of that size."""
    packed = {kind: lin.resolve(k, n) for kind, lin in (("state", STATE), ("params", PARAMS),
                                                          ("loads", LOADS), ("slosh", SLOSH))}
    slices = {kind: {name: packed[kind].slice(name) for name in packed[kind].names}
              for kind in ("state", "params", "loads")}
    return packed, slices


@dataclass(frozen=True)
class Layout:
    """Index map of state, parameter and load vectors for N slosh pendulums and K modes per plane
    (the :class:`~lvgym.packing.Packed` layouts of :data:`STATE`, :data:`PARAMS` and :data:`LOADS`)."""

    n_slosh: int
    n_modes: int
    state: dict[str, slice] = field(init=False, repr=False)
    params: dict[str, slice] = field(init=False, repr=False)
    loads: dict[str, slice] = field(init=False, repr=False)
    packed: dict[str, Packed] = field(init=False, repr=False, compare=False)
    n_x: int = field(init=False)
    n_p: int = field(init=False)
    n_u: int = field(init=False)

    SLOSH_FIELDS = SLOSH_FIELDS

    def __post_init__(self) -> None:
        for key in ("n_slosh", "n_modes"):
            value = getattr(self, key)
            if not isinstance(value, (int, np.integer)) or value < 0:
                raise ValueError(f"Layout.{key} = {value!r}: must be an integer >= 0")
        packed, slices = _resolved(int(self.n_slosh), int(self.n_modes))
        object.__setattr__(self, "packed", dict(packed))
        for kind in ("state", "params", "loads"):
            object.__setattr__(self, kind, dict(slices[kind]))
        for name, kind in (("n_x", "state"), ("n_p", "params"), ("n_u", "loads")):
            object.__setattr__(self, name, packed[kind].size)

    # ------------------------------------------------------------------ slosh parameter blocks
    @property
    def slosh_block(self) -> int:
        """Number of parameters per slosh pendulum."""
        return self.packed["slosh"].size

    def slosh_param(self, j: int, name: str) -> slice:
        """Slice of parameter ``name`` (one of ``SLOSH_FIELDS``) of pendulum ``j`` in ``p``."""
        if not 0 <= j < self.n_slosh:
            raise IndexError(f"slosh index {j} outside 0..{self.n_slosh - 1}")
        if name not in SLOSH_FIELDS:
            raise KeyError(f"slosh parameter {name!r}: allowed {SLOSH_FIELDS}")
        sub = self.packed["slosh"].slice(name)
        start = self.params["slosh"].start + j * self.slosh_block
        return slice(start + sub.start, start + sub.stop)

    # ------------------------------------------------------------------ allocation helpers
    def zeros_state(self, batch: int | None = None) -> np.ndarray:
        """A state at rest: identity attitudes, everything else zero."""
        x = np.zeros(self.n_x if batch is None else (batch, self.n_x))
        x[..., self.state["q_bi"].start] = 1.0
        q_si = self.view(x, "state", "q_si")
        q_si[..., 0] = 1.0
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
        if kind not in ("state", "params", "loads"):
            raise KeyError(f"kind {kind!r}: allowed 'state', 'params', 'loads'")
        layout = self.packed[kind]
        if name not in layout:
            raise KeyError(f"{kind} has no {name!r}: allowed {sorted(layout.names)}")
        return layout.view(array, name)


def _doc() -> str:
    parts = [("State ``x``", STATE), ("Parameters ``p``", PARAMS), ("Per slosh pendulum ``j`` (block ``slosh``)", SLOSH),
             ("Loads ``u``, held constant over one integration stage", LOADS),
             ("Independent speeds of the reduced system", SPEEDS)]
    return "\n\n".join(f"{title} (length ``{lin.table_size()}``):\n\n{lin.table()}" for title, lin in parts)


__doc__ = (__doc__ or "") + "\n" + _doc()
