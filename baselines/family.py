"""The launcher family's flight check: a generated vehicle (:mod:`lvgym.vehicle.generator`) is kept only if
a sensible controller flies its nominal flight.

The check flies the benchmark's main-suite conditions (``smile-v2``) on the vehicle, non-rigid, without wind
or dispersion, with the privileged reference (:mod:`.privileged`: a controller that needs no design for the
vehicle, since it reads the true state) and accepts a flight that reaches its end without a failure and with
q-alpha below :data:`QALPHA_SHARE` of the vehicle's limit at every step. The aeroelastic-divergence check the
family is meant to pass too is not part of it yet.
"""

from __future__ import annotations

import tempfile
from functools import partial
from pathlib import Path
from typing import Any

import yaml

from lvgym.vehicle.generator import FamilyRanges, GeneratedVehicle, generate

from .privileged import PrivilegedPolicy

__all__ = ["QALPHA_SHARE", "flies_nominal", "generate_flyable"]

#: the largest q-alpha, as a share of the limit, a nominal flight may reach
QALPHA_SHARE = 0.9


def flies_nominal(data: dict[str, Any], seconds: float = 60.0) -> bool:
    """Whether the vehicle file ``data`` (a mapping) flies ``seconds`` [s] of its nominal flight (module
    docstring)."""
    import lvgym

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "vehicle.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
        env = lvgym.make_env("smile-v2", model="nonrigid", vehicle=str(path), wind="none", randomize=[],
                             privileged_info=True, mission_time_s=seconds)
        policy = PrivilegedPolicy(env)
        obs, info = env.reset(seed=0)
        peak = 0.0
        while True:
            obs, _, terminated, truncated, info = env.step(policy.act(obs, info))
            peak = max(peak, float(info["qalpha_pa_deg"]) / float(info["qalpha_limit_pa_deg"]))
            if terminated or truncated:
                return bool(truncated and not info["termination"] and peak < QALPHA_SHARE)


def generate_flyable(seed: int, ranges: FamilyRanges | None = None, seconds: float = 60.0) -> GeneratedVehicle:
    """The vehicle of ``seed`` that also passes :func:`flies_nominal` over ``seconds`` [s]."""
    return generate(seed, ranges, check=partial(flies_nominal, seconds=seconds))
