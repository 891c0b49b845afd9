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

__all__ = ["A_MAX", "ERRORS", "NO_THRUST", "TERMS", "InversionPolicy", "command", "error_index", "gain6_s0",
           "gain6_s1", "gain6_s2", "gains", "law_terms", "s0", "s1", "s2"]


def _seeded(k: int, prefix: str = "inversion", label: str = "inversion-id"):
    def factory(env: Any) -> InversionPolicy:
        return from_file(env, RESULTS / f"{prefix}-s{k}.pt", name=f"{label}-s{k}")
    factory.__name__ = f"s{k}" if prefix == "inversion" else f"{prefix.split('-')[-1]}_s{k}"
    return factory


#: the three training seeds' policies (``evaluate.py --policies experiments.fault_id.inversion:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))
#: ... trained under the loop dispersion (``train.py --loop-gain-db 6``: inversion-gain6-s<k>.pt)
gain6_s0, gain6_s1, gain6_s2 = (_seeded(k, "inversion-gain6", "inversion-id-gain6") for k in range(3))
