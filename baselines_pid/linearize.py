"""The old name of :mod:`lvgym.baselines.design.linearize`, kept in the repository (not installed) so that a
checkout's ``baselines_pid.*`` imports keep working; new code imports :mod:`lvgym.baselines.design.linearize`."""

from lvgym.baselines.design.linearize import *  # noqa: F401,F403
