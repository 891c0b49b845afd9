"""Result files of an evaluation: CSV, JSON, a Markdown table and PNG plots, each written atomically.

Every file is first written to a hidden temporary file in the same folder (``.<name>.<pid>.tmp``),
flushed and fsync'ed, then renamed over its final name with ``os.replace`` (atomic on POSIX and
Windows within one file system). An evaluation that is interrupted therefore leaves each result file
either complete (new or old) or absent, never half-written; an exception while writing removes the
temporary file, and temporaries left by killed processes are removed by the next write to the folder.

Files (:func:`write_results`): ``episodes.csv`` (one row per episode, SI units and radians),
``summary.csv`` (per suite, condition and policy, with intervals and ranks), ``degradation.csv`` (one row
per policy, condition and metric: ``rate_error_rad`` and ``score``), ``comparison.csv`` (the paired
comparison, :mod:`.compare`), ``run_groups.csv`` (agents over training runs, when there are any),
``headline.csv`` and ``headline_others.csv`` (protocol v2's headline and the other policies flown beside
it, :mod:`.headline`), ``table.md`` (what :func:`~.tables.markdown_table` prints), ``results.json`` (all of it
with the run's metadata; written last), and the figures of :mod:`.plots`: ``rate_error.png``,
``degradation.png`` and, when a v2 suite was flown, ``headline.png``, each policy in one colour and marker
in all of them.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from .headline import flat
from .plots import plot_degradation, plot_headline, plot_rate_error, styles
from .tables import markdown_table

__all__ = ["atomic_path", "atomic_write", "atomic_write_text", "csv_text", "json_text", "markdown_table",
           "plot_degradation", "plot_headline", "plot_rate_error", "remove_stale_temporaries", "write_results"]

_TMP = re.compile(r"^\..+\.(\d+)\.tmp$")


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_temporaries(folder: str | os.PathLike[str]) -> list[Path]:
    """Delete ``.<name>.<pid>.tmp`` files in ``folder`` whose writing process is gone; returns them."""
    removed = []
    folder = Path(folder)
    if not folder.is_dir():
        return removed
    for p in folder.iterdir():
        m = _TMP.match(p.name)
        if m and not _pid_alive(int(m.group(1))):
            with contextlib.suppress(FileNotFoundError):
                p.unlink()
                removed.append(p)
    return removed


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on a clean exit it replaces ``path`` (``os.replace``),
    on an exception it is deleted and ``path`` is left as it was."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        yield tmp
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


def atomic_write(path: str | os.PathLike[str], write: Callable[[IO[Any]], None], binary: bool = False) -> Path:
    """Open a temporary file next to ``path``, call ``write(file)``, then atomically move it to ``path``."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb" if binary else "w", newline="" if not binary else None,
                  **({} if binary else {"encoding": "utf-8"})) as f:
            write(f)
    return Path(path)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda f: f.write(text))


# ---------------------------------------------------------------------------------------------- formats
def _plain(value: Any) -> Any:
    """JSON-safe value: numpy scalars to Python, NaN and infinities to None."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def csv_text(rows: Sequence[Mapping[str, Any]]) -> str:
    """Rows as CSV (columns in order of first appearance; floats in shortest round-trip form)."""
    columns: list[str] = []
    for r in rows:
        columns += [k for k in r if k not in columns]
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (v.item() if isinstance(v, np.generic) else v) for k, v in r.items()})
    return buf.getvalue()


def json_text(obj: Any) -> str:
    """``obj`` as indented JSON (NaN and infinities as null)."""
    return json.dumps(_plain(obj), indent=1, sort_keys=False) + "\n"


# ---------------------------------------------------------------------------------------------- all files
def write_results(out: str | os.PathLike[str], records: Sequence[Mapping[str, Any]],
                  summary: Sequence[Mapping[str, Any]], degradation: Sequence[Mapping[str, Any]],
                  meta: Mapping[str, Any], plots: bool = True, comparison: Sequence[Mapping[str, Any]] = (),
                  groups: Sequence[Mapping[str, Any]] = (), headline: Sequence[Mapping[str, Any]] = (),
                  family: Sequence[str] = (), others: Sequence[Mapping[str, Any]] = (),
                  faults: Sequence[Mapping[str, Any]] = ()) -> dict[str, Path]:
    """Write every result file into ``out`` (created if missing), each atomically; ``results.json``
    last (``headline``: protocol v2's rows, :func:`~.headline.headline`, also as ``headline.csv`` and
    ``headline.png``; ``others``: the other policies flown beside it, :func:`~.headline.others`, also as
    ``headline_others.csv``; ``faults``: the rows by kind of in-flight fault, :func:`~.decide.by_fault`, also
    as ``faults.csv``). Returns the paths by name."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(folder)
    paths: dict[str, Path] = {}
    paths["episodes.csv"] = atomic_write_text(folder / "episodes.csv", csv_text(records))
    paths["summary.csv"] = atomic_write_text(folder / "summary.csv", csv_text(summary))
    paths["degradation.csv"] = atomic_write_text(folder / "degradation.csv", csv_text(degradation))
    if comparison:
        paths["comparison.csv"] = atomic_write_text(folder / "comparison.csv", csv_text(comparison))
    if groups:
        paths["run_groups.csv"] = atomic_write_text(folder / "run_groups.csv", csv_text(groups))
    if headline:
        paths["headline.csv"] = atomic_write_text(folder / "headline.csv", csv_text(flat(headline)))
    if others:
        paths["headline_others.csv"] = atomic_write_text(folder / "headline_others.csv", csv_text(others))
    if faults:
        paths["faults.csv"] = atomic_write_text(folder / "faults.csv", csv_text(faults))
    paths["table.md"] = atomic_write_text(folder / "table.md",
                                          markdown_table(summary, degradation, meta, comparison, groups, headline,
                                                         family, others, faults))
    if plots:                                       # one colour and marker per policy in every figure
        look = styles([r["policy"] for r in records] + [r["policy"] for r in (*summary, *degradation, *others)])
        paths["rate_error.png"] = atomic_write(folder / "rate_error.png",
                                               lambda f: plot_rate_error(records, f, summary, look), True)
        if degradation:
            paths["degradation.png"] = atomic_write(folder / "degradation.png",
                                                    lambda f: plot_degradation(degradation, f, look), True)
        if headline:
            paths["headline.png"] = atomic_write(folder / "headline.png",
                                                 lambda f: plot_headline(headline, f, others, look), True)
    paths["results.json"] = atomic_write_text(folder / "results.json", json_text(
        {"meta": meta, "summary": summary, "degradation": degradation, "comparison": list(comparison),
         "run_groups": list(groups), **({"headline": list(headline)} if headline else {}),
         **({"headline_others": list(others)} if others else {}), **({"faults": list(faults)} if faults else {}),
         "episodes": records}))
    return paths
