"""Simulator layer: the vehicle, its environment and the dynamics core flown together (no rewards, no
spaces). :class:`Simulator` (built from the frozen specs of :mod:`.spec`) holds the constants of a flight and
steps a batch whose state is one :class:`SimData` value that it returns and takes (:class:`SimView` reads
it by name); :class:`Timeline` tabulates the mass model and modes; :mod:`.flight` holds the
compiled loads (:mod:`.strips` their aeroelastic part); :mod:`.layouts` describes every packed vector;
:mod:`.record` records, saves and plots trajectories."""

from .core import SITES, Kernel, Simulator, aeroelastic_strips
from .data import SimData
from .flight import flight_conditions_batch, flight_loads, pack_context
from .layouts import CONDITIONS, CONTEXT
from .piece import SLOSH_FREQUENCIES
from .record import Recorder, fly, load
from .spec import EnvironmentSpec, LaunchSpec, PhysicsSpec, TimelineSpec
from .tabulate import build_timeline
from .timeline import MODE_BASES, MODELS, Tables, Timeline
from .view import SimView

__all__ = ["CONDITIONS", "aeroelastic_strips", "CONTEXT", "EnvironmentSpec", "Kernel", "LaunchSpec", "MODE_BASES",
           "MODELS", "PhysicsSpec", "Recorder", "SLOSH_FREQUENCIES", "SITES", "SimData", "SimView", "Simulator", "Tables",
           "TimelineSpec", "Timeline", "build_timeline", "fly", "flight_conditions_batch", "flight_loads", "load", "pack_context"]
