"""Train a student of one training seed (a teacher-student scheme): the thrust-direction estimator
(:mod:`.estimator`, ``--scheme thrust``) or the disturbance observer of the reference's law
(:mod:`.inversion`, ``--scheme inversion``).

    python -m experiments.fault_id.train --seed 0            # results/fault_id/estimator-s0.pt
    python -m experiments.fault_id.train --scheme inversion --seed 0 --flights 100 --rounds 4 --validation 50
                                                             # results/fault_id/inversion-s0.pt
    python -m experiments.fault_id.train --scheme inversion --suite family-v2 --family-vehicles 16
                                                             # the family's train vehicles: inversion-family-s0.pt

1. **Teacher's flights** on ``smile-v2-faults`` (both flight models, ``--flights`` each, training seeds
   ``100000 + 10000 seed ...``: neither validation nor test seeds), every step recorded as the student sees
   it (:class:`lvgym.agents.observer.Window`) with its label (:class:`ThrustScheme`, :class:`InversionScheme`):

   - ``thrust``: ``lqg`` with the true misalignment (the env's privileged info) subtracted from its
     command, known late by a delay drawn per flight from :data:`DELAYS` (never known, for one flight in
     six), so the flights cover the states before and after the correction; label: the true misalignment
     over the gimbal limit.
   - ``inversion``: the reference's law on the true terms (:func:`lvgym.agents.inversion.law_terms`), its
     action with an exploration noise of a standard deviation drawn per flight from :data:`NOISE` (else the
     action sent last holds the label, and the student reads it back from its own action); label: the true
     terms.
2. **Regression.** :class:`lvgym.agents.observer_fit.Estimator` fitted by mean squared error (Adam, ``--epochs``; the
   inversion's labels standardised; ``--ignition-weight``: the windows of the first ``--ignition-s`` after the
   next stage's ignition weigh more, :class:`lvgym.agents.staging.Ignition`).
3. **DAgger rounds** (``--rounds``): the student flies half as many flights again, labelled the same way,
   added to the data, and the estimator is fitted again. The thrust scheme's policy is the last fit; the
   inversion's the mean of the last three fits (:class:`lvgym.agents.observer_fit.Ensemble`).

After each fit the student flies validation seeds ``0 .. --validation - 1`` of both flight models and the
mean ``score_v2`` and its failed or unflyable flights are printed (``lqg``: 0.994 (6) rigid, 1.109 (7)
non-rigid on seeds 0-99; ``lqg`` with the true misalignment 0.778 (2), 0.900 (2): README.md). A run's memory
is its data (float32 windows, 1.6 kB per step; the fit's standard deviation is taken in chunks of rows,
:func:`.fitting.row_std`): SMILE's ``--flights 200 --rounds 4`` reach 3.9 M steps, 6.3 GB, and about 7 GB per
process at round 3; three such runs at once outgrow 24 GB in round 4.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from lvgym.agents.inversion import TERMS, Lead, command, error_index, gains, law_terms
from lvgym.agents.observer import Window
from lvgym.agents.staging import Ignition, signal_index
from lvgym.agents.observer_fit import Ensemble, Estimator, load, save
from lvgym.commandline import arg, parse

from .estimator import RESULTS, base_lqg, corrected
from .fitting import Data, fit

#: the teacher's delays [control steps] of its knowledge of the misalignment (0-2 s at 0.02 s; the last: never)
DELAYS = (0, 12, 25, 50, 100, None)
SUITE = "smile-v2-faults"


def condition(model: str, suite: str = SUITE, **options: Any):
    """``suite``'s condition of ``model`` with env ``options`` (``privileged_info=True``: the info the teacher
    and the labels need, the same flight with the true state in the info; a family suite's: its last
    vehicle's unless ``options`` name the ``vehicle``)."""
    from lvgym.benchmark.suites import get_suite

    return {c.model: c for c in get_suite(suite).conditions}[model].with_options(**options)


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


class InversionScheme:
    """The law of :mod:`lvgym.agents.inversion` on the true terms (the teacher) or the student's estimate;
    labels: the true terms (:func:`lvgym.agents.inversion.law_terms`), the moment's ``ahead`` control periods
    ahead (the preview), or the moment as it acts carried ``extrapolated`` periods along its slope over the
    last :data:`lvgym.agents.inversion.SPAN` (:class:`lvgym.agents.inversion.Lead`: a causal label, the estimate's
    slope learned from the window instead of differenced from the student's own estimates); ``lead``: the law
    flies the moment terms carried that many periods along their slope (:class:`lvgym.agents.inversion.Lead`:
    the teacher's of the truth, the student's of its estimates), the labels stay; ``law``: the law's gains per
    flight model where they are not the reference's (:func:`lvgym.agents.inversion.gains`); ``upset``: the
    share of the teacher's flights that, after the next stage's ignition, cancel only a part of the
    aerodynamic moment (a gain drawn from :data:`UPSET_GAIN`) for a while (drawn from :data:`UPSET_S`), then
    fly it out on the truth: flights through the large moments a late estimate meets there, labelled."""

    prefix, outputs, scaled, ensemble = "inversion", len(TERMS), True, 3

    def __init__(self, env1: Any, n: int, rng: np.random.Generator | None, deadband: float,
                 loop_gain: np.ndarray | None = None, ahead: int = 0, extrapolated: int = 0, lead: int = 0,
                 law: dict[str, Any] | None = None, upset: float = 0.0) -> None:
        self.limit, self.n, self.ahead = float(env1.unwrapped.func.gimbal_limit), n, int(ahead)
        self.label_lead = Lead(n, extrapolated)               # the label's, on the true moment
        self.lead = Lead(n, lead)                              # the law's, on the truth or the estimate
        self.index, (self.w, self.z) = error_index(env1), gains(env1, law)
        # a loop gain after the action (the margins' perturbation) scales the control power the action sees:
        # the terms in gimbal angles are labelled as the action must carry them, the truth over the gain
        self.per_gain = np.ones((n, 1)) if loop_gain is None else 1.0 / np.asarray(loop_gain, dtype=float)[:, None]
        self.truth = np.zeros((n, len(TERMS)))
        self.rng = rng                                   # the teacher's: its exploration
        self.sigma = None if rng is None else np.asarray(NOISE)[rng.integers(0, len(NOISE), n)][:, None]
        self.noise = np.zeros((n, 2))
        self.upset_gain, self.upset_s = np.ones(n), np.zeros(n)      # none: the whole moment, never
        if upset and rng is not None:
            hit = rng.random(n) < upset
            self.upset_gain[hit] = rng.uniform(*UPSET_GAIN, n)[hit]
            self.upset_s[hit] = rng.uniform(*UPSET_S, n)[hit]

    def labels(self, info: dict[str, Any]) -> np.ndarray:
        self.truth = law_terms(info, self.n, self.limit, self.ahead)
        if "m_aero_b" in info:                               # not the reset's info
            self.truth[:, 0:2] = self.label_lead.push(np.arange(self.n), self.truth[:, 0:2])
        self.truth[:, :6] *= self.per_gain
        return self.truth

    def act(self, live: np.ndarray, obs: np.ndarray, info: dict[str, Any], estimate: np.ndarray | None,
            since: np.ndarray) -> np.ndarray:
        """The rows ``live``'s actions; ``since``: their time since the next stage's ignition [s] (-1 before)."""
        terms = (self.truth[live] if estimate is None else estimate).copy()
        terms[:, 0:2] = self.lead.push(live, terms[:, 0:2])
        if estimate is not None:
            return command(obs, terms, self.index, self.w, self.z)
        upset = (since >= 0.0) & (since < self.upset_s[live])
        terms[upset, 0:2] *= self.upset_gain[live][upset][:, None]
        # the teacher's action with a slowly varying exploration: without it the action sent last holds the
        # label (it is ``a alpha - f``), and a student reads ``f`` back from its own action
        self.noise[live] = (NOISE_PHI * self.noise[live] + np.sqrt(1.0 - NOISE_PHI ** 2) * self.sigma[live]
                            * self.rng.standard_normal((len(live), 2)))
        return np.clip(command(obs, terms, self.index, self.w, self.z) + self.noise[live],
                       -1.0, 1.0).astype(np.float32)


#: the inversion teacher's exploration: its standard deviations [gimbal limits], one drawn per flight, and the
#: step-to-step correlation of the noise (a time constant of 0.2 s at 0.02 s)
NOISE = (0.0, 0.05, 0.1)
NOISE_PHI = float(np.exp(-0.1))
#: the inversion teacher's upsets after the next stage's ignition (``upset``): the share of the aerodynamic
#: moment it cancels and for how long [s], each drawn uniformly per flight
UPSET_GAIN = (0.3, 0.8)
UPSET_S = (0.5, 2.0)
#: the students by name (``--scheme``)
SCHEMES = {"thrust": ThrustScheme, "inversion": InversionScheme}


def fly(model: str, seeds: Sequence[int], estimator: Estimator | Ensemble | None = None,
        rng: np.random.Generator | None = None, deadband: float = 0.0, scheme: str = "thrust",
        loop_gain: np.ndarray | None = None, suite: str = SUITE, ahead: int = 0, extrapolated: int = 0,
        lead: int = 0, law: dict[str, Any] | None = None, upset: float = 0.0, **options: Any
        ) -> tuple[np.ndarray, np.ndarray, list[dict], np.ndarray]:
    """Fly the rows seeded ``seeds`` of the batched env of ``model`` with ``scheme``'s law (:data:`SCHEMES`) on
    the truth (``estimator`` None: the teacher; ``rng`` draws its delays) or on the ``estimator``'s output (the
    student; ``deadband``: the thrust scheme's). Returns the windows ``(steps, WINDOW, FEATURES)``, their
    labels ``(steps, outputs)``, the flights' records (protocol v2's fields) and each window's time [s] since
    the next stage's ignition (:class:`lvgym.agents.staging.Ignition`; -1 before it); ``loop_gain``: per row,
    a gain on the action after the flight computer sent it (the margins' perturbation, a training device; the
    inversion scheme only); ``suite``: whose condition (a family's with ``vehicle=`` in ``options``);
    ``ahead``: the inversion's moment label that many control periods ahead (its teacher flies on it);
    ``extrapolated``: ... the moment as it acts carried that many periods along its slope (the same);
    ``lead``: the inversion's law flies its moment carried that many periods along its slope (the labels stay);
    ``law``: its gains per flight model (:func:`lvgym.agents.inversion.gains`; None: the reference's);
    ``upset``: the share of the inversion teacher's flights upset after ignition (:class:`InversionScheme`);
    ``options``: env keywords (tests shorten the mission)."""
    from lvgym.benchmark.rows import RowsLog

    c = condition(model, suite, privileged_info=True, **options)
    n = len(seeds)
    env, env1 = c.make_vec_env(n), c.make_env()
    obs, info = env.reset(seed=[int(s) for s in seeds])
    if loop_gain is not None and scheme != "inversion":
        raise ValueError("loop_gain: the inversion scheme's training device only")
    if upset and scheme != "inversion":
        raise ValueError("upset: the inversion scheme's training device only")
    pilot = SCHEMES[scheme](env1, n, rng if estimator is None else None, deadband, loop_gain, ahead, extrapolated,
                            lead, law, upset)
    dt = float(env1.unwrapped.func.spec.timing.control_dt_s)
    gain = np.ones((n, 1)) if loop_gain is None else np.asarray(loop_gain, dtype=float)[:, None]
    window, log = Window(n), RowsLog(env)
    lit = Ignition(n, signal_index(env1, ("controller_on",))[0])
    xs, ys, since = [], [], []
    done = np.zeros(n, dtype=bool)
    while not done.all():
        live = np.flatnonzero(~done)
        truth = pilot.labels(info)
        w = window.push(live, obs[live])
        xs.append(w.copy())
        ys.append(truth[live].astype(np.float32))
        steps = lit.push(live, obs[live])
        since.append(np.where(steps >= 0, steps * dt, -1.0))
        estimate = None
        if estimator is not None:
            with torch.no_grad():
                estimate = estimator(torch.as_tensor(w)).numpy().astype(np.float64)
        a = pilot.act(live, obs[live], info, estimate, since[-1])
        window.sent(live, a)
        actions = np.zeros((n, 2), dtype=np.float32)
        actions[live] = np.clip(a * gain[live], -1.0, 1.0)
        obs, reward, term, trunc, info = env.step(actions)
        log.add(live, obs, reward, info, actions)
        ended = live[(np.asarray(term) | np.asarray(trunc))[live]]
        log.end(ended, info)
        done[ended] = True
    env.close()
    return np.concatenate(xs), np.concatenate(ys), log.records(True), np.concatenate(since)


def own_law(bandwidth: float) -> dict[str, list[float]] | None:
    """The inversion law's gains per flight model (:func:`lvgym.agents.inversion.gains`) of ``--bandwidth``: the
    non-rigid vehicle's bandwidth [rad/s] with the reference's damping; None (the reference's gains) for 0."""
    from lvgym.baselines.privileged import GAINS

    return {"nonrigid": [float(bandwidth), GAINS["nonrigid"][1]]} if bandwidth else None


def lost(record: dict[str, Any]) -> bool:
    """Whether a flight's record is failed or unflyable (protocol v2's charge)."""
    return bool(record["failed"] or not record["flyable"])


def scored(records: Sequence[dict[str, Any]]) -> tuple[float, int]:
    """The mean ``score_v2`` of ``records`` and how many of them are lost (:func:`lost`)."""
    return float(np.mean([r["score_v2"] for r in records])), sum(lost(r) for r in records)


def validate(est: Estimator | Ensemble, episodes: int, deadband: float = 0.0, scheme: str = "thrust",
             suite: str = SUITE, lead: int = 0, law: dict[str, Any] | None = None) -> dict[str, tuple[float, int]]:
    """Mean ``score_v2`` and failed or unflyable flights of the student on validation seeds ``0 ..
    episodes - 1`` per flight model (:func:`fly`: the rows of one batched env; the benchmark flies the same
    law one row at a time through :class:`.estimator.FaultIdPolicy` or
    :class:`lvgym.agents.inversion.InversionPolicy`); on the family, ``episodes`` spread over its validation
    vehicles (:data:`lvgym.benchmark.suites.FAMILY_VALIDATION_VEHICLES`, seeds ``0 .. episodes / 10 - 1``
    each); ``lead``, ``law``: :func:`fly`'s."""
    from lvgym.benchmark.suites import FAMILY_VALIDATION_VEHICLES

    out = {}
    for model in ("rigid", "nonrigid"):
        if suite != "family-v2":
            rs = [r for k in range(0, episodes, 100)
                  for r in fly(model, range(k, min(episodes, k + 100)), est, deadband=deadband, scheme=scheme,
                               suite=suite, lead=lead, law=law)[2]]
        else:
            each = max(1, episodes // len(FAMILY_VALIDATION_VEHICLES))
            rs = [r for v in FAMILY_VALIDATION_VEHICLES
                  for r in fly(model, range(each), est, scheme=scheme, suite=suite, lead=lead, law=law,
                               vehicle=v)[2]]
        out[model] = scored(rs)
    return out


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
    (:class:`lvgym.agents.staging.Ignition`: the law's terms change at once after a coast of ten seconds; 1:
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
    rng, t0 = np.random.default_rng(a.seed), time.time()
    first = 100_000 + 10_000 * a.seed
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
    vehicles = [None]
    if family:
        from lvgym.agents.familytrain import train_vehicle_files

        vehicles = [str(f) for f in train_vehicle_files(a.family_vehicles)]
    where = "" if a.suite == SUITE else "-family" if family else f"-{a.suite}"
    prefix = (SCHEMES[a.scheme].prefix + where + (f"-ahead{a.ahead}" if a.ahead else "")
              + (f"-extrapolated{a.extrapolated}" if a.extrapolated else "") + (f"-lead{a.lead}" if a.lead else "")
              + (f"-w{a.bandwidth:g}" if a.bandwidth else "") + (f"-{a.tag}" if a.tag else "")
              + (f"-ign{a.ignition_weight:g}" if a.ignition_weight != 1.0 else "")
              + (f"-upset{a.upset:g}" if a.upset else "")
              + (f"-gain{a.loop_gain_db:g}" if a.loop_gain_db else ""))
    law = own_law(a.bandwidth)
    data = Data()
    est: Estimator | None = None                      # the teacher flies round 0, the student the others
    fits: list[Estimator] = []
    for rnd in range(a.rounds + 1):
        count = a.flights if rnd == 0 else max(1, a.flights // 2)
        start = first + (0 if rnd == 0 else 5_000 * rnd)
        for model in ("rigid", "nonrigid"):
            for k in range(0, count, 100):
                chunk = list(range(start + k, start + min(count, k + 100)))
                for j, vehicle in enumerate(vehicles):          # the family: the chunk's seeds dealt out
                    seeds = chunk[j::len(vehicles)]
                    if not seeds:
                        continue
                    gain = (10.0 ** (rng.uniform(-a.loop_gain_db, a.loop_gain_db, len(seeds)) / 20.0)
                            if a.loop_gain_db else None)
                    place = {"suite": a.suite, **({"vehicle": vehicle} if family else {})}
                    x, y, _, since = fly(model, seeds, est, rng, scheme=a.scheme, loop_gain=gain,
                                         ahead=a.ahead, extrapolated=a.extrapolated, lead=a.lead, law=law,
                                         upset=a.upset, **place)
                    data.add(x, y, np.where((since >= 0) & (since < a.ignition_s), a.ignition_weight, 1.0))
            if rnd == 0:                              # room for the rounds to come (each flies half the flights
                data.reserve(len(data) * (4 + 3 * a.rounds) // 4)       # of round 0, their steps up to 3/4)
        print(f"seed {a.seed} round {rnd}: {len(data)} steps of data at {time.time() - t0:.0f} s", flush=True)
        done = RESULTS / f"{prefix}-s{a.seed}-r{rnd}.pt"
        if a.resume and done.is_file():               # this round's fit, from a run that stopped after it
            est = load(done)
            fits.append(est)
            print(f"seed {a.seed} round {rnd}: loaded {done}", flush=True)
            continue
        est = fit(*data.view(), a.seed, a.epochs, SCHEMES[a.scheme].scaled, data.weights())
        fits.append(est)
        save(est, done)
        if a.validation:
            v = validate(est, a.validation, scheme=a.scheme, suite=a.suite, lead=a.lead, law=law)
            print(f"seed {a.seed} round {rnd} validation 0-{a.validation - 1}: " + ", ".join(
                f"{m} {s:.3f} ({b})" for m, (s, b) in v.items()) + f" at {time.time() - t0:.0f} s", flush=True)
    last = SCHEMES[a.scheme].ensemble                 # the policy: the mean of the last rounds' fits
    final = Ensemble(fits[-last:]) if last > 1 else est
    save(final, RESULTS / f"{prefix}-s{a.seed}.pt")
    if a.validation and last > 1:
        v = validate(final, a.validation, scheme=a.scheme, suite=a.suite, lead=a.lead, law=law)
        print(f"seed {a.seed} the last {last} rounds' mean, validation 0-{a.validation - 1}: " + ", ".join(
            f"{m} {s:.3f} ({b})" for m, (s, b) in v.items()), flush=True)
    print(f"wrote {RESULTS / f'{prefix}-s{a.seed}.pt'} in {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
