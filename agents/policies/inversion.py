"""``inversion-id``: the privileged reference's law flown on what a learned observer estimates of the plant
and of the aerodynamic moment from a flight computer's signals (a learned disturbance observer; issue 35's
shipped policy for ``smile-v2-faults``, docs/training-results.md).

The privileged reference (:mod:`lvgym.baselines.privileged`) inverts the rigid body: per axis it commands the
gimbal angle whose thrust moment gives a second-order attitude loop's angular acceleration and cancels the
aerodynamic moment, less the thrust misalignment, over the actuator's effectiveness, with load relief. Flown
on the observation's rate and attitude errors, without its wind preview, it needs per axis (pitch, yaw)
three numbers of the plant and one of the flight (:data:`TERMS`, :func:`law_terms`):

- ``f_aero = M_aero / (T l eff)`` and ``f_mis = misalignment / eff``, the gimbal angles that cancel the
  aerodynamic moment and the misalignment (over the gimbal limit);
- ``a = J / (T l eff)``, the gimbal angle per rad/s^2 of angular acceleration (the inverse of the control
  power, over the gimbal limit; 0 without thrust, where the law commands nothing);
- ``share``, the q-alpha over its limit (one for both axes);

and commands ``delta = a alpha - h f_aero - f_mis`` with ``alpha = -2 zeta w e_rate - h w^2 e_att`` (:func:`command`;
``w``, ``zeta``: the reference's :data:`~lvgym.baselines.privileged.GAINS` of the flight model; ``h``: the reference's
relief, :func:`~lvgym.baselines.privileged.relief_hold`). The env knows the terms (its ``privileged_info``); a flight
computer does not. :class:`InversionPolicy` flies the law with them estimated by a
:class:`~lvgym.agents.policies.observer_net.Estimator` (an :class:`~lvgym.agents.policies.observer_net.Ensemble`) from
the last :data:`~lvgym.agents.policies.observer.WINDOW` steps of observations and actions sent. It is causal: it reads
the observation only.

The shipped observer (:data:`SHIPPED`, ``agents/trained``) was trained on SMILE's fault suite, both flight models, with
the reference's law on the true terms as the teacher and DAgger rounds (``lvgym train --recipe teacher-student``,
:mod:`lvgym.agents.training.teacher_student`); ``inversion-id-stratos``'s on Stratos III and ``inversion-id-smile``'s on
``smile-v2``, the law flying its estimated moment carried 3 and 5 steps ahead (:class:`Lead`, the record's ``lead``),
``inversion-id-smile``'s law at a non-rigid bandwidth of 1.25 rad/s (:func:`gains`, the record's ``law``). A policy
refuses an env its observer was not trained for (:func:`check_env`). ``ignition``: for its first seconds after the next
stage's ignition the law can cancel the moment measured from the rigid body (:class:`Staging`,
:mod:`lvgym.agents.policies.staging`; the record's ``ignition``, and its share ``ignition_share``). ``inversion-id``
flies its moment averaged over 6 steps and carried 3 ahead, and for 4 s after the ignition half the measured moment and
half its estimate: options chosen after training on validation seeds (the record's ``flight``,
docs/training-results.md).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lvgym.benchmark.batch import BatchLaw, RowFace
from lvgym.errors import ConfigError

from .observer import N_OBS, Observer, Window
from .staging import GIMBAL, RATES, Ignition, Measured, signal_index

__all__ = ["A_MAX", "ERRORS", "SHIPPED", "SPAN", "TERMS", "InversionLaw", "InversionPolicy", "Lead", "Staging",
           "carry", "check_env", "command", "env_record", "error_index", "from_file", "gains", "law_terms",
           "shipped_inversion"]

#: the law's terms, in the order of :func:`law_terms`
TERMS = ("f_aero_pitch", "f_aero_yaw", "f_mis_pitch", "f_mis_yaw", "a_pitch", "a_yaw", "qalpha_share")
#: the labels' ceiling of ``a`` [gimbal limits per rad/s^2]: the thrust's tail-off would send it to infinity
A_MAX = 5.0
#: the observation's entries the law reads (SMILE's flight observation)
ERRORS = ("pitch_rate_error", "yaw_rate_error", "pitch_attitude_error", "yaw_attitude_error")
#: a law's own gains: ``{flight model: [bandwidth, damping]}`` or, as a policy spec's options must be hashable,
#: its ``(model, (bandwidth, damping))`` pairs (:func:`gains`)
Law = dict[str, Any] | Sequence[tuple[str, Any]]
#: the lever [N m per rad of gimbal] under which the law commands nothing (the privileged reference's)
NO_THRUST = 1.0
#: the shipped observer (``<stem>.npz``) and its record (``<stem>.json``: how it was trained, the env)
SHIPPED = "inversion_id_smile_v2_faults"
TRAINED = Path(__file__).resolve().parents[1] / "trained"


def law_terms(info: dict[str, Any], n: int, limit: float, ahead: int = 0) -> np.ndarray:
    """``(n, 7)``: :data:`TERMS` of the module docstring (``f_aero``, ``f_mis`` over the gimbal limit ``limit``
    [rad], ``a`` [gimbal limits per rad/s^2], ``share`` [-]) from a privileged step's info of ``n`` rows (zeros
    without thrust, or before the first step). The observer's labels; ``ahead`` > 0: ``f_aero`` of the
    aerodynamic moment that many control periods ahead (the info's ``m_aero_ahead_b``: the reference's
    preview, a label a causal observer can only predict)."""
    out = np.zeros((n, len(TERMS)))
    if "m_aero_b" not in info:                               # the reset's info
        return out
    lever = (np.asarray(info["thrust"], dtype=float) * np.asarray(info.get("vectored_share", 1.0), dtype=float)
             * np.asarray(info["gimbal_arm"], dtype=float)).reshape(n)
    on = lever >= NO_THRUST
    eff = np.maximum(np.asarray(info["actuator_effectiveness"], dtype=float).reshape(n, 2), 0.1)
    m_aero = (np.asarray(info["m_aero_ahead_b"], dtype=float).reshape(n, -1, 3)[:, ahead - 1, 1:] if ahead
              else np.asarray(info["m_aero_b"], dtype=float).reshape(n, 3)[:, 1:])
    mis = np.asarray(info["misalignment"], dtype=float).reshape(n, 2)
    J = np.asarray(info["J_b_diag"], dtype=float).reshape(n, 3)[:, 1:]
    safe = np.where(on, lever, 1.0)[:, None]
    out[on, 0:2] = (m_aero / safe / eff / limit)[on]
    out[on, 2:4] = (mis / eff / limit)[on]
    out[on, 4:6] = np.minimum(J / (safe * eff) / limit, A_MAX)[on]
    out[:, 6] = (np.asarray(info["qalpha_pa_deg"], dtype=float) / np.asarray(info["qalpha_limit_pa_deg"], dtype=float)
                 ).reshape(n)
    return out


def command(observations: np.ndarray, terms: np.ndarray, index: list[int], w: float, z: float) -> np.ndarray:
    """The law's action (module docstring) within [-1, 1] for ``(n, 14)`` observations (``index``: the
    positions of :data:`ERRORS`) and ``(n, 7)`` terms (:func:`law_terms`, true or estimated); ``w`` [rad/s]
    and ``z`` [-]: the attitude loop's bandwidth and damping."""
    from lvgym.baselines.privileged import RELIEF, relief_hold

    o = np.asarray(observations, dtype=np.float64)
    e_rate, e_att = o[:, index[:2]], o[:, index[2:]]
    hold = relief_hold(terms[:, 6:7], *RELIEF)
    alpha = -2.0 * z * w * e_rate - hold * w * w * e_att
    return np.clip(terms[:, 4:6] * alpha - hold * terms[:, 0:2] - terms[:, 2:4], -1.0, 1.0).astype(np.float32)


def gains(env: Any, law: Law | None = None) -> tuple[float, float]:
    """The law's (bandwidth [rad/s], damping) for ``env``'s flight model: ``law``'s ``{model: [bandwidth,
    damping]}`` where it names the model (a student's record: its law's own gains), else the reference's
    :data:`~lvgym.baselines.privileged.GAINS`."""
    from lvgym.baselines.privileged import GAINS

    model = "rigid" if env.unwrapped.func.spec.model == "rigid" else "nonrigid"
    law = dict(law or {})                             # or its (model, gains) pairs: a policy spec's hashable form
    unknown = sorted(set(law) - set(GAINS))
    if unknown:
        raise ConfigError("law", unknown, f"flight models of {sorted(GAINS)}")
    own = law.get(model)
    if own is None:
        return GAINS[model]
    try:
        w, z = (float(v) for v in own)
    except (TypeError, ValueError):
        w = z = math.nan
    if not (0.0 < w <= 100.0 and 0.0 < z <= 10.0):
        raise ConfigError(f"law {model}", list(own), "[bandwidth, damping] in (0, 100] rad/s and (0, 10]")
    return w, z


def error_index(env: Any) -> list[int]:
    """Where :data:`ERRORS` sit in ``env``'s observation."""
    return signal_index(env, ERRORS, "the law's errors")


def env_record(env: Any) -> dict[str, Any]:
    """What of ``env`` the observer's features depend on: the vehicle, the observation, its history, the
    control and the control period [s]."""
    spec = env.unwrapped.func.spec
    return {"vehicle": spec.vehicle, "observation": spec.sensors.observation, "history": spec.sensors.history,
            "control": spec.actuator.control, "control_dt_s": spec.timing.control_dt_s}


def check_env(env: Any, trained: dict[str, Any]) -> None:
    """Refuse ``env`` when it differs from the env the observer was trained on (``trained``: its
    :func:`env_record`) in anything its features depend on, naming the key."""
    for key, value in env_record(env).items():
        if key in trained and trained[key] != value:
            raise ConfigError(f"inversion-id env {key}", value, f"{trained[key]!r}: the observer was trained on it")
    shape = tuple(getattr(env, "single_observation_space", env.observation_space).shape)
    if shape != (N_OBS,):
        raise ConfigError("env observation", list(shape),
                          f"({N_OBS},): the observer reads SMILE's flight observation")


#: the span [control steps] of the slope a lead carries the aerodynamic moment along (:class:`Lead`)
SPAN = 5


def carry(now: np.ndarray, back: np.ndarray, ahead: int, span: int = SPAN) -> np.ndarray:
    """``now`` carried ``ahead`` steps along the slope from ``back``, ``span`` steps before it."""
    return now + ahead * (now - back) / span


class Lead:
    """The aerodynamic-moment terms (``f_aero``, pitch and yaw) of ``n`` rows averaged over the last ``average``
    control steps (over fewer at the start of a flight; 1: as they are), then carried ``ahead`` steps along
    the average's slope over the last ``span`` steps (:func:`carry`; over fewer at the start of a flight, none
    at its first step): a causal prediction of the moment the gimbal will meet, about a delay and a servo lag
    later (the privileged reference reads it 5 steps ahead in the wind). ``ahead`` 0 and ``average`` 1: the
    terms as they are. The average removes an oscillation of its period exactly and delays the moment by
    ``(average - 1) / 2`` steps, which the lead takes back: a learned observer can close a loop with its own
    action through the window it reads (the fault suite's observer on a gyro bias step: a limit cycle of 6
    steps, about 8 Hz; docs/training-results.md)."""

    def __init__(self, n: int, ahead: int = 0, span: int = SPAN, average: int = 1) -> None:
        if ahead < 0 or span < 1 or average < 1:
            raise ConfigError("lead", {"ahead": ahead, "span": span, "average": average},
                              "ahead >= 0, span >= 1 and average >= 1 control steps")
        self.ahead, self.span, self.average = int(ahead), int(span), int(average)
        self.past = np.zeros((int(n), self.span + 1, 2))          # the averages, oldest first
        self.count = np.zeros(int(n), dtype=np.int64)
        self.raw = np.zeros((int(n), self.average, 2))            # the terms as they came, oldest first

    def push(self, rows: np.ndarray, f_aero: np.ndarray) -> np.ndarray:
        """Add the step's ``f_aero`` ``(len(rows), 2)`` of ``rows`` and return them averaged and carried ahead."""
        f = np.asarray(f_aero, dtype=np.float64)
        if not self.ahead and self.average == 1:
            return f
        self.count[rows] += 1
        if self.average > 1:
            self.raw[rows, :-1] = self.raw[rows, 1:]
            self.raw[rows, -1] = f
            f = self.raw[rows].sum(axis=1) / np.minimum(self.count[rows], self.average)[:, None]
        if not self.ahead:
            return f
        self.past[rows, :-1] = self.past[rows, 1:]
        self.past[rows, -1] = f
        back = self.past[rows, np.maximum(0, self.span + 1 - self.count[rows])]
        return carry(f, back, self.ahead, self.span)

    def reset(self, rows: np.ndarray) -> None:
        """Forget the flights of ``rows``."""
        self.past[rows] = 0.0
        self.raw[rows] = 0.0
        self.count[rows] = 0


class Staging:
    """How a policy flies the next stage's ignition: for ``seconds`` after it (0: never; ``steps``: in control
    periods of ``env``) the aerodynamic moment is the moment measured from the rigid body
    (:class:`~lvgym.agents.policies.staging.Measured`, on the observer's control power) less the observer's
    misalignment, in place of the observer's estimate, while the observer's window still holds the coast;
    ``share`` < 1: that share of the measured moment and the rest of the estimate. The measured moment closes
    an incremental loop on the gimbal whose gain is the observer's error in the control power (and a gain
    between the command and the servo, as the margin test's); the share scales that loop's gain
    (``inversion-id``: half, for 6 dB of gain margin; docs/training-results.md)."""

    def __init__(self, env: Any, seconds: float = 0.0, share: float = 1.0) -> None:
        if not 0.0 <= seconds <= 60.0:
            raise ConfigError("ignition", seconds, "0 (never) to 60 s after the next stage's ignition")
        if not 0.0 < share <= 1.0:
            raise ConfigError("ignition share", share, "more than 0 and at most 1 (the measured moment's share)")
        self.dt = float(env.unwrapped.func.spec.timing.control_dt_s)
        self.steps = round(seconds / self.dt)
        self.share = float(share)
        if self.steps:
            self.on = signal_index(env, ("controller_on",))[0]
            self.rates, self.gimbal = signal_index(env, RATES), signal_index(env, GIMBAL)

    def rows(self, n: int) -> tuple[Ignition, Measured] | None:
        """The ignition's clock and the measured moment of ``n`` rows (None: never)."""
        return (Ignition(n, self.on), Measured(n, self.rates, self.gimbal, self.dt)) if self.steps else None


class InversionLaw(BatchLaw):
    """The law of the module docstring on the observer's estimated terms for ``n`` rows (the benchmark's policy; no
    privileged information): one window per row, the observer on every row's window in one call
    (:meth:`~lvgym.agents.policies.observer.Observer.rows`), the law on the rows at once (elementwise: a row's action
    does not depend on the others). ``observer``: an :class:`~lvgym.agents.policies.observer.Observer` (or a callable of
    one window, applied to each row's window in turn); ``trained``: the :func:`env_record` it was trained on (it refuses
    another env: :func:`check_env`); ``lead``, ``span``: the control steps the estimated aerodynamic moment is carried
    ahead along its slope over ``span`` steps (:class:`Lead`; 0: the moment as estimated), after its average over
    ``average`` steps (1: none); ``law``: the law's gains per flight model where they are not the reference's
    (:func:`gains`); ``ignition``: for that long [s] after the next stage's ignition the law cancels the moment measured
    from the rigid body (:class:`Staging`) in place of the estimated aerodynamic moment (0: never), ``ignition_share``
    of it and the rest of the estimate (1: the measured alone)."""

    def __init__(self, env: Any, observer: Observer | Callable[[np.ndarray], np.ndarray], 
                 name: str = "inversion-id",
                 trained: dict[str, Any] | None = None, lead: int = 0, span: int = SPAN,
                 law: Law | None = None, average: int = 1, ignition: float = 0.0,
                 ignition_share: float = 1.0, n: int = 1) -> None:
        check_env(env, trained or {})
        self.observer = observer
        #: the observer on every row's window: an Observer's own rows, else (a study's callable of one window)
        #: the callable on each window
        self.estimate = getattr(observer, "rows", None) or (lambda ws: np.stack([observer(w) for w in ws]))
        self.name = name
        self.index, (self.w, self.z) = error_index(env), gains(env, law)
        self.lead, self.span, self.average = int(lead), int(span), int(average)
        self.staging = Staging(env, ignition, ignition_share)
        self.allocate(n)

    def _rows(self, n: int) -> None:
        self.window, self.ahead = Window(n), Lead(n, self.lead, self.span, self.average)
        self.fresh = self.staging.rows(n)

    def reset(self, rows: Any) -> None:
        """Forget the flights of ``rows``: the window starts from zeros, the lead from no slope, the ignition's
        clock."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        self.window.reset(rows)
        self.ahead.reset(rows)
        if self.fresh is not None:
            for part in self.fresh:
                part.reset(rows)

    def act(self, rows: Any, observations: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        """The actions of ``rows`` for their ``(len(rows), 14)`` observations (``info`` is not read), their
        windows moved on by one."""
        rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        o = np.asarray(observations, dtype=np.float32)
        terms = self.estimate(self.window.push(rows, o))
        terms[:, 0:2] = self.ahead.push(rows, terms[:, 0:2])
        if self.fresh is not None:                     # the next stage's first seconds: the measured moment
            lit, measured = self.fresh
            since = lit.push(rows, o)
            measured.push(rows, o)
            now = (since >= 0) & (since < self.staging.steps)
            if now.any():
                w = self.staging.share
                terms[now, 0:2] = (w * (measured.moment(rows[now], terms[now, 4:6]) - terms[now, 2:4])
                                   + (1.0 - w) * terms[now, 0:2])
        a = command(o, terms, self.index, self.w, self.z)
        self.window.sent(rows, a)
        return a


class InversionPolicy(RowFace):
    """:class:`InversionLaw` (its arguments) for one env row: the benchmark's policy."""

    def __init__(self, env: Any, observer: Observer | Callable[[np.ndarray], np.ndarray], name: str = "inversion-id",
                 trained: dict[str, Any] | None = None, lead: int = 0, span: int = SPAN,
                 law: Law | None = None, average: int = 1, ignition: float = 0.0,
                 ignition_share: float = 1.0) -> None:
        self.law = InversionLaw(env, observer, name, trained, lead, span, law, average, ignition, ignition_share)


def from_file(env: Any, path: str | Path, name: str = "inversion-id", trained: dict[str, Any] | None = None,
              lead: int = 0, span: int = SPAN, law: Law | None = None, average: int = 1,
              ignition: float = 0.0, ignition_share: float = 1.0) -> InversionPolicy:
    """The policy on the observer saved at ``path``: an :class:`~lvgym.agents.policies.observer.Observer`'s ``.npz``, or
    a training run's torch ``.pt`` (:func:`lvgym.agents.policies.observer_net.load`; needs torch); ``lead``, ``span``,
    ``average``: the :class:`Lead` of its aerodynamic moment [control steps]; ``law``: its gains per flight
    model (:func:`gains`; None: the reference's); ``ignition``: the seconds after the next stage's ignition
    it flies the measured moment, ``ignition_share`` of it (:class:`Staging`)."""
    if Path(path).suffix == ".pt":
        from .observer_net import load, to_observer

        observer = to_observer(load(path))
    else:
        observer = Observer.load(path)
    return InversionPolicy(env, observer, name=name, trained=trained, lead=lead, span=span, law=law,
                           average=average, ignition=ignition, ignition_share=ignition_share)


def shipped_inversion(env: Any, name: str = "inversion-id", file: str = SHIPPED) -> InversionPolicy:
    """A shipped policy: ``agents/trained/<file>.npz`` flown on ``env`` (refused unless it is the env of
    ``<file>.json``'s ``env``) with the record's ``lead`` and ``average`` (:class:`Lead`; none when it names
    none), ``law`` (its gains per flight model, :func:`gains`; the reference's when it names none) and
    ``ignition`` and ``ignition_share`` (the seconds it flies the measured moment after the next stage's
    ignition and its share, :class:`Staging`; none and 1 when it names none)."""
    weights, record = TRAINED / f"{file}.npz", TRAINED / f"{file}.json"
    if not weights.is_file() or not record.is_file():
        raise FileNotFoundError(f"the shipped policy {str(weights)!r} or its record is missing "
                                "(docs/training-results.md)")
    meta = json.loads(record.read_text())
    return from_file(env, weights, name=name, trained=meta["env"], lead=int(meta.get("lead", 0)),
                     law=meta.get("law"), average=int(meta.get("average", 1)),
                     ignition=float(meta.get("ignition", 0.0)),
                     ignition_share=float(meta.get("ignition_share", 1.0)))


shipped_inversion.kind = from_file.kind = "learned"  # type: ignore[attr-defined]
