"""DESIGN.md layers: nothing imports upward.

The dynamics core imports neither gymnasium nor the environment models nor the vehicle layer; the
environment models and the vehicle layer are independent of each other and of everything above them.
"""

import subprocess
import sys

import pytest

ABOVE_ALL = ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.simulator", "lvgym.benchmark")

FORBIDDEN = {
    "lvgym.dynamics": ABOVE_ALL + ("lvgym.environment", "lvgym.vehicle"),
    "lvgym.environment": ABOVE_ALL + ("lvgym.dynamics", "lvgym.vehicle"),
    "lvgym.vehicle": ABOVE_ALL + ("lvgym.dynamics", "lvgym.environment"),
}


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_layer_imports_nothing_above_it(package):
    forbidden = FORBIDDEN[package]
    code = (f"import sys, pkgutil, importlib, {package} as pkg\n"
            f"for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + '.'):\n"
            f"    importlib.import_module(m.name)\n"
            f"bad = [m for m in sys.modules if m.startswith({forbidden!r})]\n"
            f"print(bad); sys.exit(1 if bad else 0)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
