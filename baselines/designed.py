"""The classical baselines of a vehicle that has no shipped design: ``auto-gs-pid``, ``auto-gs-pid-flex`` and
``auto-lqg`` fly the schedules :func:`lvgym.baselines.design.auto.design_vehicle` makes for the env's vehicle
file: the last design of it in the design cache (:func:`~lvgym.baselines.design.auto.latest_design`, whatever
options ``lvgym design auto`` was given), or one made on first use with the defaults (about a minute; needs
the ``control`` extra).

``auto-gs-pid`` is the rigid-body design (the thesis's practice), ``auto-gs-pid-flex`` the design on the
non-rigid flight loop with structural filters (the field's practice), ``auto-lqg`` the LQG design; all three
are made the same way for every vehicle, so they are the per-vehicle baselines of a launcher family
(``lvgym.vehicle.generator``). ``fixed-gs-pid-flex`` and ``fixed-lqg`` fly instead the automatic design of the
family's nominal member (:func:`lvgym.vehicle.generator.nominal`: every range at its middle, L/D 25,
thrust-to-weight 1.85, finless) on whatever vehicle the env flies: the family's ``fixed`` baseline, one design
for vehicles it was not made for. (``gs-pid-flex`` is scheduled on mass, so on another vehicle it flies the
nominal member's row nearest in mass; ``lqg`` is scheduled on flight time.)
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError

__all__ = ["auto_policy", "fixed_policy", "nominal_file"]

KINDS = ("gs-pid", "gs-pid-flex", "lqg")


def auto_policy(env: Any, kind: str = "gs-pid-flex", name: str | None = None) -> Any:
    """The ``kind`` (one of :data:`KINDS`) policy of the automatic design of ``env``'s vehicle file."""
    from lvgym.vehicle.config import vehicle_file

    vehicle = getattr(env.unwrapped.task, "vehicle", None)
    if isinstance(vehicle, str) and vehicle.startswith("family/"):
        vehicle = vehicle_file(vehicle)              # a shipped family vehicle (family/test_20000) by its file
    if not isinstance(vehicle, (str, os.PathLike)) or not Path(os.fspath(vehicle)).suffix:
        raise ConfigError("env vehicle", vehicle, "the path of a vehicle YAML file or a family vehicle "
                          "(family/test_20000; the shipped vehicles fly their shipped designs: gs-pid, "
                          "gs-pid-flex, lqg)")
    return _designed(env, vehicle, kind, name or f"auto-{kind}")


def nominal_file() -> Path:
    """The family's nominal member as a vehicle file, in the design cache's folder (or a temporary one when
    the cache is off); written once, the same content every time."""
    import tempfile

    import yaml

    from lvgym.vehicle.generator import nominal

    from .design.auto import designs_folder

    folder = designs_folder() or Path(tempfile.gettempdir()) / "lvgym-designs"
    path = folder / "family_nominal.yaml"
    text = yaml.safe_dump(nominal().data, sort_keys=False)
    if not path.is_file() or path.read_text() != text:
        folder.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return path


def fixed_policy(env: Any, kind: str = "lqg", name: str | None = None) -> Any:
    """The ``kind`` policy of the automatic design of the family's nominal member (:func:`nominal_file`),
    whatever vehicle ``env`` flies."""
    return _designed(env, nominal_file(), kind, name or f"fixed-{kind}")


# their kind in protocol v2's headline (lvgym.benchmark.headline): classical designs
auto_policy.kind = "classical"  # type: ignore[attr-defined]
fixed_policy.kind = "classical"  # type: ignore[attr-defined]


def _designed(env: Any, vehicle: Any, kind: str, label: str) -> Any:
    """The ``kind`` policy flying the automatic design of the vehicle file ``vehicle`` on ``env``."""
    from .design.auto import design_vehicle, latest_design

    if kind not in KINDS:
        raise ConfigError("kind", kind, f"one of {list(KINDS)}")
    design = latest_design(vehicle) or design_vehicle(vehicle)
    if kind == "lqg":
        from .lqg import LQGPolicy

        return LQGPolicy(env=env, schedule=design.path("lqg"), name=label)
    from .pid import GainScheduledPIDPolicy

    return GainScheduledPIDPolicy(str(design.path(kind)), env=env, name=label)
