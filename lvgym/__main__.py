"""``python -m lvgym``: the console script ``lvgym`` (:mod:`lvgym.cli.main`)."""

import sys

from lvgym.cli.main import main

sys.exit(main())
