"""Compare TVC policies on the frozen benchmark protocol: ``python evaluate.py --help``.

The command is :mod:`lvgym.cli.evaluate`, installed as ``lvgym evaluate``; this file runs it from a
checkout (``python evaluate.py --policies zero lqg --episodes 10``) and keeps its names importable.
"""

from lvgym.cli.evaluate import (DEFAULT_EPISODES, DEFAULT_POLICIES, DEFAULT_SUITE, DEFAULT_SUITES, POLICIES, Args,  # noqa: F401
                                main, parse_args, resolve_policy)

if __name__ == "__main__":
    main()
