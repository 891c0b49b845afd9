"""The old name of :mod:`baselines.linearize` (the package is ``baselines`` since it holds more than PID loops)."""

from baselines.linearize import *  # noqa: F401,F403
