"""The disturbance-observer students of the study's training seeds: :class:`lvgym.agents.inversion.InversionPolicy`
(the privileged reference's law on the terms a learned observer estimates from the flight computer's signals;
its module docstring gives the law) flown on each seed's ``results/fault_id`` file, written by :mod:`.train`
with ``--scheme inversion``. The policy shipped as ``inversion-id`` is one of them
(:mod:`.ship`, docs/training-results.md).

    python evaluate.py --suites smile-v2-faults --policies experiments.fault_id.inversion:s0
"""

from __future__ import annotations

from typing import Any

from lvgym.agents.inversion import (A_MAX, ERRORS, NO_THRUST, SPAN, TERMS, InversionPolicy, command, error_index,
                                    from_file, gains, law_terms)

from .estimator import RESULTS

__all__ = ["A_MAX", "ERRORS", "NO_THRUST", "TERMS", "InversionPolicy", "command", "error_index", "gain6_s0",
           "gain6_s1", "gain6_s2", "gains", "law_terms", "s0", "s1", "s2", "stratos_extrapolated15_s0",
           "stratos_extrapolated_s0", "stratos_lead3_gain6_s0", "stratos_lead3_gain6_s1", "stratos_lead3_gain6_s2",
           "smile_lead5_gain6_s0", "smile_lead5_gain6_s1", "smile_lead5_gain6_s2", "stratos_lead3_s0",
           "stratos_lead3_s1", "stratos_lead3_s2", "stratos_s0"]


def _seeded(k: int, prefix: str = "inversion", label: str = "inversion-id", attribute: str = "", lead: int = 0,
            span: int = SPAN):
    """The factory of training seed ``k``'s student (``results/fault_id/<prefix>-s<k>.pt``), flown with
    ``lead`` and ``span`` (:class:`lvgym.agents.inversion.Lead`)."""
    def factory(env: Any) -> InversionPolicy:
        return from_file(env, RESULTS / f"{prefix}-s{k}.pt", name=f"{label}-s{k}", lead=lead, span=span)
    factory.__name__ = f"{attribute}s{k}"
    factory.kind = "learned"                          # the headline's column (lvgym.benchmark.headline)
    return factory


#: the three training seeds' policies (``evaluate.py --policies experiments.fault_id.inversion:s0``)
s0, s1, s2 = (_seeded(k) for k in range(3))
#: ... trained under the loop dispersion (``train.py --loop-gain-db 6``: inversion-gain6-s<k>.pt)
gain6_s0, gain6_s1, gain6_s2 = (_seeded(k, "inversion-gain6", "inversion-id-gain6", "gain6_") for k in range(3))


#: the Stratos III student of the present moment (``train.py --scheme inversion --suite stratos-tvc-v2``) as it
#: was trained, and with its moment carried 5 steps ahead along its last 5 (:class:`lvgym.agents.inversion.Lead`;
#: ``evaluate.py --seed-set validation`` only)
stratos_s0 = _seeded(0, "inversion-stratos-tvc-v2", "inversion-stratos", "stratos_")
stratos_extrapolated_s0 = _seeded(0, "inversion-stratos-tvc-v2", "inversion-stratos-extrapolated",
                                  "stratos_extrapolated_", lead=5)
#: ... its slope over the last 15 steps (a smoother slope of a noisy estimate)
stratos_extrapolated15_s0 = _seeded(0, "inversion-stratos-tvc-v2", "inversion-stratos-extrapolated15",
                                    "stratos_extrapolated15_", lead=5, span=15)
#: the Stratos III students trained with the law's lead of 3 steps (``train.py --suite stratos-tvc-v2 --lead 3
#: --flights 200 --epochs 16 --tag f200e16``), flown with it
stratos_lead3_s0, stratos_lead3_s1, stratos_lead3_s2 = (
    _seeded(k, "inversion-stratos-tvc-v2-lead3-f200e16", "inversion-stratos-lead3", "stratos_lead3_", lead=3)
    for k in range(3))
#: ... and under the loop dispersion (``--loop-gain-db 6``)
stratos_lead3_gain6_s0, stratos_lead3_gain6_s1, stratos_lead3_gain6_s2 = (
    _seeded(k, "inversion-stratos-tvc-v2-lead3-f200e16-gain6", "inversion-stratos-lead3-gain6",
            "stratos_lead3_gain6_", lead=3) for k in range(3))
#: the smile-v2 students trained with the law's lead of 5 steps under the loop dispersion (``train.py --suite
#: smile-v2 --lead 5 --flights 200 --epochs 16 --tag f200e16 --loop-gain-db 6``), flown with it
smile_lead5_gain6_s0, smile_lead5_gain6_s1, smile_lead5_gain6_s2 = (
    _seeded(k, "inversion-smile-v2-lead5-f200e16-gain6", "inversion-smile-lead5-gain6", "smile_lead5_gain6_",
            lead=5) for k in range(3))
