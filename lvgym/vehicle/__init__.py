"""Vehicle layer: configuration (YAML -> frozen dataclasses), mass model, propulsion, staging, beam modes.

Imports neither the environment models nor the dynamics core: it hands plain numbers and arrays up to the
simulator, which composes them.
"""

from .config import clear_vehicle_cache, load_vehicle, parse_vehicle
from .definition import Vehicle
from .massmodel import MassModel, MassProperties, MassState

__all__ = ["MassModel", "MassProperties", "MassState", "Vehicle", "clear_vehicle_cache", "load_vehicle", "parse_vehicle"]
