"""The classical baselines of a vehicle that has no shipped design: ``auto-gs-pid``, ``auto-gs-pid-flex`` and
``auto-lqg`` fly the schedules :func:`lvgym.baselines.design.auto.design_vehicle` makes for the env's vehicle
file: the last design of it in the design cache (:func:`~lvgym.baselines.design.auto.latest_design`, whatever
options ``lvgym design auto`` was given), or one made on first use with the defaults (about a minute; needs
the ``control`` extra).

``auto-gs-pid`` is the rigid-body design (the thesis's practice), ``auto-gs-pid-flex`` the design on the
non-rigid flight loop with structural filters (the field's practice), ``auto-lqg`` the LQG design; all three
are made the same way for every vehicle, so they are the per-vehicle baselines of a launcher family
(``lvgym.vehicle.generator``).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError

__all__ = ["auto_policy"]

KINDS = ("gs-pid", "gs-pid-flex", "lqg")


def auto_policy(env: Any, kind: str = "gs-pid-flex", name: str | None = None) -> Any:
    """The ``kind`` (one of :data:`KINDS`) policy of the automatic design of ``env``'s vehicle file."""
    from .design.auto import design_vehicle, latest_design

    if kind not in KINDS:
        raise ConfigError("kind", kind, f"one of {list(KINDS)}")
    vehicle = getattr(env.unwrapped.task, "vehicle", None)
    if not isinstance(vehicle, (str, os.PathLike)) or not Path(os.fspath(vehicle)).suffix:
        raise ConfigError("env vehicle", vehicle, "the path of a vehicle YAML file (the shipped vehicles fly their "
                          "shipped designs: gs-pid, gs-pid-flex, lqg)")
    design = latest_design(vehicle) or design_vehicle(vehicle)
    label = name or f"auto-{kind}"
    if kind == "lqg":
        from .lqg import LQGPolicy

        return LQGPolicy(env=env, schedule=design.path("lqg"), name=label)
    from .pid import GainScheduledPIDPolicy

    return GainScheduledPIDPolicy(str(design.path(kind)), env=env, name=label)
