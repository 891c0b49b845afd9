"""Gymnasium environments of lvgym, registered on ``import lvgym``:

- ``lvgym/SmileAscent-v0`` (:class:`~.ascent.SmileAscentEnv`): SMILE's first-stage flight, TVC;
- ``lvgym/SmileAscent-v1`` (:class:`~.ascent.SmileAscentV1Env`): SMILE as protocol v1 flies it;
- ``lvgym/StratosIII-v0`` (:class:`~.ascent.StratosIIIEnv`): Stratos III through its thrust drop, roll RCS;
- ``lvgym/SlenderAscent-v0`` (:class:`~.ascent.SlenderAscentEnv`): the parametric L/D vehicle;
- ``lvgym/StratosIII-v1``, ``lvgym/SlenderAscent-v1``: Stratos III with TVC and the slender vehicle with
  protocol v1's physics and timing.

Each is a thin adapter over the functional env :class:`~.functional.AscentFuncEnv` (explicit state and
parameters, batched over rows); each has a native batched ``VectorEnv`` as its ``vector_entry_point``
(``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point", **options)``, which calls
:func:`lvgym.make_vector` with the id; the ids and their classes are one table, :data:`lvgym.ENV_IDS`) and an SB3
``VecEnv`` adapter, :func:`make_sb3_vec_env`, over the same batched code. ``env.unwrapped.get_state()``
and ``set_state(state)`` capture and restore an episode (:mod:`.snapshot`).
"""

from __future__ import annotations

from typing import Any

from lvgym import ENV_IDS, env_class, make_vector

from .ascent import (AscentEnv, SlenderAscentEnv, SlenderAscentV1Env, SmileAscentEnv, SmileAscentV1Env,
                     StratosIIIEnv, StratosIIIV1Env)
from .functional import AscentFuncEnv, AscentParams, AscentState
from .layouts import OBS_FLIGHT, OBS_SENSORS, OBS_STATE, OBSERVATIONS, REWARD_TERMS, TASK
from .snapshot import EpisodeState
from .dispersions import DISPERSIONS
from .options import (ActuatorOptions, AtmosphereOptions, CoastOptions, DispersionOptions, GuidanceOptions, LaunchOptions,
                      LimitOptions, PhysicsOptions, RewardOptions, SensorOptions, TimingOptions)
from .presets import FLIGHT_DEFAULTS, FLIGHT_SENSORS
from .spec import RANDOMIZE, WIND_TIERS, TaskSpec
from .vector import AscentVectorEnv

#: env id -> env class, for every id of the one table :data:`lvgym.ENV_IDS`
ENVS = {env_id: env_class(env_id) for env_id in ENV_IDS}


def make_sb3_vec_env(env_id: str, num_envs: int = 1, seed: int | None = None, **options: Any):
    """A stable-baselines3 ``VecEnv`` of ``num_envs`` rows of ``env_id`` (batched, one simulator;
    :class:`~.sb3.AscentSB3VecEnv`, imported here so that ``import lvgym`` does not import SB3)."""
    cls = env_class(env_id)                          # a ConfigError names the ids for an unknown one
    from .sb3 import AscentSB3VecEnv
    return AscentSB3VecEnv(cls, num_envs, seed, **options)


def __getattr__(name: str) -> Any:
    if name == "AscentSB3VecEnv":                    # lazily: importing it imports stable-baselines3
        from .sb3 import AscentSB3VecEnv
        return AscentSB3VecEnv
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["DISPERSIONS", "ENVS", "FLIGHT_DEFAULTS", "FLIGHT_SENSORS", "OBSERVATIONS", "OBS_FLIGHT", "OBS_SENSORS", "OBS_STATE", "RANDOMIZE",
           "REWARD_TERMS", "TASK", "WIND_TIERS",
           "ActuatorOptions", "AtmosphereOptions", "CoastOptions", "DispersionOptions", "GuidanceOptions",
           "LaunchOptions", "LimitOptions", "PhysicsOptions", "RewardOptions", "SensorOptions", "TimingOptions",
           "AscentEnv", "AscentFuncEnv", "AscentParams", "AscentSB3VecEnv", "AscentState", "AscentVectorEnv",
           "EpisodeState", "SlenderAscentEnv", "SlenderAscentV1Env", "SmileAscentEnv", "SmileAscentV1Env",
           "StratosIIIEnv", "StratosIIIV1Env", "TaskSpec", "env_class", "make_sb3_vec_env", "make_vector"]
