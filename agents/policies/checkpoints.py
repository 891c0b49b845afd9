"""A training run's checkpoints: their names (``checkpoints/step_<N>``, N the env steps in 12 digits), the complete
ones (their JSON exists, and their ``.zip``) and the removal of a half-written one. The training callbacks write
them (:mod:`lvgym.agents.training.callbacks` lists the files of one); the loader of a run folder flies the newest
when the run has no best or final model (:func:`lvgym.agents.policies.saved.resolve_model_path`). A saved policy's
files are :func:`lvgym.agents.policies.saved.policy_files` of the stem: ``<stem>.zip`` the model, ``<stem>.json``
its record, written last."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from lvgym.benchmark.results import remove_stale_temporaries

__all__ = ["checkpoint_stem", "clean_incomplete", "latest_checkpoint", "list_checkpoints"]

_STEM = re.compile(r"^step_(\d{12})$")


def checkpoint_stem(folder: Path, step: int) -> Path:
    return folder / f"step_{int(step):012d}"


def list_checkpoints(folder: str | Path) -> list[tuple[int, Path]]:
    """Complete checkpoints (their JSON exists) of ``folder``, oldest first: ``(step, stem)``."""
    folder = Path(folder)
    out = []
    if folder.is_dir():
        for p in folder.glob("step_*.json"):
            m = _STEM.match(p.stem)
            if m and p.with_suffix(".zip").is_file():
                out.append((int(m.group(1)), p.with_suffix("")))
    return sorted(out)


def latest_checkpoint(folder: str | Path) -> tuple[Path, dict[str, Any]] | None:
    """``(zip path, state)`` of the newest complete checkpoint of ``folder``, or None."""
    ckpts = list_checkpoints(folder)
    if not ckpts:
        return None
    stem = ckpts[-1][1]
    return stem.with_suffix(".zip"), json.loads(stem.with_suffix(".json").read_text(encoding="utf-8"))


def clean_incomplete(folder: str | Path) -> list[Path]:
    """Remove the files of checkpoints whose JSON was never written (a run killed while saving) and
    stale temporaries; returns what was removed."""
    folder = Path(folder)
    removed = remove_stale_temporaries(folder)
    complete = {stem.name for _, stem in list_checkpoints(folder)}
    for p in sorted(folder.glob("step_*")) if folder.is_dir() else []:
        stem = p.name[:len("step_") + 12]
        if _STEM.match(stem) and stem not in complete:
            p.unlink()
            removed.append(p)
    return removed
