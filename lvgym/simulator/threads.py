"""Threads of the simulator: the compiled step releases the GIL, so large batches run row ranges on a
process-wide thread pool; :class:`Kernel` calls a compiled function through its entry point (the simulator's
and the envs' kernels, and the control laws' through :meth:`Kernel.keyed`)."""

from __future__ import annotations

import functools
import os
from collections.abc import Hashable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from lvgym.parallel import default_workers

from .coldstart import announce_compile

__all__ = ["ROWS_PER_THREAD", "Kernel", "default_threads", "pool"]

ROWS_PER_THREAD = 8          # smaller batches run on the calling thread


def default_threads() -> int:
    """``$LVGYM_THREADS``, else the CPUs this process may run on."""
    env = os.environ.get("LVGYM_THREADS")
    return max(1, int(env)) if env else default_workers()


class Kernel:
    """A compiled function called through its compiled entry point after the first call.

    Numba's dispatcher resolves the types of every argument on every call; for the loads function
    (a cfunc) that costs about 25 us, a fifth of a whole env step. The simulator always passes the
    same types, so after the first call (which compiles or loads the cached machine code) it calls
    the compiled entry point directly."""

    def __init__(self, dispatcher: Any) -> None:
        self.dispatcher = dispatcher
        self.entry: Any = None
        self.entries: dict[Hashable, Any] = {}

    def __call__(self, *args: Any) -> None:
        if self.entry is None:
            announce_compile(self.dispatcher)        # one line on stderr before a compile from a cold cache
            self.dispatcher(*args)
            if len(self.dispatcher.signatures) == 1:
                self.entry = self.dispatcher.overloads[self.dispatcher.signatures[0]].entry_point
            return
        self.entry(*args)

    def keyed(self, key: Hashable, *args: Any) -> None:
        """The call for a caller whose arguments' types may change between calls (a control law's
        observations' dtype): the first call of a ``key`` goes through the dispatcher and keeps the entry
        point of the overload the arguments' types select; later calls of that key go to it. The caller
        passes the same types for the same key (its own blocks, the varying arrays contiguous with fixed
        dtypes). AAC around the PID law: 7.9 us a call through the dispatcher, 1.6 us through this."""
        entry = self.entries.get(key)
        if entry is not None:
            entry(*args)
            return
        announce_compile(self.dispatcher)
        self.dispatcher(*args)
        types = tuple(self.dispatcher.typeof_pyval(a) for a in args)
        self.entries[key] = self.dispatcher.overloads[types].entry_point


@functools.lru_cache(maxsize=4)
def pool(threads: int) -> ThreadPoolExecutor:
    """A process-wide thread pool (the compiled step releases the GIL)."""
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="lvgym")
