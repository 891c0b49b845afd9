"""The launcher family's flight check: a generated vehicle (:mod:`lvgym.vehicle.generator`) is kept only if
a sensible controller flies its nominal flight, below its structural limit and away from aeroelastic
divergence.

The check flies the benchmark's main-suite conditions (``smile-v2``) on the vehicle, non-rigid, without wind
or dispersion, with the privileged reference (:mod:`.privileged`: a controller that needs no design for the
vehicle, since it reads the true state) and accepts a flight that reaches its end without a failure, with
q-alpha below :data:`QALPHA_SHARE` of the vehicle's limit at every step, and with the dynamic pressure below
:data:`DIVERGENCE_SHARE` of the static aeroelastic divergence pressure of the moment
(:func:`lvgym.simulator.divergence.flight_divergence_qbar`: lvgym's own modes and strips, at the flight's
Mach number, sampled every :data:`DIVERGENCE_EVERY_S`).

Why a factor of 2 on the divergence pressure (``DIVERGENCE_SHARE`` 0.5): the divergence pressure is the
strip-theory aerodynamics alone. On the 2 mm slender vehicle, lvgym's number (409-451 kPa at 3-6 s, D 0.2833 m,
Mach 2) lies 11-17 % below the independent study's aerodynamics-only number (477-511 kPa) and the study's
follower thrust and axial compression lower that by another fifth (367-398 kPa), i.e. about 10 % below
lvgym's number; the flight's dispersions (wind, CN-alpha, CP) raise the load on top. A factor of 2 on
lvgym's number leaves about 1.8 against the independent model with thrust and axial load, which is the
margin (at least 1.62 over 3-8 s) that set ``SlenderAscent-v1``'s 4.5 mm wall (docs/aerodynamics.md,
"Independent check of the divergence").
"""

from __future__ import annotations

import tempfile
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lvgym.vehicle.generator import FamilyRanges, GeneratedVehicle, generate

from .privileged import PrivilegedPolicy

__all__ = ["DIVERGENCE_EVERY_S", "DIVERGENCE_SHARE", "QALPHA_SHARE", "flies_nominal", "generate_flyable",
           "nominal_flight"]

#: the largest q-alpha, as a share of the limit, a nominal flight may reach
QALPHA_SHARE = 0.9
#: the largest dynamic pressure, as a share of the static divergence pressure, a nominal flight may reach
DIVERGENCE_SHARE = 0.5
#: how often the divergence pressure is evaluated along the flight [s]
DIVERGENCE_EVERY_S = 0.5


def nominal_flight(data: dict[str, Any], seconds: float = 60.0, divergence: bool = True) -> dict[str, Any]:
    """Fly ``seconds`` [s] of the vehicle file ``data``'s nominal flight (module docstring) and return what
    the check reads: ``completed`` (reached its end without a failure), ``termination`` (the failure, or
    ""), ``qalpha_share`` (the peak q-alpha over the limit), ``divergence_share`` (the peak ``qbar / q_div``;
    nan when ``divergence`` is False or the flight ended early), ``peak_qbar_pa`` and ``duration_s``."""
    import lvgym
    from lvgym.simulator.divergence import divergence_ratio

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "vehicle.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
        env = lvgym.make_env("smile-v2", model="nonrigid", vehicle=str(path), wind="none", randomize=[],
                             privileged_info=True, mission_time_s=seconds)
        policy = PrivilegedPolicy(env)
        obs, info = env.reset(seed=0)
        peak, rows, next_t = 0.0, [], 0.0
        while True:
            obs, _, terminated, truncated, info = env.step(policy.act(obs, info))
            peak = max(peak, float(info["qalpha_pa_deg"]) / float(info["qalpha_limit_pa_deg"]))
            t = float(np.ravel(info["time"])[0])
            if t >= next_t:
                rows.append((t, float(np.ravel(info["qbar"])[0]), float(np.ravel(info["mach"])[0])))
                next_t = t + DIVERGENCE_EVERY_S
            if terminated or truncated:
                break
        completed = bool(truncated and not info["termination"])
        share = float("nan")
        if divergence and completed:
            t, q, m = np.array(rows).T
            share = float(np.max(divergence_ratio(path, t, q, m)))
    return {"completed": completed, "termination": str(info["termination"] or ""), "qalpha_share": peak,
            "divergence_share": share, "peak_qbar_pa": float(np.max(np.array(rows)[:, 1])) if rows else 0.0,
            "duration_s": float(np.ravel(info["time"])[0])}


def flies_nominal(data: dict[str, Any], seconds: float = 60.0) -> bool:
    """Whether the vehicle file ``data`` (a mapping) flies ``seconds`` [s] of its nominal flight without a
    failure, below :data:`QALPHA_SHARE` of its q-alpha limit and :data:`DIVERGENCE_SHARE` of its divergence
    pressure (module docstring)."""
    r = nominal_flight(data, seconds)
    return bool(r["completed"] and r["qalpha_share"] < QALPHA_SHARE and r["divergence_share"] < DIVERGENCE_SHARE)


def generate_flyable(seed: int, ranges: FamilyRanges | None = None, seconds: float = 60.0) -> GeneratedVehicle:
    """The vehicle of ``seed`` that also passes :func:`flies_nominal` over ``seconds`` [s]."""
    return generate(seed, ranges, check=partial(flies_nominal, seconds=seconds))


def write_family(split: str, count: int, folder: str | Path) -> list[Path]:
    """The first ``count`` vehicles of ``split``'s seeds (:data:`lvgym.vehicle.generator.SPLITS`) that pass
    the family's checks (:func:`generate_flyable`; a seed none of whose draws passes is skipped), written to
    ``folder`` as ``<split>_<seed>.yaml`` with a header naming the seed and the attempt. The shipped family
    vehicles (``lvgym/vehicles/family``) were written by it: they are frozen data of the family's suites, so
    a later change of the generator changes none of them."""
    from lvgym.errors import ConfigError
    from lvgym.vehicle.generator import SPLITS

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    seed, end = SPLITS[split] if split in SPLITS else (None, None)
    if seed is None:
        raise ConfigError("split", split, f"one of {sorted(SPLITS)}")
    while len(paths) < count and seed < end:
        try:
            g = generate_flyable(seed)
        except ConfigError:
            seed += 1
            continue
        path = out / f"{split}_{seed}.yaml"
        header = (f"# lvgym's launcher family: the {split} vehicle of seed {seed} (generator attempt {g.attempt}),\n"
                  "# written by lvgym.baselines.family.write_family: frozen data of the family's suites\n")
        path.write_text(header + yaml.safe_dump(g.data, sort_keys=False))
        paths.append(path)
        seed += 1
    return paths
