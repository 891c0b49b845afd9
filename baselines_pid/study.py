"""The old name of :mod:`baselines.study` (the package is ``baselines`` since it holds more than PID loops);
``python -m baselines_pid.study`` runs ``python -m baselines.study``."""

import sys

from baselines.study import *  # noqa: F401,F403
from baselines.study import main

if __name__ == "__main__":
    sys.exit(main())
