"""What the time-domain margins (:mod:`.margins`) insert between a policy and the actuator, and the
search that raises it until the flight fails.

- :class:`GainPolicy`: the policy's action times a gain ``k`` (the env then clips it to the action
  space, as it clips every action); ``20 log10 k`` dB.
- :class:`ActuatorDelay`: a pure extra delay of whole physics steps (``physics_dt_s``, 10 ms by default)
  between the policy and the actuator. Whole control periods are a first-in first-out buffer of actions
  (the env's own computational delay, ``action_delay_steps``, is such a buffer too); the steps left over
  go into the row's servo delay (layout :data:`lvgym.simulator.layouts.ACTUATOR`, field ``delay``: the
  first so many physics steps of a control period follow the previous period's command), the same field
  the ``servo_delay`` dispersion sets. The gimbal command is held over a control period, so both are the
  same pure shift of the command signal, and no equation is written twice. :class:`RowDelay` is the
  same for the rows of a batched env, each with its own delay (a batched flight scales each row's
  actions by its own gain: :func:`lvgym.benchmark.rows.fly_rows`).
- :func:`find_threshold`: the largest value that passes, searched outwards from one known to pass
  (doubling steps), then bisected; :func:`threshold_search` is the same search as a generator, so that
  many go on side by side.
- :func:`fly`: one episode of a policy spec on a condition with a gain and a delay, summarised.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Generator
from typing import Any

import gymnasium as gym
import numpy as np

from lvgym.simulator.layouts import ACTUATOR

from .policy import Policy
from .runner import PolicySpec, episode_objects, play_episode
from .suites import Condition

__all__ = ["ActuatorDelay", "GainPolicy", "RowDelay", "SUMMARY", "db_to_gain", "find_threshold", "fly", "gain_to_db",
           "summary", "threshold_search"]


def db_to_gain(db: float) -> float:
    """``10 ** (db / 20)``: the gain of ``db`` decibels [-]."""
    return 10.0 ** (float(db) / 20.0)


def gain_to_db(gain: float) -> float:
    """``20 log10 gain`` [dB] (``-inf`` for a gain of 0)."""
    return 20.0 * math.log10(gain) if gain > 0.0 else -math.inf


class GainPolicy:
    """``policy``'s action times ``gain`` [-] (a ``Box`` action; the env clips it to [-1, 1] as any action).

    >>> from lvgym.benchmark.policy import ZeroPolicy
    >>> class Half(ZeroPolicy):
    ...     def act(self, observation, info):
    ...         return np.array([0.5, -0.25], dtype=np.float32)
    >>> GainPolicy(Half(), 2.0).act(np.zeros(14), {})
    array([ 1. , -0.5], dtype=float32)
    """

    def __init__(self, policy: Policy, gain: float) -> None:
        gain = float(gain)
        if not (math.isfinite(gain) and gain >= 0.0):
            raise ValueError(f"gain = {gain!r}: a finite number >= 0")
        self.policy, self.gain = policy, gain
        self.name = f"{policy.name}*{gain:g}"

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        action = np.asarray(self.policy.act(observation, info))
        if action.dtype.kind not in "fc":
            raise ValueError(f"policy {self.policy.name!r} gave action {action!r}: a gain needs a Box (TVC) action")
        return (action * np.asarray(self.gain, dtype=action.dtype)).astype(action.dtype, copy=False)


def _task(env: gym.Env) -> Any:
    return env.unwrapped.task


class ActuatorDelay(gym.Wrapper):
    """``env`` with a pure extra delay of ``steps`` physics steps (``steps * physics_dt_s`` seconds) between
    the actions it is given and the actuator; a TVC env of lvgym. ``steps = n * P + m`` (``P`` physics
    steps per control period): the whole periods ``n`` are a buffer of actions that starts with the
    neutral action (zeros); the ``m`` steps are added to the row's servo delay after each reset, on top of
    its dispersed one (when the sum reaches ``P`` a period moves into the buffer). ``physics_dt_s`` [s]
    is the resolution. The buffer sits, as the env's own ``action_delay_steps`` does, before the env
    masks the command while the controller is off; the servo's part acts after it."""

    def __init__(self, env: gym.Env, steps: int) -> None:
        super().__init__(env)
        task = _task(env)
        if task.control != "tvc":
            raise ValueError(f"control = {task.control!r}: an actuator delay needs a TVC env")
        if int(steps) != steps or steps < 0:
            raise ValueError(f"steps = {steps!r}: a whole number of physics steps >= 0")
        self.steps = int(steps)
        self.per_period = int(task.substeps)
        self.physics_dt_s = float(task.control_dt_s) / self.per_period
        self.delay_s = self.steps * self.physics_dt_s
        self._queue: deque[np.ndarray] = deque()

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        periods, servo_steps = divmod(self.steps, self.per_period)
        delay = ACTUATOR.view(self.env.unwrapped.state.sim.actuator, "delay")
        more, delay[0, 0] = divmod(int(round(delay[0, 0])) + servo_steps, self.per_period)
        neutral = np.zeros(self.action_space.shape, dtype=self.action_space.dtype)
        self._queue = deque(neutral.copy() for _ in range(periods + more))
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        if self._queue:
            self._queue.append(np.array(action, copy=True))
            action = self._queue.popleft()
        return self.env.step(action)


class RowDelay:
    """:class:`ActuatorDelay` for the rows of a batched lvgym TVC env, each its own delay: row ``b`` gets
    ``steps[b]`` physics steps (0: none), split as the wrapper splits them (whole periods into a
    first-in first-out buffer of actions that starts neutral; the rest added to the row's servo delay,
    written here, right after the env's reset). :meth:`apply` takes the actions the policies gave every
    row and returns those the env gets (float64, which holds every action's value exactly)."""

    def __init__(self, env: Any, steps: Any) -> None:
        u = env.unwrapped
        task = u.task
        if task.control != "tvc":
            raise ValueError(f"control = {task.control!r}: an actuator delay needs a TVC env")
        n = int(env.num_envs)
        raw = np.asarray(steps).reshape(-1)
        if raw.size != n or np.any(raw < 0) or np.any(raw != np.round(raw)):
            raise ValueError(f"steps = {raw.tolist()!r}: {n} whole numbers of physics steps >= 0, one per row")
        steps = raw.astype(np.int64)
        per = int(task.substeps)
        self.physics_dt_s = float(task.control_dt_s) / per
        delay = ACTUATOR.view(u.state.sim.actuator, "delay")
        self.length = np.zeros(n, dtype=np.int64)
        for b in np.flatnonzero(steps).tolist():
            periods, servo_steps = divmod(int(steps[b]), per)
            more, delay[b, 0] = divmod(int(round(delay[b, 0])) + servo_steps, per)
            self.length[b] = periods + more
        self.rows = np.flatnonzero(self.length)
        n_a = int(np.prod(u.single_action_space.shape))
        self._buffer = np.zeros((n, max(1, int(self.length.max(initial=0))), n_a))
        self._next = np.zeros(n, dtype=np.int64)

    def apply(self, actions: np.ndarray) -> np.ndarray:
        """The actions (n, n_a) the env gets this step: a buffered row's oldest action (its buffer takes
        this one), the others' own."""
        q = self.rows
        if not q.size:
            return actions
        a = np.asarray(actions)
        out = a.astype(np.float64)
        k = self._next[q]
        out[q] = self._buffer[q, k]
        self._buffer[q, k] = a[q]
        self._next[q] = (k + 1) % self.length[q]
        return out


def threshold_search(safe: float, limit: float, tol: float, first_step: float,
                     integer: bool = False) -> Generator[float, bool, tuple[float, float | None, list[tuple[float, bool]]]]:
    """:func:`find_threshold` as a generator: it yields each value to try and is sent whether it passed;
    its return value (``StopIteration.value``) is ``(passed, failed, trials)``. Many searches can so go on
    side by side, their trials flown together (the margins' seeds, :mod:`.margins`)."""
    a, lim = float(safe), float(limit)
    if integer:
        a, lim, tol, first_step = float(round(a)), float(round(lim)), 1.0, max(1.0, float(round(abs(first_step))))
    direction = 1.0 if lim >= a else -1.0
    step = abs(float(first_step))
    trials: list[tuple[float, bool]] = []
    failed = None
    while a != lim:                                   # outwards
        x = a + direction * step
        x = lim if (x - lim) * direction >= 0.0 else x
        ok = bool((yield x))
        trials.append((x, ok))
        if not ok:
            failed = x
            break
        a, step = x, 2.0 * step
    if failed is None:
        return a, None, trials
    b = failed
    while abs(b - a) > tol + 1e-12:                   # then bisection of the bracket [a, b]
        m = a + (math.trunc((b - a) / 2.0) if integer else (b - a) / 2.0)
        ok = bool((yield m))
        trials.append((m, ok))
        if ok:
            a = m
        else:
            b = m
    return a, b, trials


def find_threshold(passes: Callable[[float], bool], safe: float, limit: float, tol: float, first_step: float,
                   integer: bool = False) -> tuple[float, float | None, list[tuple[float, bool]]]:
    """The largest value that passes, searched outwards from ``safe`` (known to pass, not tried) towards
    ``limit`` (either side of it): steps of ``first_step``, doubling (``safe + first_step``, ``+ 2 first_step``,
    ``+ 4 first_step``, ..., the last one at ``limit``) until one fails, then bisection between the last
    that passed and the first that failed until the bracket is at most ``tol`` wide (``integer``: whole
    values, the bracket ends 1 wide). It assumes one crossing in that bracket; searching outwards from the
    nominal, it finds the first failure on that grid and not a wider pass region further out. Returns
    ``(passed, failed, trials)``: the value that passed closest to the failure, the first value that
    failed (None: ``limit`` passed, the threshold lies beyond it) and every ``(value, passed)`` in the
    order tried (:func:`threshold_search` is the same search as a generator).

    >>> find_threshold(lambda x: x < 7.3, 0.0, 20.0, 0.25, 1.0)[:2]
    (7.25, 7.5)
    """
    search = threshold_search(safe, limit, tol, first_step, integer)
    try:
        x = next(search)
        while True:
            x = search.send(bool(passes(x)))
    except StopIteration as stop:
        return stop.value


#: the fields of an episode's record a margin search reads and keeps (:func:`fly`)
SUMMARY = ("failed", "failure_reason", "rate_error_rad", "score", "gimbal_rate_limit_s", "effort_rad_s", "duration_s")


def summary(record: dict[str, Any]) -> dict[str, Any]:
    """The :data:`SUMMARY` fields of an episode's record."""
    return {key: record[key] for key in SUMMARY}


def fly(policy_spec: PolicySpec, condition: Condition, seed: int, gain: float = 1.0,
        delay_steps: int = 0) -> dict[str, Any]:
    """One episode of ``policy_spec`` on ``condition`` reset with ``seed``, its actions times ``gain`` [-]
    and delayed by ``delay_steps`` physics steps (neither when 1 and 0: the episode of
    :func:`~.runner.run_episode`); returns ``failed``, ``failure_reason``, ``rate_error_rad``, ``score``
    [rad], ``gimbal_rate_limit_s`` [s], ``effort_rad_s`` [rad s] and ``duration_s`` [s] of its record. Envs and
    policies are cached per process."""
    env, policy = episode_objects(policy_spec, condition)
    if gain != 1.0:
        policy = GainPolicy(policy, gain)
    if delay_steps:
        env = ActuatorDelay(env, delay_steps)
    return summary(play_episode(policy, env, seed))
