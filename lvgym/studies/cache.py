"""Run cache: one small JSON file per finished run, keyed by a hash of everything that defines the run.

A study asks :meth:`RunCache.get` before it runs a case and :meth:`RunCache.put` as soon as the case has
finished (in the parent process, as results arrive), so a study that is interrupted resumes with only the
missing runs. Files are written to a temporary file in the same directory and moved into place with
:func:`os.replace`, so a file is either absent or complete.

>>> import tempfile
>>> cache = RunCache(tempfile.mkdtemp())
>>> key = run_key({"diameter": 0.3, "setup": {"t_end": 12.0}})
>>> cache.get(key) is None
True
>>> cache.put(key, {"flex_max": 1e-5})
>>> cache.get(key)
{'flex_max': 1e-05}
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["CACHE_VERSION", "RunCache", "run_key"]

#: bump when the meaning of a record changes (new responses, a fixed bug): old files are then ignored
CACHE_VERSION = 1


def _plain(x: Any) -> Any:
    """``x`` with floats rounded to 12 significant digits (0.1 + 0.2 and 0.3 hash alike) and tuples as lists."""
    if isinstance(x, float):
        return float(f"{x:.12g}") if math.isfinite(x) else str(x)
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in sorted(x.items())}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    return x


def run_key(params: dict[str, Any]) -> str:
    """A hex digest (20 characters) of ``params`` (JSON, sorted keys) and :data:`CACHE_VERSION`."""
    text = json.dumps({"v": CACHE_VERSION, "p": _plain(params)}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


class RunCache:
    """A directory of ``<key>.json`` run records (created on first use)."""

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)

    def path(self, key: str) -> Path:
        return self.directory / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The record stored under ``key``, or None (absent or unreadable)."""
        try:
            with open(self.path(key), encoding="utf-8") as fh:
                return json.load(fh)
        except (OSError, ValueError):
            return None

    def put(self, key: str, record: dict[str, Any]) -> None:
        """Store ``record`` (JSON-serialisable; NaN allowed) under ``key`` atomically."""
        self.directory.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{key}.", suffix=".tmp", dir=self.directory)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                json.dump(record, fh, sort_keys=True)
            os.replace(tmp, self.path(key))
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def __len__(self) -> int:
        return len(list(self.directory.glob("*.json"))) if self.directory.is_dir() else 0
