"""Schedules read once per process: a baseline builds one policy per env row (a residual training run
builds 32) and per evaluation worker, and each would otherwise parse its schedule file again (the
flex schedules' YAML, with their margin records, took 0.1-0.5 s to parse per policy in pure Python).

:func:`read_once` keeps what a reader made of a file, keyed by the file's resolved path, size and
modification time, so an edited or regenerated file is read again. The objects are shared between
the policies built from them, so they must not be changed after reading (the schedules are frozen
dataclasses of tuples and arrays that the policies only read).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

__all__ = ["read_once"]

T = TypeVar("T")
_CACHE: dict[tuple[str, str, int, int], Any] = {}


def read_once(path: str | Path, reader: Callable[[Path], T], kind: str) -> T:
    """``reader(path)``, or what it returned before for the same file content (path, size and mtime);
    ``kind`` names the reader (one file may be read by two readers)."""
    p = Path(path).resolve()
    st = p.stat()
    key = (kind, str(p), st.st_size, st.st_mtime_ns)
    if key not in _CACHE:
        _CACHE[key] = reader(p)
    return _CACHE[key]
