"""The on-disk timeline cache: a hit gives the same timeline, any change of the vehicle or the arguments
misses, a damaged file is rebuilt, and the cache can be switched off."""

import dataclasses

import numpy as np
import pytest

from lvgym.simulator import build_timeline
from lvgym.simulator import cache, tabulate
from lvgym.vehicle import MassModel, load_vehicle
from lvgym.vehicle.config import VEHICLE_DIR
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


def test_a_hit_is_the_timeline_without_building_it(folder, monkeypatch):
    mm = MassModel(load_vehicle("stratos3"))
    args = ("nonrigid", 40.0, 0.05, None, [-2.0], 50.0)
    built = build_timeline(mm, *args)
    assert len(list(folder.glob("*" + cache.SUFFIX))) == 1
    fresh = build_timeline(mm, *args, cache=False)

    def no_build(*_):
        raise AssertionError("a cache hit must not build the timeline")
    monkeypatch.setattr(tabulate, "_pieces", no_build)
    again = build_timeline(mm, *args)
    _same(again, fresh)
    _same(built, again)


def test_the_key_is_the_vehicle_files_content(folder, tmp_path):
    """A copy of a vehicle file under another name hits its entry; one changed value misses."""
    text = (VEHICLE_DIR / "stratos3.yaml").read_text(encoding="utf-8")
    args = ("rigid", 2.0, 0.05, None, (), np.inf)
    copy, edited = tmp_path / "copy.yaml", tmp_path / "edited.yaml"
    copy.write_text(text, encoding="utf-8")
    assert text.count("fill_ratio: 0.7,") == 1
    edited.write_text(text.replace("fill_ratio: 0.7,", "fill_ratio: 0.69,"), encoding="utf-8")
    shipped = MassModel(load_vehicle("stratos3"))
    assert cache.key(MassModel(load_vehicle(copy)), args) == cache.key(shipped, args)
    assert cache.key(MassModel(load_vehicle(edited)), args) != cache.key(shipped, args)
    a, b = build_timeline(MassModel(load_vehicle(copy)), *args), build_timeline(MassModel(load_vehicle(edited)), *args)
    assert len(list(folder.glob("*" + cache.SUFFIX))) == 2 and a.mass[0] > b.mass[0]


def test_another_vehicle_or_argument_misses(folder):
    a, b = MassModel(slender_vehicle(8.5, 0.30)), MassModel(slender_vehicle(8.5, 0.31))
    args = ("rigid", 2.0, 0.05, None, (), np.inf)
    assert cache.key(a, args) != cache.key(b, args)
    assert cache.key(a, args) != cache.key(a, ("rigid", 2.5, 0.05, None, (), np.inf))
    assert cache.key(a, args) != cache.key(MassModel(a.vehicle, "thesis"), args)
    assert cache.key(a, args) == cache.key(MassModel(slender_vehicle(8.5, 0.30)), args)
    build_timeline(a, "rigid", 2.0)
    build_timeline(b, "rigid", 2.0)
    assert len(list(folder.glob("*" + cache.SUFFIX))) == 2


def test_a_damaged_file_is_rebuilt_and_off_switches_it_off(folder, monkeypatch):
    mm = MassModel(load_vehicle("stratos3"))
    first = build_timeline(mm, "rigid", 3.0)
    (path,) = folder.glob("*" + cache.SUFFIX)
    path.write_bytes(b"not a timeline")
    _same(first, build_timeline(mm, "rigid", 3.0))
    monkeypatch.setenv("LVGYM_CACHE_DIR", "off")
    assert cache.cache_dir() is None
    _same(first, build_timeline(mm, "rigid", 3.0))


def _fly(env_id: str, steps: int = 60) -> np.ndarray:
    import gymnasium as gym

    import lvgym  # noqa: F401
    from lvgym.envs import functional

    functional.cached_vehicle.cache_clear()
    functional.cached_timeline.cache_clear()
    env = gym.make(env_id)
    obs, _ = env.reset(seed=3)
    rows, rng = [obs.astype(float)], np.random.default_rng(11)
    for _ in range(steps):
        obs, reward, term, trunc, _ = env.step(rng.uniform(-0.3, 0.3, 2).astype(np.float32))
        rows.append(np.concatenate([obs.astype(float), [reward, term, trunc]]))
    return np.concatenate(rows + [env.unwrapped.state.sim.x.ravel(), env.unwrapped.state.sim.p.ravel()])


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.parametrize("env_id", ["lvgym/SlenderAscent-v0", "lvgym/SlenderAscent-v1"])
def test_an_episode_from_the_cache_is_the_episode_from_built_tables(folder, env_id):
    """An env whose tables were built (empty cache) and one whose tables are read back fly the same
    seeded episode to the bit."""
    cold = _fly(env_id)
    assert len(list(folder.glob("*" + cache.SUFFIX))) == 1
    warm = _fly(env_id)
    np.testing.assert_array_equal(warm, cold)
