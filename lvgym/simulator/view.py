"""Read-outs of explicit simulator rows by name: :class:`SimView`, what :meth:`Simulator.view` returns.

A :class:`~.core.Simulator` holds no rows; its read-outs take a :class:`~.data.SimData` explicitly
(``sim.conditions(data, "qbar")``). A ``SimView`` binds one ``data`` to its simulator so that the rows
read as attributes, with a leading batch axis (B rows; one for a single env)::

    v = sim.view(data)
    v.t, v.x, v.gimbal                      # (B,), (B, n_x), (B, 2) [rad]: views of data's arrays
    v.conditions("qbar"), v.state("omega_bi_b"), v.slosh_angles()

The view holds references, not copies: it reads whatever ``data`` holds when an attribute is read
(the envs' ``env.unwrapped.flight`` makes a new view of the current state on every access).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import SimData

if TYPE_CHECKING:                                    # pragma: no cover
    from .core import Simulator

__all__ = ["SimView"]


class SimView:
    """The rows ``data`` of the simulator ``sim``, read by name (see the module docstring)."""

    __slots__ = ("sim", "data")

    def __init__(self, sim: Simulator, data: SimData) -> None:
        self.sim, self.data = sim, data

    def __repr__(self) -> str:
        return f"SimView({self.batch} rows at t = {np.array2string(self.t, threshold=4, precision=3)} s)"

    batch = property(lambda self: int(self.data.t.size), doc="rows (B)")
    t = property(lambda self: self.data.t, doc="time of each row [s] (B,)")
    x = property(lambda self: self.data.x, doc="dynamics state (B, n_x)")
    p = property(lambda self: self.data.p, doc="dynamics parameters in force (B, n_p)")
    c = property(lambda self: self.data.ctx, doc="context (B, n_ctx), layout CONTEXT then the models' blocks")
    failed = property(lambda self: self.data.failed, doc="rows whose state turned non-finite (B,)")
    gimbal = property(lambda self: self.sim.gimbal(self.data), doc="gimbal angles (B, 2) [rad]")
    gimbal_rate = property(lambda self: self.sim.gimbal_rate(self.data), doc="gimbal rates (B, 2) [rad/s]")
    cmd = property(lambda self: self.sim.command(self.data), doc="gimbal command (B, 2) [rad]")
    effort = property(lambda self: self.sim.effort(self.data),
                      doc="integrals of |gimbal| [rad s] and |gimbal rate| [rad] over the last period (B, 2)")
    on_rail = property(lambda self: self.sim.on_rail(self.data), doc="still held on the pad or rail (B,)")
    lifted = property(lambda self: self.sim.lifted(self.data), doc="lifted off (B,)")
    rail_s = property(lambda self: self.sim.rail_s(self.data), doc="travel along the rail [m] (B,)")

    def conditions(self, name: str) -> np.ndarray:
        """Flight condition ``name`` of every row (:meth:`Simulator.conditions`)."""
        return self.sim.conditions(self.data, name)

    def state(self, name: str) -> np.ndarray:
        """State entry ``name`` of every row (:meth:`Simulator.state`)."""
        return self.sim.state(self.data, name)

    def load_dispersion(self, name: str) -> np.ndarray:
        """Load dispersion ``name`` of every row (B,) (:meth:`Simulator.load_dispersion`)."""
        return self.sim.load_dispersion(self.data, name)

    def slosh_angles(self) -> np.ndarray:
        """Pendulum deflections (B, N, 2) [rad] (:meth:`Simulator.slosh_angles`)."""
        return self.sim.slosh_angles(self.data)

    def lateral_cg_offset(self) -> np.ndarray:
        """Lateral CG offset (B, 2) [m] (:meth:`Simulator.lateral_cg_offset`)."""
        return self.sim.lateral_cg_offset(self.data)
