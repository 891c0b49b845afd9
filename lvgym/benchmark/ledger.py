"""The ledger of test flights: every flight of a policy on test seeds, one JSON line per call.

A test seed that has been looked at many times stops being a test: a design tuned while its author watched the
test table has been selected on it. The ledger makes that history visible. Every call that flies test seeds
(:func:`~.runner.evaluate` with ``seed_set="test"``, :func:`~.margins.run_margins` on test seeds, ``lvgym
headline fly``) appends one line (:func:`log_flight`): the UTC time, the git commit of the checkout (or the
installed version), the command and its purpose, the suites, models, policies, the seed ranges and their
count. ``lvgym ledger`` prints, per policy, how often it has flown on test seeds and on which blocks
(:func:`per_policy`).

Where the ledger lives (:func:`ledger_path`): the environment variable :data:`ENV_VAR` names a file; else, run
from the repository's checkout, the project's committed ledger ``docs/data/test-flights.jsonl``; else a file
of the user's (``$XDG_DATA_HOME/lvgym/test-flights.jsonl``, default ``~/.local/share``). The test suite sets
the variable (tests/conftest.py), so that no test writes the committed file.

The committed ledger begins with the history that could be reconstructed (lines with ``"history": true``):
the 50 seeds 10,000-10,049 flown throughout development (how often is not recorded: many times, by every
policy of the time) and 150 further test seeds flown once by a re-flight study (their range not recorded).
"""

from __future__ import annotations

import datetime as dt
import json
import os
import subprocess
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .suites import N_TEST_SEEDS, TEST_SEED0

__all__ = ["ENV_VAR", "LEDGER_IN_REPO", "blocks", "checkout", "ledger_path", "log_flight", "per_policy", "read",
           "source", "table", "test_seeds"]

#: the environment variable that names the ledger file (it overrides every default)
ENV_VAR = "LVGYM_TEST_FLIGHTS"
#: the project's ledger, relative to the repository's root
LEDGER_IN_REPO = Path("docs") / "data" / "test-flights.jsonl"


def checkout() -> Path | None:
    """The root of the repository this package runs from (its ``lvgym`` folder beside ``.git`` and
    ``docs/data``), or ``None`` when it runs from an installed wheel."""
    root = Path(__file__).resolve().parents[2]
    return root if (root / ".git").exists() and (root / LEDGER_IN_REPO).parent.is_dir() else None


def ledger_path() -> Path:
    """The ledger file written and read (module docstring: :data:`ENV_VAR`, else the checkout's, else the user's)."""
    if os.environ.get(ENV_VAR):
        return Path(os.environ[ENV_VAR])
    root = checkout()
    if root is not None:
        return root / LEDGER_IN_REPO
    base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "lvgym" / "test-flights.jsonl"


def source() -> dict[str, Any]:
    """What flew: ``commit`` (the checkout's git commit, and ``dirty`` when it has uncommitted changes) or
    ``version`` (the installed package's)."""
    root = checkout()
    if root is not None:
        try:
            head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10)
            dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                                   capture_output=True, text=True, timeout=10)
            if head.returncode == 0:
                return {"commit": head.stdout.strip(), "dirty": bool(dirty.stdout.strip())}
        except (OSError, subprocess.SubprocessError):
            pass
    from importlib.metadata import PackageNotFoundError, version

    try:
        return {"version": version("lvgym")}
    except PackageNotFoundError:
        import lvgym

        return {"version": getattr(lvgym, "__version__", "unknown")}


def blocks(seeds: Iterable[int]) -> list[list[int]]:
    """The seeds as sorted ranges of consecutive seeds ``[first, last]`` (both included)."""
    out: list[list[int]] = []
    for s in sorted({int(x) for x in seeds}):
        if out and s == out[-1][1] + 1:
            out[-1][1] = s
        else:
            out.append([s, s])
    return out


def test_seeds(seeds: Iterable[int]) -> list[int]:
    """The test seeds among ``seeds``: :data:`~.suites.TEST_SEED0` and the :data:`~.suites.N_TEST_SEEDS` after it
    (not the training seeds beyond them, :data:`~.suites.TRAINING_SEEDS`)."""
    return [int(s) for s in seeds if TEST_SEED0 <= int(s) < TEST_SEED0 + N_TEST_SEEDS]


def _command() -> str:
    argv = [Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python", *sys.argv[1:3]]
    return " ".join(a for a in argv if a and not a.startswith("-"))


def log_flight(seeds: Iterable[int], suites: Sequence[str], models: Sequence[str], policies: Sequence[str],
               purpose: str | None = None, command: str | None = None, path: str | Path | None = None) -> Path | None:
    """Append one line for a flight of ``policies`` on the test seeds among ``seeds`` (nothing without any):
    ``utc``, the :func:`source`, ``command`` (default: the running command's name), ``purpose`` (default: the
    command), ``suites``, ``models``, ``policies``, ``seeds`` (:func:`blocks`) and ``n_seeds``. Returns the
    ledger's path (``path``, default :func:`ledger_path`), or ``None`` when no test seed flew."""
    mine = test_seeds(seeds)
    if not mine:
        return None
    command = command or _command()
    line = {"utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"), **source(), "command": command,
            "purpose": purpose or command, "suites": list(dict.fromkeys(suites)),
            "models": list(dict.fromkeys(models)), "policies": list(dict.fromkeys(policies)), "seeds": blocks(mine),
            "n_seeds": len(set(mine))}
    target = Path(path) if path is not None else ledger_path()
    target.parent.mkdir(parents=True, exist_ok=True)
    with open(target, "a", encoding="utf-8") as f:      # one short append: whole lines, even from two processes
        f.write(json.dumps(line, sort_keys=False) + "\n")
    return target


def read(path: str | Path | None = None) -> list[dict[str, Any]]:
    """The ledger's lines (``path``, default :func:`ledger_path`; none when the file does not exist)."""
    target = Path(path) if path is not None else ledger_path()
    if not target.exists():
        return []
    return [json.loads(x) for x in target.read_text(encoding="utf-8").splitlines() if x.strip()]


def _block_text(line: Mapping[str, Any]) -> str:
    if line.get("seeds"):
        return ", ".join(f"{a:,}-{b:,}" if a != b else f"{a:,}" for a, b in line["seeds"])
    return f"{line.get('n_seeds', '?')} seeds, range not recorded"


def per_policy(lines: Sequence[Mapping[str, Any]], only: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """Per policy (in order of first appearance; ``only``: these, in this order): ``policy``, ``calls`` (the
    logged calls that flew it), ``history`` (the reconstructed lines that apply to every policy of the time,
    :func:`read`), ``blocks`` (each block of test seeds it flew with how many calls flew it) and
    ``last_utc``."""
    shared = [ln for ln in lines if ln.get("policies") is None]
    names = list(dict.fromkeys(p for ln in lines for p in (ln.get("policies") or ())))
    names = list(only) if only is not None else names
    out = []
    for name in names:
        mine = [ln for ln in lines if name in (ln.get("policies") or ())]
        count: dict[str, int] = {}
        for ln in mine:
            count[_block_text(ln)] = count.get(_block_text(ln), 0) + 1
        out.append({"policy": name, "calls": len(mine), "history": [_block_text(ln) + ": " + ln.get("flights", "")
                                                                     for ln in shared],
                    "blocks": count, "last_utc": max((ln.get("utc") or "" for ln in mine), default="")})
    return out


def table(lines: Sequence[Mapping[str, Any]], only: Sequence[str] | None = None) -> str:
    """:func:`per_policy` as a Markdown table, the history lines under it."""
    rows = per_policy(lines, only)
    out = ["| policy | logged calls on test seeds | blocks flown (calls) | last |", "|---|---:|---|---|"]
    for r in rows:
        flown = "; ".join(f"{b} ({n})" for b, n in r["blocks"].items()) or "-"
        out.append(f"| `{r['policy']}` | {r['calls']} | {flown} | {r['last_utc'] or '-'} |")
    history = [ln for ln in lines if ln.get("policies") is None]
    if history:
        out += ["", "Before the ledger, every policy of the time flew (the history the ledger starts with):", ""]
        out += [f"- {_block_text(ln)}: {ln.get('flights', '')} ({ln.get('purpose', '')})" for ln in history]
    return "\n".join(out) + "\n"
