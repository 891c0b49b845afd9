"""A training run's folder: its ``config.yaml``, the provenance recorded with it, and SB3's logger.

Used by ``train.py`` (docs/training.md, "The run folder"). ``config.yaml`` is written atomically
(:func:`lvgym.benchmark.results.atomic_write_text`) with plain YAML types.
"""

from __future__ import annotations

import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

import yaml

__all__ = ["create_run", "make_logger", "provenance", "write_yaml"]

ROOT = Path(__file__).resolve().parents[2]


def provenance() -> dict[str, Any]:
    """Versions, git commit (of the repository holding ``agents/``) and whether the work tree had changes,
    the host and the command line."""
    import gymnasium
    import stable_baselines3
    import torch

    import lvgym

    def git(*cmd: str) -> str:
        try:
            return subprocess.run(["git", *cmd], cwd=ROOT, capture_output=True, text=True, timeout=10).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return ""

    try:
        from importlib.metadata import version

        lv = version("lvgym")
    except Exception:  # noqa: BLE001
        lv = getattr(lvgym, "__version__", "unknown")
    return {"lvgym_version": lv, "git_commit": git("rev-parse", "HEAD") or None,
            "git_dirty": bool(git("status", "--porcelain", "--untracked-files=no")),
            "stable_baselines3": stable_baselines3.__version__, "torch": torch.__version__,
            "gymnasium": gymnasium.__version__, "python": platform.python_version(),
            "host": platform.node(), "command": [sys.executable, *sys.argv]}


def make_logger(run_dir: Path, start: int, verbose: int) -> Any:
    """SB3's logger of a run segment starting at step ``start``: TensorBoard under ``tb/``,
    ``progress_<start>.csv``, and SB3's tables on stdout if ``verbose``."""
    from stable_baselines3.common.logger import CSVOutputFormat, HumanOutputFormat, Logger, TensorBoardOutputFormat

    formats: list[Any] = [TensorBoardOutputFormat(str(run_dir / "tb")),
                          CSVOutputFormat(str(run_dir / f"progress_{start:012d}.csv"))]
    if verbose:
        formats.append(HumanOutputFormat(sys.stdout))
    return Logger(str(run_dir), formats)


def _plain(x: Any) -> Any:
    """``x`` with tuples as lists and str subclasses (enums) as str, for ``yaml.safe_dump``."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, str):
        return str(x)
    return x


def write_yaml(path: Path, data: dict[str, Any]) -> None:
    """``data`` as YAML at ``path``, atomically."""
    from lvgym.benchmark.results import atomic_write_text

    atomic_write_text(path, yaml.safe_dump(_plain(data), sort_keys=False, width=120))


def create_run(config: dict[str, Any], run_dir: Path) -> None:
    """Write the run's ``config.yaml`` (a new run: make its folder; a resumed one: its new target)."""
    run_dir.mkdir(parents=True, exist_ok=True)
    write_yaml(run_dir / "config.yaml", config)
