"""Threads of the simulator: the compiled step releases the GIL, so large batches run row ranges on a
process-wide thread pool; :class:`Kernel` calls a compiled function through its entry point."""

from __future__ import annotations

import functools
import os
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

    def __call__(self, *args: Any) -> None:
        if self.entry is None:
            announce_compile(self.dispatcher)        # one line on stderr before a compile from a cold cache
            self.dispatcher(*args)
            if len(self.dispatcher.signatures) == 1:
                self.entry = self.dispatcher.overloads[self.dispatcher.signatures[0]].entry_point
            return
        self.entry(*args)


@functools.lru_cache(maxsize=4)
def pool(threads: int) -> ThreadPoolExecutor:
    """A process-wide thread pool (the compiled step releases the GIL)."""
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="lvgym")
