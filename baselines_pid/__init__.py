"""The old name of :mod:`lvgym.baselines`, kept in the repository (not installed) so that a checkout's
``baselines_pid.*`` imports keep working; new code imports :mod:`lvgym.baselines`."""

from lvgym.baselines import *  # noqa: F401,F403
from lvgym.baselines import __all__  # noqa: F401
