"""The old name of :mod:`baselines.pid` (the package is ``baselines`` since it holds more than PID loops)."""

from baselines.pid import *  # noqa: F401,F403
