"""Run a list of cases through the cache and an executor; the common engine of every study.

:func:`run_cases` looks every case up in the :class:`~.cache.RunCache`, runs only the missing ones with
:func:`~.executor.run_map` (each record is cached the moment it arrives, so an interrupted study resumes)
and returns all records as a table, in the order of the cases.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from .cache import RunCache, run_key
from lvgym.parallel import run_map
from .responses import FACTORS, RECORD, RunSetup, run_case

__all__ = ["StudyRun", "case", "run_cases"]


@dataclass(frozen=True)
class StudyRun:
    """What :func:`run_cases` did: ``table`` (one row per case), ``ran`` new runs, ``cached`` reused."""

    table: pd.DataFrame
    ran: int
    cached: int


def case(length: float, diameter: float, fill: float, mass_flow: float, slosh_damping: float,
         setup: RunSetup) -> dict[str, Any]:
    """The parameters of one run (the argument of :func:`~.responses.run_case`), factors as floats
    (length [m], diameter [m], fill [-], mass_flow [kg/s], slosh_damping [-])."""
    return {"length": float(length), "diameter": float(diameter), "fill": float(fill),
            "mass_flow": float(mass_flow), "slosh_damping": float(slosh_damping), "setup": setup.as_dict()}


def run_cases(cases: Sequence[dict[str, Any]], cache_dir: str | os.PathLike[str], executor: str = "local",
              workers: int | None = None, progress: bool = True, desc: str = "runs") -> StudyRun:
    """Records of ``cases`` (see :func:`case`), from the cache where present, else run; extra keys of a
    case other than the factors and ``setup`` (labels such as ``run``) are copied into its row."""
    cache = RunCache(cache_dir)
    keys = [run_key({k: c[k] for k in (*FACTORS, "setup")}) for c in cases]
    records: list[dict[str, Any] | None] = [cache.get(k) for k in keys]
    todo = [i for i, r in enumerate(records) if r is None]

    def store(j: int, record: dict[str, Any]) -> None:
        i = todo[j]
        cache.put(keys[i], record)
        records[i] = record

    tasks = [{k: cases[i][k] for k in (*FACTORS, "setup")} for i in todo]
    run_map(run_case, tasks, executor=executor, workers=workers, progress=progress, on_result=store, desc=desc)
    rows = []
    for c, r, k in zip(cases, records, keys):
        labels = {n: v for n, v in c.items() if n not in (*FACTORS, "setup")}
        r = r or {}
        rows.append({**labels, **{n: r.get(n) for n in RECORD}, "key": k})
    return StudyRun(pd.DataFrame(rows), ran=len(todo), cached=len(cases) - len(todo))
