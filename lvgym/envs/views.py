"""What every face of the batch core shows of its functional env (:class:`~.functional.AscentFuncEnv`, held
as ``self.func``) and of its state (``self.state``): the single env, the Gymnasium vector env and the SB3
``VecEnv`` read the same facts of the task, and the current flight, through this mixin."""

from __future__ import annotations

from typing import Any

__all__ = ["FuncViews"]


class FuncViews:
    """Read-only views of ``self.func`` (an :class:`~.functional.AscentFuncEnv`)."""

    func: Any
    state: Any

    @property
    def sim(self) -> Any:
        """The :class:`~lvgym.simulator.Simulator` of the current variant: the flight's constants (it holds
        no rows; its read-outs take them: ``sim.conditions(env.state.sim, "qbar")``)."""
        return self.func.sim

    @property
    def flight(self) -> Any:
        """The current flight: the simulator's read-outs of this env's rows (``self.state.sim``) by name, a
        :class:`~lvgym.simulator.SimView` with one row per episode (row 0 for a single env):
        ``flight.t[0]``, ``flight.x[0]``, ``flight.conditions("qbar")[0]``, ``flight.state("omega_bi_b")[0]``,
        ``flight.gimbal[0]``, ``flight.slosh_angles()[0]``. Views of the state's arrays, read when used;
        ask again after a reset (a reset may replace them)."""
        if self.state is None:
            raise RuntimeError("call reset() before reading the flight")
        return self.func.sim.view(self.state.sim)

    @property
    def timeline(self) -> Any:
        """The mass and mode tables (:class:`~lvgym.simulator.timeline.Timeline`) in force."""
        return self.func.timeline

    @property
    def vehicle(self) -> Any:
        """The :class:`~lvgym.vehicle.definition.Vehicle` in force."""
        return self.func.vehicle

    @property
    def observation_layout(self) -> Any:
        """The :class:`~lvgym.packing.Packed` layout of one row's observation (names, indices, units)."""
        return self.func.observation_layout

    @property
    def gimbal_limit(self) -> float:
        """Gimbal limit [rad]: a TVC action of 1 commands this angle."""
        return self.func.gimbal_limit
