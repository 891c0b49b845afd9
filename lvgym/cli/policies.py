"""The policies of the command lines: importing this module registers every built-in policy with the
benchmark's registry (:mod:`lvgym.benchmark.registry`): the controllers of ``lvgym.baselines`` (``pid``,
``gs-pid``, ``gs-pid-flex``, ``aac``, ``lqg``, ...) and the shipped learned policies and the loader of saved
models of ``lvgym.agents`` (``ppo``, ``ppo-res-lqg``, ``.zip`` models, ``train.py`` run folders).

The benchmark layer names no controller module; the command layer (``evaluate.py``, the ``lvgym``
commands) imports this module, which imports the packages that register themselves. It sits above
``lvgym.cli`` (whose ``__init__`` the lower layers use and which imports none of this).
"""

from __future__ import annotations

import lvgym.agents  # noqa: F401  (registers ppo, ppo-res-lqg and the loader of saved models)
import lvgym.baselines  # noqa: F401  (registers pid, gs-pid, gs-pid-flex, aac, pid-thesis, gs-pid-thesis, lqg, lqg-front)
from lvgym.benchmark.registry import LOADERS, POLICIES, register_policy, register_policy_loader, resolve_policy

__all__ = ["LOADERS", "POLICIES", "register_policy", "register_policy_loader", "resolve_policy"]
