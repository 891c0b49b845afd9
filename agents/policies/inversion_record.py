"""A learned disturbance observer's record: the ``.json`` beside its ``.npz`` that says how the law flies it and
how it was made (the shipped ``agents/trained/inversion_id_*.json``, and those ``lvgym train --recipe
teacher-student`` writes), and the policy it names.

A record holds the env the observer was trained on (``env``: :func:`lvgym.agents.policies.inversion.env_record`, which
the policy checks), the options the law flies (``lead``, ``law``, ``average``, ``ignition``,
``ignition_share``: :func:`flown`; absent ones at their defaults), the training command and its validation,
and the observer file's SHA-256 (``sha256``); ``observer`` names that file relative to the record (absent:
the record's own stem with ``.npz``).

:func:`from_record` is the policy a record names; ``lvgym evaluate --policies path/to/record.json`` flies it
(the loader ``lvgym.agents`` registers for ``.json`` files), as ``lvgym margins`` does.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError

from .inversion import InversionPolicy, from_file

__all__ = ["OPTIONS", "flown", "from_record", "observer_file", "read_record", "sha256", "write_record"]

#: the options a record may set for the law, and their defaults
OPTIONS = {"lead": 0, "law": None, "average": 1, "ignition": 0.0, "ignition_share": 1.0}


def flown(lead: int = 0, law: dict[str, list[float]] | None = None, ignition: float = 0.0, average: int = 1,
          ignition_share: float = 1.0) -> dict[str, Any]:
    """The options a policy flies (:func:`lvgym.agents.policies.inversion.from_file`'s), those at their defaults left
    out but the lead (a record's keys; the share only with an ``ignition``)."""
    return {"lead": int(lead), **({"law": law} if law else {}), **({"ignition": float(ignition)} if ignition else {}),
            **({"average": int(average)} if average > 1 else {}),
            **({"ignition_share": float(ignition_share)} if ignition and ignition_share != 1.0 else {})}


def sha256(path: str | Path) -> str:
    """The SHA-256 of the file at ``path`` (hex)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def write_record(path: str | Path, record: dict[str, Any]) -> Path:
    """Write ``record`` to ``path`` as the shipped records are written (keys sorted, one space of indent)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return path


def read_record(path: str | Path) -> dict[str, Any]:
    """The record at ``path``, refused by name when it is not an observer's record."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no record file {str(path)!r}")
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ConfigError("record", str(path), f"a JSON file ({exc})") from None
    missing = [k for k in ("env", "policy") if not isinstance(record, dict) or k not in record]
    if missing:
        raise ConfigError("record", str(path), f"a disturbance observer's record with {missing} "
                                               "(lvgym train --recipe teacher-student writes one)")
    return record


def observer_file(path: str | Path, record: dict[str, Any]) -> Path:
    """The observer file of the record at ``path``: its ``observer`` relative to the record's folder, else the
    record's stem with ``.npz``."""
    path = Path(path)
    return path.parent / record["observer"] if record.get("observer") else path.with_suffix(".npz")


def from_record(env: Any, path: str | Path, name: str | None = None) -> InversionPolicy:
    """The policy the record at ``path`` names: its observer flown on ``env`` (refused unless it is the env of
    the record's ``env``) with the record's options (:data:`OPTIONS`), named ``name`` (default: the record's
    ``policy``); the observer file must be the one its ``sha256`` names."""
    record = read_record(path)
    weights = observer_file(path, record)
    if not weights.is_file():
        raise FileNotFoundError(f"the record {str(path)!r} names the observer {str(weights)!r}, which is missing")
    if record.get("sha256") and sha256(weights) != record["sha256"]:
        raise ConfigError("sha256", sha256(weights), f"{record['sha256']} (the record's): {weights} is another file")
    options = {k: record.get(k, default) for k, default in OPTIONS.items()}
    return from_file(env, weights, name=name or str(record["policy"]), trained=record["env"],
                     lead=int(options["lead"]), law=options["law"], average=int(options["average"]),
                     ignition=float(options["ignition"]), ignition_share=float(options["ignition_share"]))


from_record.kind = "learned"  # type: ignore[attr-defined]
