"""The old name of :mod:`lvgym.baselines.pid`, kept in the repository (not installed) so that a checkout's
``baselines_pid.*`` imports keep working; new code imports :mod:`lvgym.baselines.pid`."""

from lvgym.baselines.pid import *  # noqa: F401,F403
