"""Train a student of one training seed (a teacher-student scheme): the thrust-direction estimator (:mod:`.estimator`,
``--scheme thrust``) or the disturbance observer of the reference's law (:mod:`.inversion`, ``--scheme inversion``). The
shipped observers' recipe is installed, ``lvgym train --recipe teacher-student``
(:mod:`lvgym.agents.training.teacher_student`); this study flies the same teacher, rounds and fits
(:mod:`lvgym.agents.training.teacher`, :mod:`lvgym.agents.training.dagger`, :mod:`lvgym.agents.training.observer_fit`)
with what was tried beside them: the thrust scheme, the labels ahead or extrapolated, the upset teacher, the ignition's
weights, the family's vehicles.

    python -m experiments.fault_id.train --seed 0            # results/fault_id/estimator-s0.pt
    python -m experiments.fault_id.train --scheme inversion --seed 0 --flights 100 --rounds 4 --validation 50
                                                             # results/fault_id/inversion-s0.pt
    python -m experiments.fault_id.train --scheme inversion --suite family-v2 --family-vehicles 16
                                                             # the family's train vehicles: inversion-family-s0.pt

1. **Teacher's flights** on ``smile-v2-faults`` (both flight models, ``--flights`` each, training seeds
   ``100000 + 10000 seed ...``: neither validation nor test seeds), every step recorded as the student sees
   it (:class:`lvgym.agents.policies.observer.Window`) with its label (:class:`ThrustScheme`, :class:`InversionScheme`):

   - ``thrust``: ``lqg`` with the true misalignment (the env's privileged info) subtracted from its
     command, known late by a delay drawn per flight from :data:`DELAYS` (never known, for one flight in
     six), so the flights cover the states before and after the correction; label: the true misalignment
     over the gimbal limit.
   - ``inversion``: the reference's law on the true terms (:func:`lvgym.agents.policies.inversion.law_terms`), its
     action with an exploration noise of a standard deviation drawn per flight from :data:`NOISE` (else the
     action sent last holds the label, and the student reads it back from its own action); label: the true
     terms.
2. **Regression.** :class:`lvgym.agents.policies.observer_net.Estimator` fitted by mean squared error (Adam,
   ``--epochs``; the inversion's labels standardised; ``--ignition-weight``: the windows of the first
   ``--ignition-s`` after the next stage's ignition weigh more, :class:`lvgym.agents.policies.staging.Ignition`).
3. **DAgger rounds** (``--rounds``): the student flies half as many flights again, labelled the same way,
   added to the data, and the estimator is fitted again. The thrust scheme's policy is the last fit; the
   inversion's the mean of the last three fits (:class:`lvgym.agents.policies.observer_net.Ensemble`).

After each fit the student flies validation seeds ``0 .. --validation - 1`` of both flight models and the
mean ``score_v2`` and its failed or unflyable flights are printed (``lqg``: 0.994 (6) rigid, 1.109 (7)
non-rigid on seeds 0-99; ``lqg`` with the true misalignment 0.778 (2), 0.900 (2): README.md). A run's memory
is its data (float32 windows, 1.6 kB per step; the fit's standard deviation is taken in chunks of rows,
:func:`lvgym.agents.training.observer_fit.row_std`): SMILE's ``--flights 200 --rounds 4`` reach 3.9 M steps, 6.3 GB,
and about 7 GB per process at round 3; three such runs at once outgrow 24 GB in round 4.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from lvgym.agents.policies.inversion import Lead, law_terms
from lvgym.agents.policies.observer_net import Ensemble, Estimator, save
from lvgym.agents.training import teacher
from lvgym.agents.training.dagger import train_seed
from lvgym.agents.training.observer_fit import fit
from lvgym.agents.training.teacher import NOISE, SUITE, condition, lost, own_law, scored
from lvgym.commandline import arg, parse

from .estimator import RESULTS, base_lqg, corrected

__all__ = ["DELAYS", "NOISE", "SCHEMES", "SUITE", "UPSET_GAIN", "UPSET_S", "InversionScheme", "ThrustScheme",
           "condition", "fit", "fly", "lost", "main", "own_law", "pilot", "scored", "validate"]

#: the teacher's delays [control steps] of its knowledge of the misalignment (0-2 s at 0.02 s; the last: never)
DELAYS = (0, 12, 25, 50, 100, None)


class ThrustScheme:
    """``lqg`` corrected by the misalignment: the teacher's (true, known late by a delay drawn per flight from
    :data:`DELAYS` with ``rng``) or the student's estimate shrunk by ``deadband``
    (:func:`.estimator.corrected`); labels: the true misalignment over the gimbal limit."""

    prefix, outputs, scaled, ensemble = "estimator", 2, False, 1

    def __init__(self, env1: Any, n: int, rng: np.random.Generator | None, deadband: float,
                 loop_gain: np.ndarray | None = None, ahead: int = 0, extrapolated: int = 0, lead: int = 0,
                 law: dict[str, Any] | None = None, upset: float = 0.0) -> None:
        from lvgym.benchmark.batch import as_batch

        self.limit, self.n, self.deadband = float(env1.unwrapped.func.gimbal_limit), n, deadband
        self.lqg = as_batch(base_lqg(env1), n, lambda: base_lqg(env1))
        self.lqg.reset(np.arange(n))
        self.delay = None if rng is None else [DELAYS[i] for i in rng.integers(0, len(DELAYS), n)]
        self.truth: list[np.ndarray] = []                 # every row's label at every step

    def labels(self, info: dict[str, Any]) -> np.ndarray:
        m = info.get("misalignment")
        self.truth.append(np.zeros((self.n, 2)) if m is None else np.asarray(m, dtype=np.float64).reshape(self.n, 2)
                          / self.limit)
        return self.truth[-1]

    def act(self, live: np.ndarray, obs: np.ndarray, info: dict[str, Any], estimate: np.ndarray | None,
            since: np.ndarray) -> np.ndarray:
        base = np.asarray(self.lqg.act(live, obs, info), dtype=np.float64)
        if estimate is None:                             # the teacher: the truth, late
            step = len(self.truth) - 1
            estimate = np.array([self.truth[step - d][r] if d is not None and step >= d else np.zeros(2)
                                 for r, d in zip(live, (self.delay[r] for r in live))])
        return corrected(base, estimate, 0.0 if self.delay is not None else self.deadband)


class InversionScheme(teacher.InversionScheme):
    """The installed teacher and student (:class:`lvgym.agents.training.teacher.InversionScheme`: the law of
    :mod:`lvgym.agents.policies.inversion` on the true terms or the student's estimate, ``loop_gain``, ``lead``,
    ``law``) with the study's other labels and teachers: the moment's label ``ahead`` control periods ahead (the
    preview), or the moment as it acts carried ``extrapolated`` periods along its slope over the last
    :data:`lvgym.agents.policies.inversion.SPAN` (:class:`lvgym.agents.policies.inversion.Lead`: a causal label, the
    estimate's slope learned from the window instead of differenced from the student's own estimates); ``upset``: the
    share of the teacher's flights that, after the next stage's ignition, cancel only a part of the aerodynamic moment
    (a gain drawn from :data:`UPSET_GAIN`) for a while (drawn from :data:`UPSET_S`), then fly it out on the truth:
    flights through the large moments a late estimate meets there, labelled. The teacher's exploration levels are this
    module's :data:`NOISE`."""

    prefix = "inversion"

    def __init__(self, env1: Any, n: int, rng: np.random.Generator | None, deadband: float,
                 loop_gain: np.ndarray | None = None, ahead: int = 0, extrapolated: int = 0, lead: int = 0,
                 law: dict[str, Any] | None = None, upset: float = 0.0) -> None:
        self.ahead = int(ahead)
        self.label_lead = Lead(n, extrapolated)               # the label's, on the true moment
        super().__init__(env1, n, rng, loop_gain, lead, law, noise=NOISE)
        self.upset_gain, self.upset_s = np.ones(n), np.zeros(n)      # none: the whole moment, never
        if upset and rng is not None:
            hit = rng.random(n) < upset
            self.upset_gain[hit] = rng.uniform(*UPSET_GAIN, n)[hit]
            self.upset_s[hit] = rng.uniform(*UPSET_S, n)[hit]

    def true_terms(self, info: dict[str, Any]) -> np.ndarray:
        truth = law_terms(info, self.n, self.limit, self.ahead)
        if "m_aero_b" in info:                               # not the reset's info
            truth[:, 0:2] = self.label_lead.push(np.arange(self.n), truth[:, 0:2])
        return truth

    def upset(self, live: np.ndarray, terms: np.ndarray, since: np.ndarray) -> np.ndarray:
        upset = (since >= 0.0) & (since < self.upset_s[live])
        terms[upset, 0:2] *= self.upset_gain[live][upset][:, None]
        return terms


#: the inversion teacher's upsets after the next stage's ignition (``upset``): the share of the aerodynamic
#: moment it cancels and for how long [s], each drawn uniformly per flight
UPSET_GAIN = (0.3, 0.8)
UPSET_S = (0.5, 2.0)
#: the students by name (``--scheme``)
SCHEMES = {"thrust": ThrustScheme, "inversion": InversionScheme}


def pilot(scheme: str = "thrust", deadband: float = 0.0, ahead: int = 0, extrapolated: int = 0, lead: int = 0,
          law: dict[str, Any] | None = None, upset: float = 0.0) -> teacher.Pilot:
    """The pilot factory (:data:`lvgym.agents.training.teacher.Pilot`) of ``scheme`` (:data:`SCHEMES`) with its
    options."""
    def make(env1: Any, n: int, rng: np.random.Generator | None, loop_gain: np.ndarray | None) -> Any:
        return SCHEMES[scheme](env1, n, rng, deadband, loop_gain, ahead, extrapolated, lead, law, upset)
    return make


def fly(model: str, seeds: Sequence[int], estimator: Estimator | Ensemble | None = None,
        rng: np.random.Generator | None = None, deadband: float = 0.0, scheme: str = "thrust",
        loop_gain: np.ndarray | None = None, suite: str = SUITE, ahead: int = 0, extrapolated: int = 0,
        lead: int = 0, law: dict[str, Any] | None = None, upset: float = 0.0, **options: Any
        ) -> tuple[np.ndarray, np.ndarray, list[dict], np.ndarray]:
    """:func:`lvgym.agents.training.teacher.fly` with ``scheme``'s pilot (:data:`SCHEMES`, :func:`pilot`): the teacher
    (``estimator`` None; ``rng`` draws its delays or exploration) or the student on the ``estimator``'s output
    (``deadband``: the thrust scheme's). ``loop_gain``, ``upset``: the inversion scheme's training devices;
    ``ahead``, ``extrapolated``: its moment label (its teacher flies on it); ``lead``, ``law``: how its law flies
    the moment and its gains; ``options``: env keywords (tests shorten the mission; a family's ``vehicle``)."""
    if loop_gain is not None and scheme != "inversion":
        raise ValueError("loop_gain: the inversion scheme's training device only")
    if upset and scheme != "inversion":
        raise ValueError("upset: the inversion scheme's training device only")
    return teacher.fly(model, seeds, pilot(scheme, deadband, ahead, extrapolated, lead, law, upset), estimator, rng,
                       loop_gain, suite, **options)


def validate(est: Estimator | Ensemble, episodes: int, deadband: float = 0.0, scheme: str = "thrust",
             suite: str = SUITE, lead: int = 0, law: dict[str, Any] | None = None) -> dict[str, tuple[float, int]]:
    """Mean ``score_v2`` and failed or unflyable flights of the student on validation seeds ``0 ..
    episodes - 1`` per flight model (:func:`lvgym.agents.training.teacher.validate`); on the family, ``episodes``
    spread over its validation vehicles (:data:`lvgym.benchmark.suites.FAMILY_VALIDATION_VEHICLES`, seeds ``0 ..
    episodes / 10 - 1`` each); ``lead``, ``law``: :func:`fly`'s."""
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES

    made = pilot(scheme, deadband, lead=lead, law=law)
    if suite != "family-v2":
        return teacher.validate(est, episodes, made, suite)
    each = max(1, episodes // len(FAMILY_VALIDATION_VEHICLES))
    return {model: scored([r for v in FAMILY_VALIDATION_VEHICLES
                           for r in teacher.fly(model, range(each), made, est, suite=suite, vehicle=v)[2]])
            for model in ("rigid", "nonrigid")}


@dataclass
class Args:
    """Command-line arguments (``python -m experiments.fault_id.train --help``)."""

    seed: int = arg(0, lo=0, hi=99)
    """the training seed (its flights' seeds, the teacher's delays, the fits)"""
    flights: int = arg(200, lo=10, hi=2000)
    """teacher's flights per flight model (in batches of 100 rows)"""
    rounds: int = arg(2, lo=0, hi=10)
    """DAgger rounds after the teacher's data"""
    epochs: int = arg(8, lo=1, hi=100)
    """epochs per fit"""
    validation: int = arg(100, lo=0, hi=1000)
    """validation seeds flown after each fit (0: none)"""
    loop_gain_db: float = arg(0.0, lo=0.0, hi=12.0)
    """the inversion scheme's loop dispersion: a gain on every flight's action drawn uniformly in dB within
    +- this (0: none)"""
    scheme: str = arg("thrust", choices=tuple(SCHEMES))
    """the student: the thrust's direction for ``lqg`` (results/fault_id/estimator-s<seed>.pt), or the
    inversion law's terms (inversion-s<seed>.pt)"""
    suite: str = arg(SUITE, choices=(SUITE, "smile-v2", "stratos-tvc-v2", "family-v2"))
    """where the flights are: the fault suite, another v2 suite, or the launcher family's train vehicles
    (validation on its validation vehicles); other than the fault suite: the inversion scheme only, files
    ``inversion-<suite>-...`` (``inversion-family-...``)"""
    ahead: int = arg(0, lo=0, hi=10)
    """the inversion's moment label that many control periods ahead (the preview the teacher flies on; 0:
    the moment as it acts); files ``...-ahead<k>``"""
    extrapolated: int = arg(0, lo=0, hi=10)
    """the inversion's moment label: the moment as it acts carried that many control periods along its slope
    over the last 5 (causal; the teacher flies on it; 0: none); files ``...-extrapolated<k>``"""
    lead: int = arg(0, lo=0, hi=10)
    """the inversion's law flies the moment terms carried that many control periods along their slope over the
    last 5 (the teacher's true ones, the student's estimates; the labels stay the present terms; the policy
    flies it with ``lead``); files ``...-lead<k>``"""
    bandwidth: float = arg(0.0, lo=0.0, hi=10.0)
    """the inversion's law's bandwidth [rad/s] on the non-rigid vehicle, its damping the reference's (0: the
    reference's gains, :data:`lvgym.baselines.privileged.GAINS`); files ``...-w<bandwidth>``"""
    ignition_weight: float = arg(1.0, lo=1.0, hi=100.0)
    """the weight in the fits of the windows of the first ``--ignition-s`` after the next stage's ignition
    (:class:`lvgym.agents.policies.staging.Ignition`: the law's terms change at once after a coast of ten seconds; 1:
    all weigh the same);
    files ``...-ign<weight>``"""
    ignition_s: float = arg(2.0, lo=0.02, hi=20.0)
    """how long after the next stage's ignition ``--ignition-weight`` holds [s]"""
    upset: float = arg(0.0, lo=0.0, hi=1.0)
    """the share of the inversion teacher's flights that cancel only part of the aerodynamic moment for a
    while after the next stage's ignition, then fly it out (:class:`InversionScheme`; 0: none); files
    ``...-upset<share>``"""
    tag: str = arg("")
    """a label ending the files' prefix (a run of other ``--flights`` or ``--epochs`` beside the first)"""
    family_vehicles: int = arg(16, lo=1, hi=200)
    """the family's train vehicles the flights are spread over (``--suite family-v2``)"""
    resume: bool = False
    """take each round's fit from its file when a run of the same options left it (the rounds' data are flown
    again, the same flights; a fit is skipped, not its flights)"""


def main(argv: Sequence[str] | None = None) -> None:
    a = parse(Args, argv, "python -m experiments.fault_id.train", __doc__)
    torch.set_num_threads(1)
    RESULTS.mkdir(parents=True, exist_ok=True)
    family = a.suite == "family-v2"
    from lvgym.errors import ConfigError

    if a.scheme != "inversion" and (a.suite != SUITE or a.ahead or a.extrapolated or a.lead or a.bandwidth
                                    or a.upset):
        key, value = next((k, v) for k, v in (("--suite", a.suite if a.suite != SUITE else None),
                                              ("--ahead", a.ahead), ("--extrapolated", a.extrapolated),
                                              ("--lead", a.lead), ("--bandwidth", a.bandwidth),
                                              ("--upset", a.upset)) if v)
        raise ConfigError(key, value, f"{SUITE} and 0 for the thrust scheme (the others: --scheme inversion)")
    if a.ahead and a.extrapolated:
        raise ConfigError("--extrapolated", a.extrapolated, "0 with --ahead (one label of the moment)")
    places: list[dict[str, Any]] = [{}]
    if family:
        from lvgym.agents.training.familytrain import train_vehicle_files

        places = [{"vehicle": str(f)} for f in train_vehicle_files(a.family_vehicles)]
    where = "" if a.suite == SUITE else "-family" if family else f"-{a.suite}"
    prefix = (SCHEMES[a.scheme].prefix + where + (f"-ahead{a.ahead}" if a.ahead else "")
              + (f"-extrapolated{a.extrapolated}" if a.extrapolated else "") + (f"-lead{a.lead}" if a.lead else "")
              + (f"-w{a.bandwidth:g}" if a.bandwidth else "") + (f"-{a.tag}" if a.tag else "")
              + (f"-ign{a.ignition_weight:g}" if a.ignition_weight != 1.0 else "")
              + (f"-upset{a.upset:g}" if a.upset else "")
              + (f"-gain{a.loop_gain_db:g}" if a.loop_gain_db else ""))
    law = own_law(a.bandwidth)
    cls = SCHEMES[a.scheme]

    def weight(since: np.ndarray) -> np.ndarray:
        return np.where((since >= 0) & (since < a.ignition_s), a.ignition_weight, 1.0)

    final = train_seed(a.seed, a.flights, a.rounds, a.epochs,
                       pilot(a.scheme, 0.0, a.ahead, a.extrapolated, a.lead, law, a.upset),
                       lambda rnd: RESULTS / f"{prefix}-s{a.seed}-r{rnd}.pt", suite=a.suite, validation=a.validation,
                       loop_gain_db=a.loop_gain_db, places=places, weight=weight, scaled=cls.scaled,
                       ensemble=cls.ensemble, resume=a.resume,
                       validate=lambda e: validate(e, a.validation, scheme=a.scheme, suite=a.suite, lead=a.lead,
                                                   law=law),
                       log=lambda line: print(line, flush=True))
    save(final, RESULTS / f"{prefix}-s{a.seed}.pt")
    print(f"wrote {RESULTS / f'{prefix}-s{a.seed}.pt'}")


if __name__ == "__main__":
    main()
