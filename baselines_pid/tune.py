"""The old name of :mod:`lvgym.baselines.design.tune`, kept in the repository (not installed) so that a
checkout's ``baselines_pid.*`` imports keep working; new code imports :mod:`lvgym.baselines.design.tune`.
``python -m baselines_pid.tune`` runs it."""

import sys

from lvgym.baselines.design.tune import *  # noqa: F401,F403
from lvgym.baselines.design.tune import main

if __name__ == "__main__":
    sys.exit(main())
