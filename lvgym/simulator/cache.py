"""An on-disk cache of timelines: building one evaluates the mass model and the beam's modes at about a
thousand times (a second or two); reading it back takes milliseconds.

The key is a SHA-256 of the vehicle's whole content (its frozen dataclasses, pickled, without the name of
the file it was read from: a copy of a file under another name hits the same entry), the mass model's
CG convention, the timeline's arguments, whether layouts are padded, and the source files of the code that
builds a timeline (the vehicle layer, the beam, the dynamics layout and parameter builder, the mode
resampling at the aeroelastic strips, this package's timeline), so an edited vehicle file or an edited
mass model never reads a stale entry. The folder is ``$LVGYM_CACHE_DIR`` (default
``~/.cache/lvgym``), its ``timelines/`` subfolder one ``.npz`` file per entry, written atomically; ``off``
(or an unwritable folder) switches the cache off. A file that cannot be read is rebuilt.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from lvgym import packing

__all__ = ["cache_dir", "cached", "key", "using"]

_ARRAYS = ("t", "params", "hold", "thrust0", "exit_area", "mass", "cg", "inertia", "slosh_mass", "burning", "stage",
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
    import lvgym
    root = Path(lvgym.__file__).parent
    files = sorted([*root.glob("vehicle/*.py"), root / "dynamics" / "layout.py", root / "dynamics" / "model.py",
                    root / "environment" / "aeroelastic.py", root / "packing.py", root / "simulator" / "timeline.py",
                    Path(__file__)])
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def key(mass_model: Any, args: tuple) -> str:
    """The cache key of a timeline of ``mass_model`` built with ``args``."""
    h = hashlib.sha256()
    vehicle = dataclasses.replace(mass_model.vehicle, source=None)        # the content, not the file's name
    h.update(pickle.dumps((vehicle, mass_model.cg_convention, args, packing.PADDING), protocol=4))
    h.update(_source_digest().encode())
    return h.hexdigest()[:40]


def _load(path: Path) -> Any:
    from lvgym.dynamics import NonRigidModel

    from .timeline import Timeline
    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in _ARRAYS}
        meta = [str(x) for x in f["meta"]]
        n_slosh, n_modes = (int(v) for v in f["sizes"])
        event_t = f["event_t"]
        interval = float(f["mode_interval"])
        basis = str(f["mode_basis"])
    model, n_stage = meta[0], int(meta[1])
    stage_names, rest = tuple(meta[2:2 + n_stage]), meta[2 + n_stage:]
    n_names = int(rest[0])
    slosh_names, event_text = tuple(rest[1:1 + n_names]), rest[1 + n_names:]
    return Timeline(model=model, dynamics=NonRigidModel(n_slosh, n_modes), stage_names=stage_names,
                    slosh_names=slosh_names, events=tuple((float(t), e) for t, e in zip(event_t, event_text)),
                    mode_interval=None if np.isnan(interval) else interval, mode_basis=basis, **arrays)


def _store(path: Path, tl: Any) -> None:
    meta = [tl.model, str(len(tl.stage_names)), *tl.stage_names, str(len(tl.slosh_names)), *tl.slosh_names,
            *(e for _, e in tl.events)]
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, meta=np.array(meta), sizes=np.array([tl.dynamics.n_slosh, tl.dynamics.n_modes]),
                     event_t=np.array([t for t, _ in tl.events], dtype=float),
                     mode_interval=np.nan if tl.mode_interval is None else tl.mode_interval,
                     mode_basis=np.array(tl.mode_basis), **{k: getattr(tl, k) for k in _ARRAYS})
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def cached(mass_model: Any, args: tuple, build: Callable[[], Any]) -> Any:
    """The timeline of ``mass_model`` and ``args`` from the cache, else ``build()`` stored in it."""
    folder = cache_dir()
    if folder is None:
        return build()
    path = folder / f"{key(mass_model, args)}.npz"
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
