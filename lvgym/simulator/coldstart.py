"""The line a process prints before it compiles the flight model.

numba compiles the simulator's kernels on their first use (the loads function when :mod:`.flight` is imported, the
step :func:`.advance.advance_range` at the first step): 121 s of CPU (224 s of wall time) to the first step of a
``smile-v2`` env on the busy 2-core development machine, with nothing to show for it. Each is ``cache=True``, so
numba keeps the machine code on disk (``__pycache__`` beside the sources, or ``$NUMBA_CACHE_DIR``) and later
processes load it (3.7 s to the first step). :func:`announce_compile` says so in one line, :data:`MESSAGE`, on
stderr, at most once per process, and only when numba's cache holds no entry for the function about to compile (a
fresh install, an edited source file, another numba version): :func:`cache_is_cold`.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

__all__ = ["MESSAGE", "announce_compile", "cache_is_cold"]

MESSAGE = "lvgym: compiling the flight model (numba), a minute or two, once: later runs load it from numba's cache"
_announced = False


def cache_is_cold(func: Any) -> bool:
    """Whether compiling ``func`` (a Python function numba compiles with ``cache=True``, or a numba dispatcher of
    one) now means compiling it: numba's on-disk index of it is missing, stale (its source file changed) or of
    another numba version, and this process has not compiled or loaded it yet. False where numba keeps no cache
    of it or does not compile (``NUMBA_DISABLE_JIT``)."""
    if getattr(func, "signatures", None):            # a dispatcher compiled or loaded in this process already
        return False
    try:
        from numba.core import config
        from numba.core.caching import FunctionCache

        if config.DISABLE_JIT:
            return False
        return not FunctionCache(getattr(func, "py_func", func))._cache_file._load_index()
    except Exception:  # noqa: BLE001  (no cache for it, or an index numba could not read either: nothing to say)
        return False


def announce_compile(func: Any, stream: TextIO | None = None) -> bool:
    """Print :data:`MESSAGE` to ``stream`` (default stderr) when ``func`` is about to compile (:func:`cache_is_cold`)
    and the process has not said so yet; returns whether it printed."""
    global _announced
    if _announced or not cache_is_cold(func):
        return False
    _announced = True
    print(MESSAGE, file=sys.stderr if stream is None else stream, flush=True)
    return True
