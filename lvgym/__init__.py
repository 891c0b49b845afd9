"""lvgym: a Gymnasium benchmark for thrust-vector control of flexible, sloshing launch vehicles.

``import lvgym`` registers the environments with Gymnasium by name (their modules load on
``gymnasium.make``), so the physics layers can be imported without Gymnasium's machinery.

The benchmark's own envs, as a suite's condition flies them (wind, gust, dispersions and all)::

    env = lvgym.make_env("smile-v1", model="nonrigid")                # gymnasium.Env
    venv = lvgym.make_vec_env("smile-v1", "rigid", num_envs=8)        # gymnasium VectorEnv, row i = seed + i
    venv = lvgym.make_vec_env("smile-v1", "rigid", num_envs=8, api="sb3", seed=0)   # the same rows, an SB3 VecEnv
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"

#: the one table of env ids: id -> the env class, as its import path (``gymnasium.make`` imports it on
#: first use, so ``import lvgym`` stays light). Each id's ``vector_entry_point`` is :func:`make_vector`
#: with the id; ``lvgym.envs.ENVS`` holds the classes themselves.
ENV_IDS = {
    "lvgym/SmileAscent-v0": "lvgym.envs.ascent:SmileAscentEnv",
    "lvgym/SmileAscent-v1": "lvgym.envs.ascent:SmileAscentV1Env",
    "lvgym/StratosIII-v0": "lvgym.envs.ascent:StratosIIIEnv",
    "lvgym/SlenderAscent-v0": "lvgym.envs.ascent:SlenderAscentEnv",
    "lvgym/StratosIII-v1": "lvgym.envs.ascent:StratosIIIV1Env",
    "lvgym/SlenderAscent-v1": "lvgym.envs.ascent:SlenderAscentV1Env",
}


def env_class(env_id: str) -> type:
    """The env class of a registered id (of :data:`ENV_IDS`; a ``ValueError`` names the ids otherwise)."""
    import importlib

    if env_id not in ENV_IDS:
        from lvgym.errors import ConfigError, did_you_mean

        raise ConfigError("env_id", env_id, f"one of {sorted(ENV_IDS)}{did_you_mean(env_id, ENV_IDS)}")
    module, _, name = ENV_IDS[env_id].partition(":")
    return getattr(importlib.import_module(module), name)


def make_vector(env_id: str, num_envs: int = 1, **options: Any) -> Any:
    """The batched Gymnasium ``VectorEnv`` of ``num_envs`` rows of ``env_id`` with ``options``
    (:class:`lvgym.envs.AscentVectorEnv`): every id's ``vector_entry_point``, i.e. what
    ``gymnasium.make_vec(env_id, num_envs, vectorization_mode="vector_entry_point", **options)`` builds."""
    from lvgym.envs.vector import AscentVectorEnv

    return AscentVectorEnv(env_class(env_id), num_envs, **options)


def make_env(suite: str, model: str = "nonrigid", **overrides: Any) -> Any:
    """The env of the condition of benchmark suite ``suite`` flown with flight model ``model``: the very
    env the benchmark flies (:meth:`lvgym.benchmark.Condition.make_env`: wind, gust, dispersions, sensors
    and mission time of the suite), with env keywords ``overrides`` added or replaced. Reset it with a
    seed of the suite's seed sets to fly the benchmark's episode of that seed. A bad suite or model raises
    a one-line ``ConfigError`` naming what is allowed."""
    from lvgym.benchmark.suites import condition

    return condition(suite, model, **overrides).make_env()


def make_vec_env(suite: str, model: str = "nonrigid", num_envs: int = 1, *, api: str = "gymnasium",
                 seed: int | None = None, **overrides: Any) -> Any:
    """:func:`make_env`'s env batched, ``num_envs`` rows over one simulator
    (:meth:`lvgym.benchmark.Condition.make_vec_env`). ``api="gymnasium"`` (default): a Gymnasium ``VectorEnv``
    whose ``reset(seed=s)`` seeds row ``i`` with ``s + i``, so row ``i`` flies the benchmark's episode of seed
    ``s + i`` (a finished row restarts at the next step). ``api="sb3"``: the same rows as a stable-baselines3
    ``VecEnv`` (:class:`lvgym.envs.sb3.AscentSB3VecEnv`, the ``train`` extra), for a pipeline of your own; its
    ``reset()`` takes no seed, so ``seed`` (or ``venv.seed(s)`` before a reset) seeds row ``i`` with ``seed + i``,
    and a finished row restarts within the step (its last observation in ``infos[i]["terminal_observation"]``)."""
    from lvgym.benchmark.suites import condition

    return condition(suite, model, **overrides).make_vec_env(num_envs, api=api, seed=seed)


def register_envs() -> None:
    """Register the envs with Gymnasium (idempotent; nothing happens without Gymnasium installed)."""
    try:
        import gymnasium as gym
    except ImportError:  # pragma: no cover - gymnasium is a dependency; the physics does not need it
        return
    import functools

    for env_id, entry in ENV_IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry, vector_entry_point=functools.partial(make_vector, env_id))


register_envs()

__all__ = ["ENV_IDS", "env_class", "make_env", "make_vec_env", "make_vector", "register_envs"]
