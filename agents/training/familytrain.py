"""Training on the launcher family (``train.py --suite family-v2 --family-vehicles N``): the rows of one
stable-baselines3 ``VecEnv`` spread over the family's first ``N`` **train** vehicles.

The family's test vehicles are its suites' conditions and its validation vehicles are what training selects
on (:func:`lvgym.benchmark.suites.family_validation_suite`); the train vehicles are the first ``N`` seeds of
the generator's train split (:data:`lvgym.vehicle.generator.SPLITS`) that pass the family's checks, written
by :func:`lvgym.baselines.family.write_family` (the same function that wrote the shipped vehicles) into
``<lvgym cache>/family/`` and read back by path. Each vehicle is one batched lvgym VecEnv (its own
simulator: the vehicles differ in their modes, stages and tables) wrapped as a run wraps its env (loop
dispersion, residual on the baseline designed for that vehicle), and :class:`ConcatVecEnv` joins them, the
rows of vehicle ``k`` after those of vehicle ``k - 1``, its row ``i`` seeded ``seed + (first row of k) + i``.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

__all__ = ["ConcatVecEnv", "concat_venv", "family_folder", "row_split", "train_vehicle_files"]


def family_folder() -> Path:
    """Where the train vehicles are written: ``$LVGYM_CACHE_DIR/family`` (default ``~/.cache/lvgym/family``),
    a temporary folder when the cache is off."""
    from lvgym.simulator.cache import cache_dir

    timelines = cache_dir()                          # the same root and switch as the timelines' cache
    return Path(tempfile.mkdtemp(prefix="lvgym-family-")) if timelines is None else timelines.parent / "family"


def train_vehicle_files(count: int, folder: str | Path | None = None) -> list[Path]:
    """The files of the family's first ``count`` train vehicles (written again on each call: the generator
    is deterministic, so a file's content is its seed's)."""
    from lvgym.baselines.family import write_family

    return write_family("train", int(count), family_folder() if folder is None else folder)


def row_split(n_envs: int, parts: int) -> list[int]:
    """``n_envs`` rows shared by ``parts`` vehicles as evenly as can be, the first ones taking one more:
    ``row_split(10, 4) == [3, 3, 2, 2]``. Every vehicle needs a row."""
    if not 1 <= parts <= n_envs:
        from lvgym.errors import ConfigError

        raise ConfigError("--family-vehicles", parts, f"1 .. the run's rows (--n-envs {n_envs})")
    base, extra = divmod(int(n_envs), int(parts))
    return [base + (k < extra) for k in range(parts)]


class ConcatVecEnv(VecEnv):
    """Several ``VecEnv`` with the same spaces as one: their rows in order. ``reset_infos`` and the step's
    infos are the parts' in that order; ``seed(s)`` seeds part ``k`` with ``s`` plus its first row."""

    def __init__(self, parts: Sequence[VecEnv]) -> None:
        if not parts:
            raise ValueError("ConcatVecEnv needs at least one VecEnv")
        first = parts[0]
        for p in parts[1:]:
            if p.observation_space != first.observation_space or p.action_space != first.action_space:
                raise ValueError(f"ConcatVecEnv: spaces differ ({p.observation_space}, {p.action_space} against "
                                 f"{first.observation_space}, {first.action_space})")
        self.parts = list(parts)
        self.starts = np.cumsum([0] + [p.num_envs for p in self.parts])
        super().__init__(int(self.starts[-1]), first.observation_space, first.action_space)

    def _rows(self, k: int) -> slice:
        return slice(int(self.starts[k]), int(self.starts[k + 1]))

    def reset(self) -> np.ndarray:
        obs = [p.reset() for p in self.parts]
        self.reset_infos = [info for p in self.parts for info in p.reset_infos]
        return np.concatenate(obs)

    def step_async(self, actions: np.ndarray) -> None:
        for k, p in enumerate(self.parts):
            p.step_async(actions[self._rows(k)])

    def step_wait(self):
        out = [p.step_wait() for p in self.parts]
        self.reset_infos = [info for p in self.parts for info in p.reset_infos]
        obs, reward, done = (np.concatenate([o[j] for o in out]) for j in range(3))
        return obs, reward, done, [info for o in out for info in o[3]]

    def seed(self, seed: int | None = None) -> list[int | None]:
        return [s for k, p in enumerate(self.parts)
                for s in p.seed(None if seed is None else seed + int(self.starts[k]))]

    def close(self) -> None:
        for p in self.parts:
            p.close()

    def _by_part(self, indices: Any) -> list[tuple[int, list[int]]]:
        """``indices`` (None: all) as (part, its local rows), in the order given."""
        out: list[tuple[int, list[int]]] = []
        for i in self._get_indices(indices):
            k = int(np.searchsorted(self.starts, i, side="right") - 1)
            if out and out[-1][0] == k:
                out[-1][1].append(i - int(self.starts[k]))
            else:
                out.append((k, [i - int(self.starts[k])]))
        return out

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [v for k, rows in self._by_part(indices) for v in self.parts[k].get_attr(attr_name, rows)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        for k, rows in self._by_part(indices):
            self.parts[k].set_attr(attr_name, value, rows)

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kwargs: Any) -> list[Any]:
        return [v for k, rows in self._by_part(indices)
                for v in self.parts[k].env_method(method_name, *args, indices=rows, **kwargs)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [v for k, rows in self._by_part(indices) for v in self.parts[k].env_is_wrapped(wrapper_class, rows)]


def concat_venv(make_part: Callable[[str, int, int], VecEnv], vehicles: Sequence[str | Path], n_envs: int,
                seed: int) -> ConcatVecEnv:
    """The rows of ``n_envs`` over ``vehicles`` (:func:`row_split`), part ``k`` built by ``make_part(vehicle,
    rows, first seed)``."""
    parts, start = [], 0
    for vehicle, rows in zip(vehicles, row_split(n_envs, len(vehicles))):
        parts.append(make_part(str(vehicle), rows, seed + start))
        start += rows
    return ConcatVecEnv(parts)
