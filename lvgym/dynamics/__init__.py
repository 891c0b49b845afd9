"""Dynamics core: coupled rigid body, bending modes and slosh pendulums (thesis chapter 2).

Imports neither gymnasium nor the environment models: plain arrays in, derivatives out.
"""

from .invariants import ENERGY_TERMS
from .layout import Layout
from .model import ADAPTIVE_METHODS, NonRigidModel, Trajectory, integrate
from .stepper import LOADS_SIGNATURE, METHODS, compile_loads, step_batch, zoh_loads

__all__ = ["ADAPTIVE_METHODS", "ENERGY_TERMS", "METHODS", "Layout", "NonRigidModel", "Trajectory",
           "integrate", "LOADS_SIGNATURE", "compile_loads", "step_batch", "zoh_loads"]
