"""Simulator layer: the vehicle, its environment and the dynamics core flown together (no rewards, no
spaces). :class:`Simulator` steps a batch; :class:`Timeline` tabulates the mass model and modes;
:mod:`.flight` holds the compiled loads; :mod:`.record` records, saves and plots trajectories."""

from .core import SITES, Simulator
from .flight import DIAG, flight_conditions_batch, flight_loads, pack_context
from .record import Recorder, fly, load
from .timeline import MODELS, Timeline, build_timeline

__all__ = ["DIAG", "MODELS", "Recorder", "SITES", "Simulator", "fly", "load", "Timeline", "build_timeline", "flight_conditions_batch",
           "flight_loads", "pack_context"]
