"""What an installed lvgym does in the Python that runs this file: ``python tests/wheel_probe.py OUT.json [--all]``.

Run by tests/test_wheel.py in a fresh virtual environment holding the wheel and only the core dependencies,
and by tests/test_packaging.py in the development environment (where every extra is installed). Writes to
``OUT.json``:

- ``lvgym_file``: where ``lvgym`` was imported from;
- ``loaded``: the optional packages (:data:`OPTIONAL`) in ``sys.modules`` after ``import lvgym, lvgym.envs``,
  and ``loaded_after_flight`` after ``gymnasium.make("lvgym/SmileAscent-v1")``, a reset (seed 0) and 100
  steps of zero gimbal command (``steps``: how many were flown, ``obs``: the last observation);
- with ``--all``: ``installed`` (which optional packages this Python can import), ``imports`` (every module
  of lvgym but the learning agents and the design tools, and ``None`` or the error its import raised),
  ``run_map`` (a serial map with its progress bar asked for) and ``load_error`` (reading a recorded
  trajectory, which needs pandas).
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import sys
from pathlib import Path

#: packages of the extras that the core must not import
OPTIONAL = ("torch", "stable_baselines3", "sb3_contrib", "matplotlib", "pandas", "control", "tqdm", "statsmodels",
            "pyarrow", "ray", "rliable")
#: the parts of lvgym that the core install does not promise to import (learning, offline design)
NOT_CORE = ("lvgym.agents", "lvgym.baselines.design")


def _loaded() -> list[str]:
    return sorted({m.partition(".")[0] for m in sys.modules} & set(OPTIONAL))


def _error(exc: BaseException) -> dict:
    return {"type": type(exc).__name__, "name": getattr(exc, "name", None), "message": str(exc)}


def _modules(root: Path) -> list[str]:
    """Every module of the package at ``root`` found on disk (a package that fails to import still
    lists its modules), but ``__main__`` scripts and :data:`NOT_CORE`."""
    names = []
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        if parts[-1] == "__main__":
            continue
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if not name.startswith(NOT_CORE):
            names.append(name)
    return names


def _square(x: int) -> int:
    return x * x


def main(out: Path, everything: bool) -> None:
    import numpy as np

    import gymnasium as gym
    import lvgym
    import lvgym.envs  # noqa: F401

    report: dict = {"lvgym_file": lvgym.__file__, "loaded": _loaded()}
    env = gym.make("lvgym/SmileAscent-v1")
    obs, _ = env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    steps = 0
    for _ in range(100):
        obs, _, terminated, truncated, _ = env.step(zero)
        steps += 1
        if terminated or truncated:
            break
    report.update(steps=steps, obs=np.asarray(obs, dtype=float).tolist(), loaded_after_flight=_loaded())
    if everything:
        report["installed"] = sorted(p for p in OPTIONAL if importlib.util.find_spec(p) is not None)
        imports: dict = {}
        for name in _modules(Path(lvgym.__file__).parent):
            try:
                importlib.import_module(name)
                imports[name] = None
            except Exception as exc:  # noqa: BLE001 - recorded for the test to judge
                imports[name] = _error(exc)
        report["imports"] = imports
        from lvgym.parallel import run_map
        report["run_map"] = run_map(_square, [1, 2, 3], executor="serial", progress=True)
        from lvgym.simulator import load
        try:
            load(out.with_suffix(".csv"))
            report["load_error"] = None
        except Exception as exc:  # noqa: BLE001
            report["load_error"] = _error(exc)
    out.write_text(json.dumps(report), encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1]), "--all" in sys.argv[2:])
