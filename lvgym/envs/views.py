"""What every adapter of the functional env (:class:`~.functional.AscentFuncEnv`, held as ``self.func``)
shows of it: the single env, the Gymnasium vector env and the SB3 ``VecEnv`` read the same facts of the
task through this mixin."""

from __future__ import annotations

from typing import Any

__all__ = ["FuncViews"]


class FuncViews:
    """Read-only views of ``self.func`` (an :class:`~.functional.AscentFuncEnv`)."""

    func: Any

    @property
    def sim(self) -> Any:
        """The :class:`~lvgym.simulator.Simulator` of the current variant (its ``data`` is this env's rows)."""
        return self.func.sim

    @property
    def timeline(self) -> Any:
        """The mass and mode tables (:class:`~lvgym.simulator.timeline.Timeline`) in force."""
        return self.func.timeline

    @property
    def vehicle(self) -> Any:
        """The :class:`~lvgym.vehicle.config.Vehicle` in force."""
        return self.func.vehicle

    @property
    def observation_layout(self) -> Any:
        """The :class:`~lvgym.packing.Packed` layout of one row's observation (names, indices, units)."""
        return self.func.observation_layout

    @property
    def gimbal_limit(self) -> float:
        """Gimbal limit [rad]: a TVC action of 1 commands this angle."""
        return self.func.gimbal_limit
