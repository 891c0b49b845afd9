"""One training seed of the teacher-student recipe (:mod:`lvgym.agents.training.teacher_student`): the teacher's
flights, the observer's fit and the DAgger rounds.

1. **The teacher's flights**: ``flights`` per flight model of the suite's condition, in batches of 100 rows,
   every step recorded as the student sees it with its label (:func:`lvgym.agents.training.teacher.fly`).
2. **The fit**: :func:`lvgym.agents.training.observer_fit.fit` on every window so far (the labels standardised).
3. **DAgger rounds** (``rounds``): the student flies half as many flights again, labelled the same way; they
   are added to the data and the observer is fitted again. The policy is the mean of the last three fits
   (:class:`lvgym.agents.policies.observer_net.Ensemble`; of the last one for a pilot whose ``ensemble`` is 1).

**Seeds.** Training flights draw their env seeds from :func:`training_seeds`: ``100,000 + 10,000 seed +
5,000 round + i``, above every validation and test seed of a suite (``0 .. 9,999`` and ``10,000 ..
19,999``; :func:`check_training_seeds` holds them apart). The loop gain of each flight (``loop_gain_db``) and
the teacher's exploration are drawn from one generator seeded with the training seed, and the fits are
seeded with it: a run is its seed's flights to the digit (the fits' floating point may differ from machine
to machine).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.suites import TRAINING_SEED0, TRAINING_SEED_STRIDE

from ..policies.observer_net import Ensemble, Estimator, load, save
from .observer_fit import Data, fit
from .teacher import Pilot, fly

__all__ = ["ROUND_STRIDE", "SEED_STRIDE", "TRAIN_SEED0", "check_training_seeds", "train_seed", "training_seeds"]

#: the first env seed of the training flights, and the strides per training seed and per round (the training
#: seeds of :mod:`lvgym.benchmark.suites`, as ``lvgym train`` draws them)
TRAIN_SEED0 = TRAINING_SEED0
SEED_STRIDE = TRAINING_SEED_STRIDE
ROUND_STRIDE = 5_000
#: rows of one batched flight
BATCH = 100


def training_seeds(seed: int, rnd: int, count: int) -> list[int]:
    """The env seeds of training seed ``seed``'s round ``rnd`` (``count`` flights per flight model)."""
    start = TRAIN_SEED0 + SEED_STRIDE * int(seed) + (0 if rnd == 0 else ROUND_STRIDE * int(rnd))
    return list(range(start, start + int(count)))


def check_training_seeds(suite: str, seeds: Sequence[int]) -> None:
    """Refuse training env seeds that are validation or test seeds of ``suite`` (its
    :meth:`~lvgym.benchmark.suites.Suite.seeds`)."""
    from lvgym.benchmark.suites import N_TEST_SEEDS, N_VALIDATION_SEEDS, get_suite
    from lvgym.errors import ConfigError

    s = get_suite(suite)
    held = set(s.seeds("validation", N_VALIDATION_SEEDS)) | set(s.seeds("test", N_TEST_SEEDS))
    clash = sorted(held.intersection(int(k) for k in seeds))
    if clash:
        raise ConfigError("training seeds", clash[:5], f"seeds outside {suite}'s validation and test seeds "
                                                       f"({min(held)} .. {max(held)})")


def train_seed(seed: int, flights: int, rounds: int, epochs: int, pilot: Pilot, round_file: Callable[[int], Path],
               *, suite: str, validation: int = 0, loop_gain_db: float = 0.0, places: Sequence[dict[str, Any]] = ({},),
               weight: Callable[[np.ndarray], np.ndarray] | None = None, scaled: bool = True, ensemble: int = 3,
               resume: bool = False, validate: Callable[[Any], dict[str, tuple[float, int]]] | None = None,
               log: Callable[[str], None] = print, **options: Any) -> Estimator | Ensemble:
    """The observer of training seed ``seed`` (module docstring): ``flights`` teacher flights per flight model,
    ``rounds`` DAgger rounds of half as many, ``epochs`` per fit; ``pilot`` flies them
    (:data:`lvgym.agents.training.teacher.Pilot`); each round's fit is written to ``round_file(rnd)`` and, with
    ``resume``, read from it where a run of the same options left it (the round's flights are flown again, the
    same flights; its fit is not). ``places``: env keywords the seeds of a batch are dealt over (a family's
    vehicles); ``weight``: each window's weight in the fits from its time since ignition (None: 1);
    ``scaled``: the labels standardised; ``ensemble``: how many of the last fits the observer averages;
    ``validate``: after each fit, the student's validation (printed with ``validation`` seeds); ``options``:
    env keywords of every flight."""
    rng, t0 = np.random.default_rng(seed), time.time()
    data = Data()
    est: Estimator | None = None                      # the teacher flies round 0, the student the others
    fits: list[Estimator] = []
    for rnd in range(rounds + 1):
        count = flights if rnd == 0 else max(1, flights // 2)
        seeds = training_seeds(seed, rnd, count)
        check_training_seeds(suite, seeds)
        for model in ("rigid", "nonrigid"):
            for k in range(0, count, BATCH):
                chunk = seeds[k:k + BATCH]
                for j, place in enumerate(places):          # a family: the chunk's seeds dealt out
                    dealt = chunk[j::len(places)]
                    if not dealt:
                        continue
                    gain = (10.0 ** (rng.uniform(-loop_gain_db, loop_gain_db, len(dealt)) / 20.0)
                            if loop_gain_db else None)
                    x, y, _, since = fly(model, dealt, pilot, est, rng, gain, suite, **place, **options)
                    data.add(x, y, None if weight is None else weight(since))
            if rnd == 0:                              # room for the rounds to come (each flies half the flights
                data.reserve(len(data) * (4 + 3 * rounds) // 4)         # of round 0, their steps up to 3/4)
        log(f"seed {seed} round {rnd}: {len(data)} steps of data at {time.time() - t0:.0f} s")
        done = round_file(rnd)
        if resume and done.is_file():                 # this round's fit, from a run that stopped after it
            est = load(done)
            fits.append(est)
            log(f"seed {seed} round {rnd}: loaded {done}")
            continue
        est = fit(*data.view(), seed, epochs, scaled, data.weights())
        fits.append(est)
        save(est, done)
        if validate is not None and validation:
            log(f"seed {seed} round {rnd} validation 0-{validation - 1}: {_shown(validate(est))} "
                f"at {time.time() - t0:.0f} s")
    final = Ensemble(fits[-ensemble:]) if ensemble > 1 else est
    if validate is not None and validation and ensemble > 1:
        log(f"seed {seed} the last {min(ensemble, len(fits))} rounds' mean, validation 0-{validation - 1}: "
            f"{_shown(validate(final))} at {time.time() - t0:.0f} s")
    return final


def _shown(v: dict[str, tuple[float, int]]) -> str:
    return ", ".join(f"{m} {s:.3f} ({b})" for m, (s, b) in v.items())
