"""DESIGN.md layers: the dynamics core imports neither gymnasium nor the environment models."""

import subprocess
import sys


def test_dynamics_core_imports_nothing_above_it():
    code = ("import sys, lvgym.dynamics; "
            "bad = [m for m in sys.modules if m.startswith(('gymnasium', 'stable_baselines3', 'torch', "
            "'lvgym.environment', 'lvgym.envs', 'lvgym.simulator', 'lvgym.vehicle'))]; "
            "print(bad); sys.exit(1 if bad else 0)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
