"""Sensitivity sweeps of thesis 6.2: diameter (L/D) at a fixed length, and mass flow (thrust-to-weight).

- L/D sweep: diameter 0.2 to 0.5 m (thesis: 1 mm steps) at L = 8.5 m, i.e. L/D 42.5 to 17; fill 1,
  mass flow 30 kg/s, slosh damping 0.5 (the :data:`~lvgym.vehicle.slender.DEFAULTS`).
- T/W sweep: mass flow 10 to 30 kg/s (thesis: 0.1 kg/s steps) at L/D 30 (D = 8.5 / 30 m), the other
  factors at their defaults; reported against the initial thrust-to-weight ratio.

Bending frequencies and shapes come from lvgym's beam analysis of each loaded vehicle
(:mod:`lvgym.vehicle.structure`); the thesis fitted ANSYS results of the bare 2 mm tube instead,
:func:`thesis_frequency_hz` (eq. 6.2) and :func:`thesis_deflection` (eq. 6.3), which the report shows
beside ours.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from lvgym.errors import ConfigError
from lvgym.vehicle.slender import DEFAULTS

from .responses import RunSetup
from .runs import case

__all__ = ["LD_LENGTH", "LD_RANGE", "TW_LD", "TW_RANGE", "ld_cases", "peak", "rise_ld", "thesis_deflection", "thesis_frequency_hz",
           "tw_cases"]

LD_LENGTH = 8.5          # [m] length of the L/D sweep
TW_LD = 30.0             # [-] slenderness of the T/W sweep
LD_RANGE = (0.2, 0.5)    # [m] diameters of the L/D sweep
TW_RANGE = (10.0, 30.0)  # [kg/s] mass flows of the T/W sweep


def thesis_frequency_hz(diameter: np.ndarray | float) -> np.ndarray:
    """Thesis eq. 6.2: first bending frequency [Hz] of the bare 8.5 m, 2 mm aluminium tube of diameter [m]
    (ANSYS fit, 0.1 <= D <= 0.5 m)."""
    return 86.738 * np.asarray(diameter, float) + 6.131


def thesis_deflection(diameter: np.ndarray | float) -> np.ndarray:
    """Thesis eq. 6.3: largest mass-normalised deflection of mode 1 [1/sqrt(kg)] of the same tube."""
    return 0.1438 * np.asarray(diameter, float) ** -0.511


def _grid(lo: float, hi: float, step: float, what: str = "step") -> np.ndarray:
    """``lo`` to ``hi`` in ``round((hi - lo) / step)`` equal steps; ``step`` in ``(0, hi - lo]``."""
    if isinstance(step, bool) or not isinstance(step, (int, float, np.floating)) or not 0.0 < step <= hi - lo:
        raise ConfigError("step", step, f"a number in (0, {hi - lo:g}]: the {what} between runs")
    if not lo < hi:
        raise ConfigError("range", (lo, hi), "low < high")
    n = int(round((hi - lo) / step))
    return np.round(np.linspace(lo, hi, n + 1), 9)


def ld_cases(step: float = 0.001, setup: RunSetup | None = None, lo: float = LD_RANGE[0],
             hi: float = LD_RANGE[1]) -> list[dict]:
    """Runs of the L/D sweep: diameters ``lo`` to ``hi`` [m] every ``step`` [m] at L = 8.5 m."""
    s = setup or RunSetup()
    return [case(LD_LENGTH, d, DEFAULTS["fill"], DEFAULTS["mass_flow"], DEFAULTS["slosh_damping"], s)
            for d in _grid(lo, hi, step, "diameter [m]")]


def tw_cases(step: float = 0.1, setup: RunSetup | None = None, lo: float = TW_RANGE[0],
             hi: float = TW_RANGE[1]) -> list[dict]:
    """Runs of the T/W sweep: mass flows ``lo`` to ``hi`` [kg/s] every ``step`` at L/D 30."""
    s = setup or RunSetup()
    return [case(LD_LENGTH, LD_LENGTH / TW_LD, DEFAULTS["fill"], m, DEFAULTS["slosh_damping"], s)
            for m in _grid(lo, hi, step, "mass flow [kg/s]")]


def peak(table: pd.DataFrame, x: str, y: str) -> tuple[float, float]:
    """``(x, y)`` where ``y`` is largest (over runs that did not depart)."""
    t = table[~table["departed"].astype(bool)] if "departed" in table else table
    i = t[y].idxmax()
    return float(t.loc[i, x]), float(t.loc[i, y])


def rise_ld(table: pd.DataFrame, y: str, fraction: float = 0.5) -> float:
    """The smallest L/D from which ``y`` stays at or above ``fraction`` of its peak up to the peak: where
    the response "strongly increases" (NaN if it never does)."""
    t = table[~table["departed"].astype(bool)].sort_values("ld")
    x, v = t["ld"].to_numpy(), t[y].to_numpy()
    k = int(np.argmax(v))
    below = np.flatnonzero(v[: k + 1] < fraction * v[k])
    return float(x[below[-1] + 1]) if below.size else float(x[0])
