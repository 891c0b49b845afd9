"""The disturbance-observer students of the study's training seeds: :class:`lvgym.agents.inversion.InversionPolicy`
(the privileged reference's law on the terms a learned observer estimates from the flight computer's signals;
its module docstring gives the law) flown on each seed's ``results/fault_id`` file, written by :mod:`.train`
with ``--scheme inversion``. The policy shipped as ``inversion-id`` is one of them
(:mod:`.ship`, docs/training-results.md).

    python evaluate.py --suites smile-v2-faults --policies experiments.fault_id.inversion:s0
"""

from __future__ import annotations

from typing import Any

from lvgym.agents.inversion import (A_MAX, ERRORS, NO_THRUST, TERMS, InversionPolicy, command, error_index, from_file,
                                    gains, law_terms)

from .estimator import RESULTS
from .privileges import extrapolate

__all__ = ["A_MAX", "ERRORS", "NO_THRUST", "TERMS", "InversionPolicy", "command", "error_index", "gain6_s0",
           "gain6_s1", "gain6_s2", "gains", "law_terms", "s0", "s1", "s2"]


def _seeded(k: int, prefix: str = "inversion", label: str = "inversion-id", attribute: str = ""):
    def factory(env: Any) -> InversionPolicy:
        return from_file(env, RESULTS / f"{prefix}-s{k}.pt", name=f"{label}-s{k}")
    factory.__name__ = f"{attribute}s{k}"
    return factory


#: the three training seeds' policies (``evaluate.py --policies experiments.fault_id.inversion:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))
#: ... trained under the loop dispersion (``train.py --loop-gain-db 6``: inversion-gain6-s<k>.pt)
gain6_s0, gain6_s1, gain6_s2 = (_seeded(k, "inversion-gain6", "inversion-id-gain6", "gain6_") for k in range(3))


class Extrapolated(InversionPolicy):
    """The law on the observer's terms with its aerodynamic-moment terms (``f_aero``) extrapolated ``ahead``
    control steps along their slope over the last ``span`` steps of its own estimates (what
    :func:`.privileges.reference`'s ``aero_ahead_steps`` does with the true moment); one env row (the
    estimates' history is the flight's)."""

    batch = None                       # one row at a time (the shipped batch shares one observer over rows)

    def __init__(self, env: Any, observer: Any, name: str, ahead: int = 5, span: int = 5) -> None:
        super().__init__(env, observer, name=name)
        self.estimate, self.ahead, self.span, self.past = observer, int(ahead), int(span), []
        self.observer = self.extrapolated

    def reset(self) -> None:
        super().reset()
        self.past = []

    def extrapolated(self, window: Any) -> Any:
        """The observer's terms of ``window`` with ``f_aero`` carried along the slope of its estimates."""
        terms = self.estimate(window)
        self.past.append(terms[0:2].copy())
        terms[0:2] = extrapolate(self.past, self.ahead, self.span)
        return terms


def _extrapolated(prefix: str, k: int, label: str, attribute: str, span: int = 5):
    def factory(env: Any) -> Extrapolated:
        return Extrapolated(env, from_file(env, RESULTS / f"{prefix}-s{k}.pt").observer, name=f"{label}-s{k}",
                            span=span)
    factory.__name__ = f"{attribute}s{k}"
    return factory


#: the Stratos III student of the present moment (``train.py --scheme inversion --suite stratos-tvc-v2``) as it
#: was trained, and with its moment extrapolated 5 steps (``evaluate.py --seed-set validation`` only)
stratos_s0 = _seeded(0, "inversion-stratos-tvc-v2", "inversion-stratos", "stratos_")
stratos_extrapolated_s0 = _extrapolated("inversion-stratos-tvc-v2", 0, "inversion-stratos-extrapolated",
                                        "stratos_extrapolated_")
#: ... its slope over the last 15 steps (a smoother slope of a noisy estimate)
stratos_extrapolated15_s0 = _extrapolated("inversion-stratos-tvc-v2", 0, "inversion-stratos-extrapolated15",
                                          "stratos_extrapolated15_", 15)
