"""The old name of :mod:`baselines`, kept so that ``baselines_pid.*`` imports and ``python -m
baselines_pid.tune`` keep working; new code imports :mod:`baselines`."""

from baselines import *  # noqa: F401,F403
from baselines import __all__  # noqa: F401
