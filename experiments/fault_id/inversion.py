"""The disturbance-observer students of the study's training seeds:
:class:`lvgym.agents.policies.inversion.InversionPolicy` (the privileged reference's law on the terms a learned observer
estimates from the flight computer's signals; its module docstring gives the law) flown on each seed's
``results/fault_id`` file, written by :mod:`.train` with ``--scheme inversion``. The policies shipped as
``inversion-id``, ``inversion-id-stratos`` and ``inversion-id-smile`` were three of them; the installed recipe ``lvgym
train --recipe teacher-student`` trains them again (:mod:`lvgym.agents.training.teacher_student`, docs/training.md).

    python evaluate.py --suites smile-v2-faults --policies experiments.fault_id.inversion:s0

Every configuration is one row of :data:`STUDENTS`; its training seed ``k``'s policy is the attribute
``<attribute>s<k>`` (``s0``, ``gain6_s1``, ``smile_lead5_w125_gain6_s2``, ...), labelled ``<label>-s<k>``
(the labels :mod:`.compare` groups by).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from lvgym.agents.policies.inversion import (A_MAX, ERRORS, NO_THRUST, SHIPPED, SPAN, TERMS, TRAINED, InversionPolicy,
                                             command, error_index, from_file, gains, law_terms)
from lvgym.agents.training.teacher import own_law

from .estimator import RESULTS

#: training seeds with a factory per configuration
SEEDS = (0, 1, 2)


@dataclass(frozen=True)
class Student:
    """A configuration of the study: the training runs' file prefix (``results/fault_id/<prefix>-s<k>.pt``), the label
    its policies fly under, and how the law flies the observer: ``lead``, ``span``, ``average``
    (:class:`lvgym.agents.policies.inversion.Lead`), ``bandwidth`` (the non-rigid law's, ``train.py --bandwidth``; 0:
    the reference's), ``ignition`` (the seconds after the next stage's ignition it cancels the moment measured from the
    rigid body, :class:`lvgym.agents.policies.inversion.Staging`; 0: never) and ``ignition_share`` (the measured
    moment's share there, the rest the estimate's)."""

    prefix: str
    label: str
    lead: int = 0
    span: int = SPAN
    bandwidth: float = 0.0
    average: int = 1
    ignition: float = 0.0
    ignition_share: float = 1.0


#: the configurations by attribute prefix
STUDENTS = {
    # the fault suite's students, without and with the loop dispersion (train.py --loop-gain-db 6)
    "": Student("inversion", "inversion-id"),
    "gain6_": Student("inversion-gain6", "inversion-id-gain6"),
    # ... the same runs flown with their moment averaged over 6 steps (the observer's 8 Hz limit cycle on a gyro
    # bias step) and carried 3 steps ahead: chosen on validation seeds after training, not trained with
    "gain6_avg6_lead3_": Student("inversion-gain6", "inversion-id-gain6-avg6-lead3", lead=3, average=6),
    # ... trained with the windows of the first 2 s after the next stage's ignition weighing 10 in the fits
    # (--ignition-weight 10: the staging coast's failures)
    "gain6_ign10_": Student("inversion-ign10-gain6", "inversion-id-gain6-ign10"),
    "gain6_ign10_avg6_lead3_": Student("inversion-ign10-gain6", "inversion-id-gain6-ign10-avg6-lead3", lead=3,
                                       average=6),
    # ... trained with half the teacher's flights upset after the next stage's ignition (--upset 0.5: 30-80 %
    # of the aerodynamic moment cancelled for 0.5-2 s, then flown out), and flown with the average and the lead
    "gain6_upset_": Student("inversion-upset0.5-gain6", "inversion-id-gain6-upset"),
    # the shipped command's runs and the upset ones flown with the moment measured from the rigid body for the
    # first 4 s after the next stage's ignition (chosen on validation seeds after training, not trained with)
    "gain6_ignition4_": Student("inversion-gain6", "inversion-id-gain6-ignition4", ignition=4.0),
    "gain6_upset_ignition4_": Student("inversion-upset0.5-gain6", "inversion-id-gain6-upset-ignition4",
                                      ignition=4.0),
    "gain6_avg6_lead3_ignition4_": Student("inversion-gain6", "inversion-id-gain6-avg6-lead3-ignition4", lead=3,
                                           average=6, ignition=4.0),
    # ... with half the measured moment and half the estimate there (the increment loop's gain margin)
    "gain6_avg6_lead3_ignition4_half_": Student("inversion-gain6", "inversion-id-gain6-avg6-lead3-ignition4-half",
                                                lead=3, average=6, ignition=4.0, ignition_share=0.5),
    "gain6_upset_avg6_lead3_": Student("inversion-upset0.5-gain6", "inversion-id-gain6-upset-avg6-lead3", lead=3,
                                       average=6),
    # Stratos III's student of the present moment as trained, and with its moment carried 5 steps ahead along
    # its last 5 or 15 steps (evaluate.py --seed-set validation only)
    "stratos_": Student("inversion-stratos-tvc-v2", "inversion-stratos"),
    "stratos_extrapolated_": Student("inversion-stratos-tvc-v2", "inversion-stratos-extrapolated", lead=5),
    "stratos_extrapolated15_": Student("inversion-stratos-tvc-v2", "inversion-stratos-extrapolated15", lead=5,
                                       span=15),
    # Stratos III trained with the law's lead of 3 (--suite stratos-tvc-v2 --lead 3 --flights 200 --epochs 16
    # --tag f200e16), and under the loop dispersion (--loop-gain-db 6)
    "stratos_lead3_": Student("inversion-stratos-tvc-v2-lead3-f200e16", "inversion-stratos-lead3", lead=3),
    "stratos_lead3_gain6_": Student("inversion-stratos-tvc-v2-lead3-f200e16-gain6", "inversion-stratos-lead3-gain6",
                                    lead=3),
    # smile-v2 with the law's lead of 5 under the dispersion (--suite smile-v2 --lead 5 --flights 200 --epochs 16
    # --tag f200e16 --loop-gain-db 6), and with the non-rigid law's bandwidth of 1.25 rad/s (--bandwidth 1.25)
    "smile_lead5_gain6_": Student("inversion-smile-v2-lead5-f200e16-gain6", "inversion-smile-lead5-gain6", lead=5),
    "smile_lead5_w125_gain6_": Student("inversion-smile-v2-lead5-w1.25-f200e16-gain6",
                                       "inversion-smile-lead5-w125-gain6", lead=5, bandwidth=1.25),
}


def seeded(attribute: str, k: int) -> Callable[[Any], InversionPolicy]:
    """The factory of :data:`STUDENTS` ``[attribute]``'s training seed ``k``."""
    student = STUDENTS[attribute]

    def factory(env: Any) -> InversionPolicy:
        return from_file(env, RESULTS / f"{student.prefix}-s{k}.pt", name=f"{student.label}-s{k}", lead=student.lead,
                         span=student.span, law=own_law(student.bandwidth), average=student.average,
                         ignition=student.ignition, ignition_share=student.ignition_share)
    factory.__name__ = f"{attribute}s{k}"
    factory.kind = "learned"                          # the headline's column (lvgym.benchmark.headline)
    return factory


def shipped_avg6_lead3(env: Any) -> InversionPolicy:
    """The shipped ``inversion-id``'s observer (``agents/trained``) flown with its moment averaged over 6 steps
    and carried 3 ahead (validation seeds only: tried on 2026-12-07, not shipped)."""
    return from_file(env, TRAINED / f"{SHIPPED}.npz", name="inversion-id-avg6-lead3", lead=3, average=6)


def shipped_ignition4(env: Any) -> InversionPolicy:
    """The shipped ``inversion-id``'s observer (``agents/trained``) flown with the moment measured from the rigid
    body for the first 4 s after the next stage's ignition (validation seeds: 2026-12-07)."""
    return from_file(env, TRAINED / f"{SHIPPED}.npz", name="inversion-id-ignition4", ignition=4.0)


def shipped_avg6_lead3_ignition4(env: Any) -> InversionPolicy:
    """The shipped ``inversion-id``'s observer with its moment averaged over 6 steps and carried 3 ahead, and the
    measured moment for the first 4 s after the next stage's ignition (validation seeds: 2026-12-07)."""
    return from_file(env, TRAINED / f"{SHIPPED}.npz", name="inversion-id-avg6-lead3-ignition4", lead=3, average=6,
                     ignition=4.0)


def shipped_avg6_lead3_ignition4_half(env: Any) -> InversionPolicy:
    """:func:`shipped_avg6_lead3_ignition4` with half the measured moment and half the estimate for the 4 s
    after the ignition (validation seeds: 2026-12-07, later)."""
    return from_file(env, TRAINED / f"{SHIPPED}.npz", name="inversion-id-ignition4-half", lead=3, average=6,
                     ignition=4.0, ignition_share=0.5)


def shipped_avg6_lead3_ignition4_share06(env: Any) -> InversionPolicy:
    """:func:`shipped_avg6_lead3_ignition4` with 0.6 of the measured moment and 0.4 of the estimate for the 4 s
    after the ignition (validation seeds: 2026-12-07, later)."""
    return from_file(env, TRAINED / f"{SHIPPED}.npz", name="inversion-id-ignition4-share06", lead=3, average=6,
                     ignition=4.0, ignition_share=0.6)


for _factory in (shipped_avg6_lead3, shipped_ignition4, shipped_avg6_lead3_ignition4,
                 shipped_avg6_lead3_ignition4_half, shipped_avg6_lead3_ignition4_share06):
    _factory.kind = "learned"  # type: ignore[attr-defined]
FACTORIES = {f"{attribute}s{k}": seeded(attribute, k) for attribute in STUDENTS for k in SEEDS}
globals().update(FACTORIES)                           # evaluate.py --policies experiments.fault_id.inversion:s0

__all__ = ["A_MAX", "ERRORS", "FACTORIES", "NO_THRUST", "STUDENTS", "TERMS", "InversionPolicy", "Student", "command",
           "error_index", "gains", "law_terms", "seeded", "shipped_avg6_lead3", "shipped_avg6_lead3_ignition4",
           "shipped_avg6_lead3_ignition4_half", "shipped_avg6_lead3_ignition4_share06", "shipped_ignition4", *FACTORIES]
