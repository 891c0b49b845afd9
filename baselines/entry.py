"""A compiled law called through the entry point of its compiled overload, after the first call.

Numba's dispatcher types every argument on every call. A law's kernel takes named tuples of the law's own
tables and state, and typing them costs several microseconds a call: at one row (a single env, a user's
policy) that is most of the call (AAC around the PID law: 7.9 us through the dispatcher, 1.6 us through
the entry point, in the same process). :class:`Entry` resolves the overload once per ``key``, the caller's
description of whatever in its arguments' types can change between calls (e.g. the observations' dtype),
and then calls its entry point, which converts the arguments but does not type them. The caller passes
the same types for the same key: its own blocks, and the varying arrays made contiguous with fixed dtypes.
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

__all__ = ["Entry"]


class Entry:
    """``dispatcher`` (a ``numba.njit`` function) called as ``entry(key, *args)``: the first call of a ``key``
    goes through the dispatcher (it compiles or loads the machine code) and keeps the entry point of the
    overload the arguments' types select; later calls of that key go to it directly."""

    def __init__(self, dispatcher: Any) -> None:
        self.dispatcher = dispatcher
        self.entries: dict[Hashable, Any] = {}

    def __call__(self, key: Hashable, *args: Any) -> None:
        entry = self.entries.get(key)
        if entry is not None:
            entry(*args)
            return
        self.dispatcher(*args)
        types = tuple(self.dispatcher.typeof_pyval(a) for a in args)
        self.entries[key] = self.dispatcher.overloads[types].entry_point
