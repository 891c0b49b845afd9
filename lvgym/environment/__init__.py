"""Environment models (thesis section 3.2): Earth, gravity, atmosphere, wind, aerodynamics.

Each model is a small class with one call signature, batched over a leading axis of vehicles, whose
arithmetic lives in numba-compiled functions over explicit parameters (so the simulator can call it
from compiled loads functions). Models are chosen by name with :func:`make`; importing this package
registers them all.
"""

from . import aerodynamics, aeroelastic, atmosphere, barrowman, datasheet, earth, gravity, turbulence, wind
from .aerodynamics import AeroState, AxisymmetricAero, Tables6Aero
from .aeroelastic import StripAeroelastic
from .barrowman import BarrowmanAero
from .conditions import Environment, FlightConditions
from .earth import LaunchSite
from .registry import make, names, register

__all__ = ["AeroState", "AxisymmetricAero", "BarrowmanAero", "Environment", "FlightConditions", "LaunchSite", "StripAeroelastic", "Tables6Aero",
           "aerodynamics", "aeroelastic", "atmosphere", "barrowman", "datasheet", "earth", "gravity", "make", "names",
           "register", "turbulence", "wind"]
