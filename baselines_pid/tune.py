"""The old name of :mod:`baselines.tune` (the package is ``baselines`` since it holds more than PID loops);
``python -m baselines_pid.tune`` runs ``python -m baselines.tune``."""

import sys

from baselines.tune import *  # noqa: F401,F403
from baselines.tune import main

if __name__ == "__main__":
    sys.exit(main())
