"""The old name of :mod:`baselines.bangbang` (the package is ``baselines`` since it holds more than PID loops)."""

from baselines.bangbang import *  # noqa: F401,F403
