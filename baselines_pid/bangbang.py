"""The old name of :mod:`lvgym.baselines.bangbang`, kept in the repository (not installed) so that a checkout's
``baselines_pid.*`` imports keep working; new code imports :mod:`lvgym.baselines.bangbang`."""

from lvgym.baselines.bangbang import *  # noqa: F401,F403
