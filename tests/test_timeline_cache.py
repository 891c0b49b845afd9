"""The on-disk timeline cache: a hit gives the same timeline, any change of the vehicle or the arguments
misses, a damaged file is rebuilt, and the cache can be switched off."""

import dataclasses
import time

import numpy as np
import pytest

from lvgym.simulator import build_timeline
from lvgym.simulator import cache
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.slender import slender_vehicle


def _same(a, b) -> None:
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y), f.name
        elif f.name == "dynamics":
            assert (x.n_slosh, x.n_modes) == (y.n_slosh, y.n_modes)
        else:
            assert x == y, f.name


@pytest.fixture()
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv("LVGYM_CACHE_DIR", str(tmp_path))
    return tmp_path / "timelines"


def test_a_hit_is_the_timeline_and_fast(folder):
    mm = MassModel(load_vehicle("stratos3"))
    args = ("nonrigid", 40.0, 0.05, None, (-2.0,), 50.0)
    t0 = time.perf_counter()
    built = build_timeline(mm, *args[:4], list(args[4]), args[5])
    t_build = time.perf_counter() - t0
    assert len(list(folder.glob("*.npz"))) == 1
    t0 = time.perf_counter()
    again = build_timeline(mm, *args[:4], list(args[4]), args[5])
    t_hit = time.perf_counter() - t0
    _same(again, build_timeline(mm, *args[:4], list(args[4]), args[5], cache=False))
    _same(built, again)
    assert t_hit < 0.1 * t_build


def test_another_vehicle_or_argument_misses(folder):
    a, b = MassModel(slender_vehicle(8.5, 0.30)), MassModel(slender_vehicle(8.5, 0.31))
    args = ("rigid", 2.0, 0.05, None, (), np.inf)
    assert cache.key(a, args) != cache.key(b, args)
    assert cache.key(a, args) != cache.key(a, ("rigid", 2.5, 0.05, None, (), np.inf))
    assert cache.key(a, args) != cache.key(MassModel(a.vehicle, "thesis"), args)
    assert cache.key(a, args) == cache.key(MassModel(slender_vehicle(8.5, 0.30)), args)
    build_timeline(a, "rigid", 2.0)
    build_timeline(b, "rigid", 2.0)
    assert len(list(folder.glob("*.npz"))) == 2


def test_a_damaged_file_is_rebuilt_and_off_switches_it_off(folder, monkeypatch):
    mm = MassModel(load_vehicle("stratos3"))
    first = build_timeline(mm, "rigid", 3.0)
    (path,) = folder.glob("*.npz")
    path.write_bytes(b"not a timeline")
    _same(first, build_timeline(mm, "rigid", 3.0))
    monkeypatch.setenv("LVGYM_CACHE_DIR", "off")
    assert cache.cache_dir() is None
    _same(first, build_timeline(mm, "rigid", 3.0))
