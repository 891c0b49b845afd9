"""The teacher-student recipe's flights (:mod:`lvgym.agents.training.teacher_student`): the privileged teacher and the
student flying a suite's condition as the rows of its batched env, every step recorded as the student sees it
with its label.

- :class:`InversionScheme`: the law of :mod:`lvgym.agents.policies.inversion` on the true terms (the teacher: the env's
  privileged info, :func:`lvgym.agents.policies.inversion.law_terms`), with an exploration noise on its action, or on
  the student's estimate of them; its labels are the true terms, as the action must carry them under a loop
  gain (``loop_gain``: the margins' perturbation as a training device).
- :func:`fly`: the rows of ``seeds`` flown by a pilot (the teacher, or the student on an estimator's output)
  through :func:`lvgym.benchmark.rows.fly_rows`; returns the windows (:class:`lvgym.agents.policies.observer.Window`),
  their labels, the flights' records and each window's time since the next stage's ignition
  (:class:`lvgym.agents.policies.staging.Ignition`).
- :func:`validate`: the student's mean ``score_v2`` and lost flights on a suite's validation seeds.

Without the teacher's exploration the action sent last holds the label (it is ``a alpha - f``) and a student
reads ``f`` back from its own action (docs/training-results.md: 49 of 50 validation flights lost).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..policies.inversion import TERMS, Lead, command, error_index, gains, law_terms
from ..policies.observer import Window
from ..policies.staging import Ignition, signal_index

__all__ = ["NOISE", "NOISE_PHI", "SUITE", "InversionScheme", "Recorder", "condition", "fly", "lost", "own_law",
           "scored", "validate"]

#: the suite the shipped ``inversion-id`` was trained on
SUITE = "smile-v2-faults"
#: the teacher's exploration: its standard deviations [gimbal limits], one drawn per flight, and the step-to-step
#: correlation of the noise (a time constant of 0.2 s at 0.02 s)
NOISE = (0.0, 0.05, 0.1)
NOISE_PHI = float(np.exp(-0.1))


def condition(model: str, suite: str = SUITE, **options: Any) -> Any:
    """``suite``'s condition of ``model`` with env ``options`` (``privileged_info=True``: the info the teacher
    and the labels need, the same flight with the true state in the info)."""
    from lvgym.benchmark.suites import get_suite

    return {c.model: c for c in get_suite(suite).conditions}[model].with_options(**options)


def own_law(bandwidth: float) -> dict[str, list[float]] | None:
    """The law's gains per flight model (:func:`lvgym.agents.policies.inversion.gains`) of a non-rigid bandwidth
    [rad/s] with the reference's damping; None (the reference's gains) for 0."""
    from lvgym.baselines.privileged import GAINS

    return {"nonrigid": [float(bandwidth), GAINS["nonrigid"][1]]} if bandwidth else None


class InversionScheme:
    """The law of :mod:`lvgym.agents.policies.inversion` for ``n`` rows of ``env1``'s batched env, on the true terms
    (the teacher, with ``rng``: its exploration is drawn from it) or on the student's estimate (``rng`` None).
    ``loop_gain``: per row, the gain after the action (labels: the terms in gimbal angles over it, as the action must
    carry them; the q-alpha share stays); ``lead``: the law flies the moment terms carried that many control periods
    along their slope (:class:`lvgym.agents.policies.inversion.Lead`: the teacher's of the truth, the student's of its
    estimates; the labels stay the present terms); ``law``: its gains per flight model where they are not the
    reference's (:func:`lvgym.agents.policies.inversion.gains`); ``noise``: the teacher's exploration levels (default
    :data:`NOISE`).

    :meth:`true_terms` and :meth:`upset` are the places a study changes the labels or the teacher's terms."""

    outputs, scaled, ensemble = len(TERMS), True, 3

    def __init__(self, env1: Any, n: int, rng: np.random.Generator | None, loop_gain: np.ndarray | None = None,
                 lead: int = 0, law: dict[str, Any] | None = None, noise: Sequence[float] | None = None) -> None:
        self.limit, self.n = float(env1.unwrapped.func.gimbal_limit), n
        self.lead = Lead(n, lead)
        self.index, (self.w, self.z) = error_index(env1), gains(env1, law)
        self.per_gain = np.ones((n, 1)) if loop_gain is None else 1.0 / np.asarray(loop_gain, dtype=float)[:, None]
        self.truth = np.zeros((n, len(TERMS)))
        self.rng = rng
        levels = NOISE if noise is None else tuple(noise)
        self.sigma = None if rng is None else np.asarray(levels)[rng.integers(0, len(levels), n)][:, None]
        self.noise = np.zeros((n, 2))

    def true_terms(self, info: dict[str, Any]) -> np.ndarray:
        """``(n, 7)``: the step's true terms (:func:`lvgym.agents.policies.inversion.law_terms`)."""
        return law_terms(info, self.n, self.limit)

    def labels(self, info: dict[str, Any]) -> np.ndarray:
        """The step's labels of every row (kept as the teacher's terms)."""
        self.truth = self.true_terms(info)
        self.truth[:, :6] *= self.per_gain
        return self.truth

    def upset(self, live: np.ndarray, terms: np.ndarray, since: np.ndarray) -> np.ndarray:
        """The teacher's terms of the rows ``live`` as it flies them (here: the truth)."""
        return terms

    def act(self, live: np.ndarray, obs: np.ndarray, info: dict[str, Any], estimate: np.ndarray | None,
            since: np.ndarray) -> np.ndarray:
        """The rows ``live``'s actions; ``since``: their time since the next stage's ignition [s] (-1 before)."""
        terms = (self.truth[live] if estimate is None else estimate).copy()
        terms[:, 0:2] = self.lead.push(live, terms[:, 0:2])
        if estimate is not None:
            return command(obs, terms, self.index, self.w, self.z)
        terms = self.upset(live, terms, since)
        # a slowly varying exploration: without it the action sent last holds the label
        self.noise[live] = (NOISE_PHI * self.noise[live] + np.sqrt(1.0 - NOISE_PHI ** 2) * self.sigma[live]
                            * self.rng.standard_normal((len(live), 2)))
        return np.clip(command(obs, terms, self.index, self.w, self.z) + self.noise[live],
                       -1.0, 1.0).astype(np.float32)


#: a pilot of ``n`` rows of a condition: ``make(env1, n, rng, loop_gain)`` (``rng`` None: the student's)
Pilot = Callable[[Any, int, "np.random.Generator | None", "np.ndarray | None"], Any]


class Recorder:
    """A pilot behind the benchmark's batch interface (:mod:`lvgym.benchmark.batch`), keeping every step's
    windows, labels and time since ignition: the student's view of the flight. ``estimator``: a torch module
    from windows to terms (the student), or None (the teacher); ``gain``: per row, the loop gain applied to the
    action after the flight computer sent it (the window holds the action sent)."""

    name = "teacher-student"

    def __init__(self, pilot: Any, n: int, estimator: Any, on: int, dt: float, gain: np.ndarray | None) -> None:
        self.pilot, self.estimator, self.dt = pilot, estimator, dt
        self.window, self.lit = Window(n), Ignition(n, on)
        self.gain = np.ones((n, 1)) if gain is None else np.asarray(gain, dtype=float)[:, None]
        self.xs: list[np.ndarray] = []
        self.ys: list[np.ndarray] = []
        self.since: list[np.ndarray] = []

    def reset(self, rows: np.ndarray) -> None:
        self.window.reset(rows)
        self.lit.reset(rows)

    def act(self, live: np.ndarray, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        truth = self.pilot.labels(info)
        w = self.window.push(live, obs)
        self.xs.append(w.copy())
        self.ys.append(truth[live].astype(np.float32))
        steps = self.lit.push(live, obs)
        self.since.append(np.where(steps >= 0, steps * self.dt, -1.0))
        estimate = None
        if self.estimator is not None:
            import torch

            with torch.no_grad():
                estimate = self.estimator(torch.as_tensor(w)).numpy().astype(np.float64)
        a = self.pilot.act(live, obs, info, estimate, self.since[-1])
        self.window.sent(live, a)
        return np.clip(a * self.gain[live], -1.0, 1.0).astype(np.float32)


def scheme(lead: int = 0, law: dict[str, Any] | None = None) -> Pilot:
    """The pilot factory of :class:`InversionScheme` with the law's ``lead`` and gains ``law``."""
    def make(env1: Any, n: int, rng: np.random.Generator | None, loop_gain: np.ndarray | None) -> InversionScheme:
        return InversionScheme(env1, n, rng, loop_gain, lead, law)
    return make


def fly(model: str, seeds: Sequence[int], pilot: Pilot, estimator: Any = None, rng: np.random.Generator | None = None,
        loop_gain: np.ndarray | None = None, suite: str = SUITE, **options: Any
        ) -> tuple[np.ndarray, np.ndarray, list[dict], np.ndarray]:
    """Fly the rows seeded ``seeds`` of the batched env of ``suite``'s ``model`` condition with the pilot made by
    ``pilot`` (:data:`Pilot`) on the truth (``estimator`` None: the teacher; ``rng`` draws its exploration) or on
    the ``estimator``'s output (the student). Returns the windows ``(steps, WINDOW, FEATURES)``, their labels
    ``(steps, outputs)``, the flights' records (protocol v2's fields) and each window's time [s] since the next
    stage's ignition (-1 before it); ``loop_gain``: per row, a gain on the action after the flight computer sent
    it; ``options``: env keywords (a short ``mission_time_s`` for tests, a family's ``vehicle``)."""
    from lvgym.benchmark.rows import fly_rows

    c = condition(model, suite, privileged_info=True, **options)
    n = len(seeds)
    env, env1 = c.make_vec_env(n), c.make_env()
    try:
        made = pilot(env1, n, rng if estimator is None else None, loop_gain)
        dt = float(env1.unwrapped.func.spec.timing.control_dt_s)
        rec = Recorder(made, n, estimator, signal_index(env1, ("controller_on",))[0], dt, loop_gain)
        records = fly_rows(env, [int(s) for s in seeds], [(rec, np.arange(n))], flyability=True)
    finally:
        env.close()
        env1.close()
    return np.concatenate(rec.xs), np.concatenate(rec.ys), records, np.concatenate(rec.since)


def lost(record: dict[str, Any]) -> bool:
    """Whether a flight's record is failed or unflyable (protocol v2's charge)."""
    return bool(record["failed"] or not record["flyable"])


def scored(records: Sequence[dict[str, Any]]) -> tuple[float, int]:
    """The mean ``score_v2`` of ``records`` and how many of them are lost (:func:`lost`)."""
    return float(np.mean([r["score_v2"] for r in records])), sum(lost(r) for r in records)


def validate(estimator: Any, episodes: int, pilot: Pilot, suite: str = SUITE, **options: Any
             ) -> dict[str, tuple[float, int]]:
    """Per flight model, the mean ``score_v2`` and the lost flights of the student (``estimator`` flown by
    ``pilot``'s law, in rows of up to 100) on ``suite``'s first ``episodes`` validation seeds
    (:meth:`lvgym.benchmark.suites.Suite.seeds`); the benchmark flies the same law one row at a time through
    :class:`lvgym.agents.policies.inversion.InversionPolicy`."""
    from lvgym.benchmark.suites import get_suite

    seeds = get_suite(suite).seeds("validation", episodes)
    out = {}
    for model in ("rigid", "nonrigid"):
        rs = [r for k in range(0, episodes, 100)
              for r in fly(model, seeds[k:k + 100], pilot, estimator, suite=suite, **options)[2]]
        out[model] = scored(rs)
    return out
