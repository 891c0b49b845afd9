"""An on-disk cache of timelines: building one evaluates the mass model and the beam's modes at about a
thousand times (a second or two); reading it back takes milliseconds.

The key is a SHA-256 of the vehicle's whole content (its frozen dataclasses, pickled, without the name of
the file it was read from: a copy of a file under another name hits the same entry), the mass model's
CG convention, the timeline's arguments, whether layouts are padded, and the source files of the code that
builds a timeline (the vehicle layer, the beam, the dynamics layout and parameter builder, the mode
resampling at the aeroelastic strips, this package's timeline and its build), so an edited vehicle file or an edited
mass model never reads a stale entry. The folder is ``$LVGYM_CACHE_DIR`` (default
``~/.cache/lvgym``), its ``timelines/`` subfolder one file per entry (``SUFFIX``; a JSON header and the raw arrays,
read back in one call), written atomically; ``off``
(or an unwritable folder) switches the cache off. A file that cannot be read is rebuilt.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import pickle
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from lvgym import packing

__all__ = ["SUFFIX", "cache_dir", "cached", "key", "using"]

_ARRAYS = ("t", "params", "hold", "thrust0", "exit_area", "vectored_share", "mass", "cg", "inertia", "slosh_mass", "burning", "stage",
           "sensor_stations", "phi_sensor", "dphi_sensor", "strip_stations", "phi_strip", "dphi_strip", "mode_change_t",
           "mode_transfer")


def cache_dir() -> Path | None:
    """The timelines' folder, or None when the cache is off."""
    root = os.environ.get("LVGYM_CACHE_DIR", "")
    if root.lower() == "off":
        return None
    return (Path(root) if root else Path.home() / ".cache" / "lvgym") / "timelines"


@contextmanager
def using(folder: str | os.PathLike[str]) -> Iterator[None]:
    """``$LVGYM_CACHE_DIR`` set to ``folder`` (or ``"off"``) inside the block, as it was after it."""
    old = os.environ.get("LVGYM_CACHE_DIR")
    os.environ["LVGYM_CACHE_DIR"] = os.fspath(folder)
    try:
        yield
    finally:
        if old is None:
            del os.environ["LVGYM_CACHE_DIR"]
        else:
            os.environ["LVGYM_CACHE_DIR"] = old


@functools.lru_cache(maxsize=1)
def _source_digest() -> str:
    """A digest of the source files that a timeline depends on."""
    root = Path(__file__).resolve().parents[1]                # the package lvgym
    files = sorted([*root.glob("vehicle/*.py"), root / "dynamics" / "layout.py", root / "dynamics" / "model.py",
                    root / "environment" / "aeroelastic.py", root / "packing.py", root / "simulator" / "timeline.py",
                    root / "simulator" / "tabulate.py", root / "simulator" / "tabled.py", Path(__file__)])
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def key(mass_model: Any, args: tuple) -> str:
    """The cache key of a timeline of ``mass_model`` built with ``args``."""
    h = hashlib.sha256()
    vehicle = dataclasses.replace(mass_model.vehicle, source=None)        # the content, not the file's name
    tables = vehicle.tables
    if tables is not None:                                    # the tables' rows, not the files they came from
        bare = [None if tb is None else dataclasses.replace(tb, source=None, lines=None)
                for tb in (tables.mass_properties, *tables.modes)]
        vehicle = dataclasses.replace(vehicle, tables=dataclasses.replace(tables, mass_properties=bare[0],
                                                                          modes=tuple(bare[1:])))
    h.update(pickle.dumps((vehicle, mass_model.cg_convention, args, packing.PADDING), protocol=4))
    h.update(_source_digest().encode())
    return h.hexdigest()[:40]


#: the first 8 bytes of an entry; then the header's length and the arrays' start (8 bytes each,
#: little-endian), the header (JSON: the arrays' names, dtypes, shapes and offsets from that start, and the
#: timeline's other fields), and from the start (a multiple of :data:`_ALIGN`) the arrays' bytes, each
#: block padded to a multiple of :data:`_ALIGN`
_MAGIC = b"LVGYMTL1"
_ALIGN = 64
#: the entries' file name suffix
SUFFIX = ".lvtl"


def _padded(n: int) -> int:
    return -(-n // _ALIGN) * _ALIGN


def _load(path: Path) -> Any:
    """The timeline stored at ``path`` by :func:`_store`: one read, the arrays views of one aligned,
    writable buffer (``np.load`` of a ``.npz`` took 3-5 ms for it: a zip member and a parsed header per array)."""
    from lvgym.dynamics import NonRigidModel

    from .timeline import Timeline
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        buf = np.empty(size, dtype=np.uint8)
        if f.readinto(memoryview(buf)) != size:
            raise ValueError(f"{path}: short read")
    if size < 24 or bytes(buf[:8]) != _MAGIC:
        raise ValueError(f"{path}: not a timeline entry")
    n_head, start = int.from_bytes(bytes(buf[8:16]), "little"), int.from_bytes(bytes(buf[16:24]), "little")
    head = json.loads(bytes(buf[24:24 + n_head]).decode("utf-8"))
    arrays = {}
    for name, dtype, shape, offset in head["arrays"]:
        dt = np.dtype(dtype)
        lo = start + offset
        hi = lo + int(np.prod(shape, dtype=np.int64)) * dt.itemsize
        if lo % _ALIGN or hi > size:
            raise ValueError(f"{path}: array {name!r} outside the file")
        arrays[name] = buf[lo:hi].view(dt).reshape(shape)
    if set(arrays) != set(_ARRAYS):
        raise ValueError(f"{path}: arrays {sorted(arrays)}")
    interval = head["mode_interval"]
    return Timeline(model=head["model"], dynamics=NonRigidModel(*head["sizes"]), stage_names=tuple(head["stage_names"]),
                    slosh_names=tuple(head["slosh_names"]), events=tuple((float(t), e) for t, e in head["events"]),
                    mode_interval=None if interval is None else float(interval), mode_basis=head["mode_basis"],
                    **arrays)


def _store(path: Path, tl: Any) -> None:
    """Write ``tl`` to ``path`` (see :data:`_MAGIC`), atomically: a temporary file renamed."""
    blocks, entries, offset = [], [], 0
    for name in _ARRAYS:
        a = np.ascontiguousarray(getattr(tl, name))
        blocks.append(a)
        entries.append([name, a.dtype.str, list(a.shape), offset])
        offset += _padded(a.nbytes)
    head = {"model": tl.model, "sizes": [tl.dynamics.n_slosh, tl.dynamics.n_modes],
            "stage_names": list(tl.stage_names), "slosh_names": list(tl.slosh_names),
            "events": [[float(t), str(e)] for t, e in tl.events], "mode_basis": tl.mode_basis,
            "mode_interval": None if tl.mode_interval is None else float(tl.mode_interval), "arrays": entries}
    text = json.dumps(head).encode("utf-8")       # floats as their shortest repr: read back to the bit
    start = _padded(24 + len(text))
    parts: list[Any] = [_MAGIC + len(text).to_bytes(8, "little") + start.to_bytes(8, "little") + text
                        + bytes(start - 24 - len(text))]
    for a in blocks:                              # the arrays' own (contiguous) bytes, then their padding
        if a.nbytes:
            parts.append(memoryview(a).cast("B"))
        if _padded(a.nbytes) > a.nbytes:
            parts.append(bytes(_padded(a.nbytes) - a.nbytes))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            _write_all(f, parts)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _write_all(f: Any, parts: list[Any]) -> None:
    """Write the buffers ``parts`` to the binary file ``f`` in order: one gathered write where the system
    has it (``os.writev``), the rest of a short write and any other system by ``f.write``."""
    done = 0
    if hasattr(os, "writev") and len(parts) <= 512:
        f.flush()
        done = os.writev(f.fileno(), parts)
    for part in parts:
        n = len(part) if isinstance(part, bytes) else part.nbytes
        if done >= n:
            done -= n
            continue
        f.write(part[done:] if done else part)
        done = 0


def cached(mass_model: Any, args: tuple, build: Callable[[], Any]) -> Any:
    """The timeline of ``mass_model`` and ``args`` from the cache, else ``build()`` stored in it."""
    folder = cache_dir()
    if folder is None:
        return build()
    path = folder / f"{key(mass_model, args)}{SUFFIX}"
    if path.is_file():
        try:
            return _load(path)
        except Exception:                                 # noqa: BLE001 (a damaged file: build it again)
            pass
    tl = build()
    try:
        _store(path, tl)
    except OSError:                                       # a read-only folder: no cache, no error
        pass
    return tl
